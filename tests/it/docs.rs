//! The book (`docs/`) and the README: the generated pages are what the
//! code generates today (the language reference from the schema, the
//! standard library and the codes' explanations; the CLI page from clap's
//! definition), the README stays short, every relative link in the
//! Markdown points at a file (and heading) that exists, and the table of
//! contents lists every page. `LENSC_BLESS=1` rewrites the generated pages.

use std::collections::{BTreeSet, HashMap};
use std::path::{Path, PathBuf};

use crate::common::root;

/// How to rewrite the generated pages, for the failure messages.
const BLESS: &str = lensc_lang::reference::BLESS;

fn bless() -> bool {
    std::env::var_os("LENSC_BLESS").is_some()
}

#[test]
fn language_reference_is_current() {
    let dir = root().join("docs/reference");
    let pages = lensc_lang::reference::reference_pages();
    if bless() {
        // Only what changed is written, and only pages no longer generated
        // removed: the link test may be reading these files meanwhile.
        std::fs::create_dir_all(&dir).expect("create docs/reference");
        let generated: BTreeSet<PathBuf> = pages.iter().map(|(n, _)| dir.join(n)).collect();
        for old in markdown_in(&dir) {
            if !generated.contains(&old) {
                std::fs::remove_file(old).expect("remove an old page");
            }
        }
        for (name, text) in &pages {
            let path = dir.join(name);
            if std::fs::read_to_string(&path).ok().as_ref() != Some(text) {
                std::fs::write(path, text).expect("write a page");
            }
        }
        return;
    }
    let mut stale = Vec::new();
    for (name, text) in &pages {
        let committed = std::fs::read_to_string(dir.join(name)).unwrap_or_default();
        if committed != *text {
            stale.push(format!("docs/reference/{name}"));
        }
    }
    let generated: BTreeSet<PathBuf> = pages.iter().map(|(n, _)| dir.join(n)).collect();
    for f in markdown_in(&dir) {
        if !generated.contains(&f) {
            stale.push(format!("{} (no longer generated)", rel(&f)));
        }
    }
    assert!(
        stale.is_empty(),
        "the language reference is stale ({}): it is generated from the schema \
         (compiler/lang/src/schema/), stdlib/*.lens and compiler/lang/explain/; \
         regenerate it with\n    {BLESS}",
        stale.join(", ")
    );
}

#[test]
fn cli_page_is_current() {
    let path = root().join("docs/cli.md");
    let generated = lensc::cli_page::page();
    if bless() {
        if std::fs::read_to_string(&path).ok() != Some(generated.clone()) {
            std::fs::write(&path, &generated).expect("write docs/cli.md");
        }
        return;
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "docs/cli.md is stale: it is generated from clap's definition of the \
         command line (compiler/lensc/src/cli.rs); regenerate it with\n    {}",
        lensc::cli_page::BLESS
    );
}

#[test]
fn readme_stays_short() {
    let text = std::fs::read_to_string(root().join("README.md")).expect("README.md");
    let lines = text.lines().count();
    assert!(
        lines <= 220,
        "README.md has {lines} lines: it is the front door (what lensc is, the two \
         commands, an example, where to go next) and stays within about 200; move \
         the rest into the book under docs/"
    );
    // CI (.ci/run) runs this line as the README's second command.
    assert!(
        text.lines()
            .any(|l| l.starts_with("cargo test --workspace")),
        "README.md must keep the line `cargo test --workspace` in a code block"
    );
}

#[test]
fn relative_links_point_at_files_and_headings_that_exist() {
    let root = root();
    let mut files = vec![root.join("README.md"), root.join("editors/README.md")];
    files.extend(markdown_in(&root.join("docs")));
    let mut headings: HashMap<PathBuf, BTreeSet<String>> = HashMap::new();
    let mut broken = Vec::new();
    for file in &files {
        let text = std::fs::read_to_string(file).expect("read a page");
        for (line, target) in links(&text) {
            if target.contains("://") || target.starts_with("mailto:") {
                continue;
            }
            let (path, anchor) = match target.split_once('#') {
                Some((p, a)) => (p, Some(a)),
                None => (target.as_str(), None),
            };
            let resolved = if path.is_empty() {
                file.clone()
            } else {
                file.parent().expect("a folder").join(path)
            };
            let Ok(resolved) = resolved.canonicalize() else {
                broken.push(format!("{}:{line}: `{target}`: no such file", rel(file)));
                continue;
            };
            if !resolved.starts_with(&root) {
                broken.push(format!(
                    "{}:{line}: `{target}` leaves the repository",
                    rel(file)
                ));
                continue;
            }
            if let Some(anchor) = anchor
                && resolved.extension().is_some_and(|e| e == "md")
            {
                let known = headings.entry(resolved.clone()).or_insert_with(|| {
                    anchors(&std::fs::read_to_string(&resolved).unwrap_or_default())
                });
                if !known.contains(anchor) {
                    broken.push(format!(
                        "{}:{line}: `{target}`: no heading with that anchor in {}",
                        rel(file),
                        rel(&resolved)
                    ));
                }
            }
        }
    }
    assert!(
        broken.is_empty(),
        "broken relative links:\n{}",
        broken.join("\n")
    );
}

#[test]
fn the_table_of_contents_lists_every_page() {
    let docs = root().join("docs");
    let summary = std::fs::read_to_string(docs.join("SUMMARY.md")).expect("docs/SUMMARY.md");
    let listed: BTreeSet<PathBuf> = links(&summary)
        .into_iter()
        .map(|(_, t)| docs.join(t.split('#').next().unwrap_or("")))
        .collect();
    let missing: Vec<String> = markdown_in(&docs)
        .into_iter()
        .filter(|f| !f.ends_with("SUMMARY.md") && !listed.contains(f))
        .map(|f| rel(&f))
        .collect();
    assert!(
        missing.is_empty(),
        "docs/SUMMARY.md (the book's table of contents) does not list: {}",
        missing.join(", ")
    );
}

#[test]
fn the_link_checker_sees_what_it_must() {
    let text = "See [a](a.md) and `[not](code.md)`, [b](b.md#x \"title\").\n\
                ```\n[fenced](f.md)\n```\n# One `two` — three\n## One two three\n";
    let found: Vec<String> = links(text).into_iter().map(|(_, t)| t).collect();
    assert_eq!(found, ["a.md", "b.md#x"]);
    let a = anchors(text);
    assert!(
        a.contains("one-two--three") && a.contains("one-two-three"),
        "{a:?}"
    );
}

/// Every `.md` file under `dir`, sorted.
fn markdown_in(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return out;
    };
    for e in entries {
        let p = e.expect("a directory entry").path();
        if p.is_dir() {
            out.extend(markdown_in(&p));
        } else if p.extension().is_some_and(|e| e == "md") {
            out.push(p);
        }
    }
    out.sort();
    out
}

fn rel(p: &Path) -> String {
    p.strip_prefix(root()).unwrap_or(p).display().to_string()
}

/// The targets of the inline links `[text](target)` of a Markdown text,
/// with their line numbers; not in fenced blocks or code spans.
fn links(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut fenced = false;
    for (n, line) in text.lines().enumerate() {
        let t = line.trim_start();
        if t.starts_with("```") || t.starts_with("~~~") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            continue;
        }
        let plain = without_code_spans(line);
        let mut rest = plain.as_str();
        while let Some(at) = rest.find("](") {
            let after = &rest[at + 2..];
            let Some(end) = after.find(')') else { break };
            let target = after[..end].split_whitespace().next().unwrap_or("");
            let target = target.trim_start_matches('<').trim_end_matches('>');
            if !target.is_empty() {
                out.push((n + 1, target.to_string()));
            }
            rest = &after[end..];
        }
    }
    out
}

/// `line` with each code span's text blanked.
fn without_code_spans(line: &str) -> String {
    let mut out = String::with_capacity(line.len());
    let mut in_code = false;
    for c in line.chars() {
        if c == '`' {
            in_code = !in_code;
            out.push(' ');
        } else {
            out.push(if in_code { ' ' } else { c });
        }
    }
    out
}

/// The anchors of a Markdown text's headings, as GitHub and mdBook make
/// them: lower case, letters, digits, `-` and `_` kept, spaces made `-`,
/// the rest dropped; a repeated one gets `-1`, `-2`.
fn anchors(text: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    let mut seen: HashMap<String, usize> = HashMap::new();
    let mut fenced = false;
    for line in text.lines() {
        let t = line.trim_start();
        if t.starts_with("```") || t.starts_with("~~~") {
            fenced = !fenced;
            continue;
        }
        if fenced || !t.starts_with('#') {
            continue;
        }
        let title = t.trim_start_matches('#');
        if !title.starts_with(' ') {
            continue;
        }
        let slug: String = title
            .trim()
            .to_lowercase()
            .chars()
            .filter_map(|c| match c {
                ' ' => Some('-'),
                c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
                _ => None,
            })
            .collect();
        let n = seen.entry(slug.clone()).or_insert(0);
        out.insert(if *n == 0 {
            slug.clone()
        } else {
            format!("{slug}-{n}")
        });
        *n += 1;
    }
    out
}
