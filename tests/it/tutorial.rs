//! docs/tutorial.md runs as written: its job file is made as the page
//! makes it, each command shown is run in a fresh project folder, and
//! every line the page shows after a command must be a line of what the
//! command printed (or of the file it shows), with the exit code the page
//! implies (1 where it shows an error, else 0).
//!
//! How the page makes its file: a ```lens block that starts with `use` is
//! the whole file from there on; one that starts with a declaration
//! (`job NAME`, `strategy NAME`, …) replaces that declaration in the file
//! (up to the next blank line); an edit the prose asks for ("write
//! `radius: 12 mm`") is carried out by the comment beside it,
//! `<!-- edit: OLD => NEW -->`, which mdBook does not show.
//!
//! Commands: `lensc …` is run; `touch`, `cat FILE`, `head -N FILE` and the
//! page's one `jq` filter are done here (jq's output formatted from the
//! report as jq prints it), so the test needs no other program.

use std::path::Path;

use crate::common::{lensc, root, text};

/// The `jq` filter the page uses on a report.
const CRITERIA_FILTER: &str = r#"'.acceptance.criteria[] | "\(.criterion)  \(.measured) of \(.limit) \(.unit)  \(.source)  passed: \(.passed)"'"#;

#[test]
fn the_tutorial_runs_as_written() {
    let page = std::fs::read_to_string(root().join("docs/tutorial.md")).expect("tutorial");
    let dir = tempfile::tempdir().expect("tmp");
    let file = dir.path().join("front.lens");
    let mut source = String::new();
    let (mut fence, mut block): (Option<String>, Vec<String>) = (None, Vec::new());
    let mut ran = 0;
    for line in page.lines() {
        match (&fence, line.strip_prefix("```")) {
            (None, Some(lang)) => {
                fence = Some(lang.to_string());
                block.clear();
            }
            (Some(lang), Some(_)) => {
                if lang == "lens" {
                    source = with_block(&source, &block);
                    std::fs::write(&file, &source).expect("write");
                } else if lang == "text" {
                    ran += run_block(dir.path(), &block);
                    // A command may have made the file (`touch`).
                    source = std::fs::read_to_string(&file).unwrap_or_default();
                }
                fence = None;
            }
            (Some(_), None) => block.push(line.to_string()),
            (None, None) => {
                if let Some(edit) = line
                    .trim()
                    .strip_prefix("<!-- edit: ")
                    .and_then(|l| l.strip_suffix(" -->"))
                {
                    let (old, new) = edit.split_once(" => ").expect("OLD => NEW");
                    assert!(source.contains(old), "the edit `{edit}` finds no `{old}`");
                    source = source.replace(old, new);
                    std::fs::write(&file, &source).expect("write");
                }
            }
        }
    }
    assert!(ran >= 12, "the tutorial runs {ran} commands");
    // The page's last file is the one `lensc fmt --check` accepts.
    let out = lensc(dir.path(), &["fmt", "--check", "front.lens"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
}

/// `source` with the ```lens block `block` applied: a whole file, or a
/// declaration that replaces its namesake.
fn with_block(source: &str, block: &[String]) -> String {
    let new = block.join("\n") + "\n";
    if block[0].starts_with("use ") {
        return new;
    }
    // `job NAME {` or `strategy NAME = …`: the keyword and the name.
    let head: Vec<&str> = block[0].split_whitespace().take(2).collect();
    let starts = |l: &str| l.split_whitespace().take(2).eq(head.iter().copied());
    let lines: Vec<&str> = source.lines().collect();
    let at = lines
        .iter()
        .position(|l| starts(l))
        .unwrap_or_else(|| panic!("the file declares no `{}`:\n{source}", head.join(" ")));
    let end = lines[at..]
        .iter()
        .position(|l| l.trim().is_empty())
        .map_or(lines.len(), |n| at + n);
    let mut out: Vec<&str> = lines[..at].to_vec();
    out.extend(new.lines());
    out.extend(&lines[end..]);
    out.join("\n") + "\n"
}

/// Runs the commands of one ```text block; how many.
fn run_block(dir: &Path, block: &[String]) -> usize {
    let mut ran = 0;
    let mut i = 0;
    while i < block.len() {
        let Some(cmd) = block[i].strip_prefix("$ ") else {
            i += 1;
            continue;
        };
        let shown: Vec<&str> = block[i + 1..]
            .iter()
            .take_while(|l| !l.starts_with("$ "))
            .map(|l| l.trim())
            .filter(|l| !l.is_empty() && *l != "…")
            .collect();
        i += 1 + shown.len();
        let (printed, code) = run(dir, cmd);
        let error = shown.iter().any(|l| l.contains("Error:"));
        assert_eq!(
            code,
            if error { 1 } else { 0 },
            "`{cmd}` printed:\n{printed}"
        );
        let lines: Vec<&str> = printed.lines().map(str::trim).collect();
        for s in &shown {
            assert!(
                lines.contains(s),
                "`{cmd}`: the tutorial shows `{s}`, which it did not print:\n{printed}"
            );
        }
        ran += 1;
    }
    ran
}

/// What `cmd` printed (stdout then stderr) and its exit code.
fn run(dir: &Path, cmd: &str) -> (String, i32) {
    let read = |name: &str| {
        std::fs::read_to_string(dir.join(name)).unwrap_or_else(|e| panic!("`{cmd}`: {e}"))
    };
    if let Some(args) = cmd.strip_prefix("lensc ") {
        let args: Vec<&str> = args.split_whitespace().collect();
        let out = lensc(dir, &args);
        let printed = format!("{}{}", text(&out.stdout), text(&out.stderr));
        return (printed, out.status.code().expect("exited"));
    }
    if let Some(name) = cmd.strip_prefix("touch ") {
        std::fs::write(dir.join(name), "").expect("touch");
        return (String::new(), 0);
    }
    if let Some(name) = cmd.strip_prefix("cat ") {
        return (read(name), 0);
    }
    if let Some(rest) = cmd.strip_prefix("head -") {
        let (n, name) = rest.split_once(' ').expect("head -N FILE");
        let n: usize = n.parse().expect("a line count");
        let whole = read(name);
        let first: Vec<&str> = whole.lines().take(n).collect();
        return (first.join("\n"), 0);
    }
    if let Some(rest) = cmd.strip_prefix("jq -r ") {
        let (filter, name) = rest.rsplit_once(' ').expect("jq -r FILTER FILE");
        assert_eq!(
            filter, CRITERIA_FILTER,
            "teach this test the page's jq filter"
        );
        let report: serde_json::Value = serde_json::from_str(&read(name)).expect("json");
        let rows = report["acceptance"]["criteria"]
            .as_array()
            .expect("criteria")
            .iter()
            .map(|c| {
                format!(
                    "{}  {} of {} {}  {}  passed: {}",
                    plain(&c["criterion"]),
                    plain(&c["measured"]),
                    plain(&c["limit"]),
                    plain(&c["unit"]),
                    plain(&c["source"]),
                    plain(&c["passed"])
                )
            })
            .collect::<Vec<_>>();
        return (rows.join("\n"), 0);
    }
    panic!("the tutorial runs `{cmd}`: teach this test to run it")
}

/// A JSON value as jq's string interpolation writes it: a string bare,
/// anything else as JSON (a whole number without a fraction).
fn plain(v: &serde_json::Value) -> String {
    match v {
        serde_json::Value::String(s) => s.clone(),
        serde_json::Value::Number(n) => match n.as_f64() {
            Some(f) if f.fract() == 0.0 && f.abs() < 1e15 => format!("{}", f as i64),
            _ => n.to_string(),
        },
        other => other.to_string(),
    }
}
