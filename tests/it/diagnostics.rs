//! The bad-input corpus: every file in tests/bad/ must produce at least one
//! error, every diagnostic must be well formed, and the rendered output
//! (human and JSON) is snapshotted.

use std::path::Path;

use lensc::render;
use lensc_build::driver;
use lensc_lang::loader::RealFs;

fn corpus() -> Vec<std::path::PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/bad");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .expect("tests/bad")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "lens"))
        .collect();
    files.sort();
    files
}

/// Renders the diagnostics of one corpus file with a stable, relative name.
fn render_file(path: &Path) -> (String, String, usize) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let rel = path.strip_prefix(&root).unwrap_or(path);
    // Check with the working directory at the repository root so file names
    // in the output do not depend on where the tests run.
    let rel_text = rel.to_string_lossy().replace('\\', "/");
    let c = driver::check_path(&RealFs, &root.join(rel)).expect("readable corpus file");
    let mut human = Vec::new();
    render::human(c.diags(), &c.loaded.sources, false, &mut human).expect("render");
    let mut json = Vec::new();
    render::json_lines(c.diags(), &c.loaded.sources, &mut json).expect("json");
    let human = String::from_utf8(human)
        .expect("utf8")
        .replace(&root.join(rel).display().to_string(), &rel_text);
    let root_prefix = format!("{}/", root.display());
    let human = human.replace(&root_prefix, "");
    let json = String::from_utf8(json)
        .expect("utf8")
        .replace(&root_prefix, "");
    // The project root is named resolved (E0107).
    let canonical_prefix = format!("{}/", root.canonicalize().expect("root").display());
    let human = human.replace(&canonical_prefix, "");
    let json = json.replace(&canonical_prefix, "");
    let errors = c.diags().iter().filter(|d| d.is_error()).count();

    // Every diagnostic is well formed: a code, words, spans inside the file.
    for d in c.diags() {
        assert!(
            d.code.len() == 5 && (d.code.starts_with('E') || d.code.starts_with('W')),
            "{}",
            d.code
        );
        assert!(!d.message.is_empty());
        for l in &d.labels {
            let text = &c.loaded.sources.get(l.file).text;
            assert!(
                l.span.start <= l.span.end && l.span.end as usize <= text.len(),
                "span {:?} outside {}",
                l.span,
                rel_text
            );
            assert!(
                text.is_char_boundary(l.span.start as usize)
                    && text.is_char_boundary(l.span.end as usize)
            );
        }
    }
    (human, json, errors)
}

#[test]
fn corpus_is_large_enough() {
    assert!(
        corpus().len() >= 40,
        "the bad-input corpus has {} files",
        corpus().len()
    );
}

#[test]
fn every_bad_file_is_reported_and_snapshotted() {
    let mut failures = Vec::new();
    for path in corpus() {
        let name = path
            .file_stem()
            .expect("stem")
            .to_string_lossy()
            .to_string();
        let (human, json, errors) = render_file(&path);
        if errors == 0 {
            failures.push(name.clone());
        }
        let shown = format!("{human}\n--- json ---\n{json}");
        insta::with_settings!({ snapshot_path => "../snapshots/bad", prepend_module_to_snapshot => false, omit_expression => true }, {
            insta::assert_snapshot!(name, shown);
        });
    }
    assert!(failures.is_empty(), "no error reported for: {failures:?}");
}

#[test]
fn json_lines_have_every_field() {
    for path in corpus() {
        let (_, json, _) = render_file(&path);
        for line in json.lines() {
            let v: serde_json::Value =
                serde_json::from_str(line).expect("one JSON object per line");
            for key in [
                "severity", "code", "message", "file", "line", "column", "span", "labels", "help",
            ] {
                assert!(v.get(key).is_some(), "{key} missing in {line}");
            }
            assert!(v["span"]["start"].is_u64() && v["span"]["end"].is_u64());
            assert!(v["line"].as_u64().unwrap() >= 1 && v["column"].as_u64().unwrap() >= 1);
        }
    }
}

#[test]
fn checker_reports_every_error_not_the_first() {
    let (_, _, errors) = render_file(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/bad/many_errors_at_once.lens"),
    );
    assert!(errors >= 6, "only {errors} errors");
    let (_, _, errors) = render_file(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/bad/syntax_two_errors.lens"),
    );
    assert!(errors >= 2, "a syntax error hid the next one");
}

#[test]
fn labels_after_multibyte_characters_point_at_the_right_bytes() {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/bad/unicode_before_error.lens");
    let c = driver::check_path(&RealFs, &path).expect("read");
    let text = &c.loaded.sources.get(lensc_grammar::FileId(0)).text;
    let d = c
        .diags()
        .iter()
        .find(|d| d.code == lensc_lang::codes::PARAMETER_DIMENSION)
        .expect("rake error");
    assert_eq!(&text[d.primary().span.range()], "3 mm");
    let (human, _, _) = render_file(&path);
    // ariadne draws the label under `3 mm`, not shifted by the µ and °.
    let line = human
        .lines()
        .find(|l| l.contains("rake: 3 mm"))
        .expect("source line");
    let marker = human
        .lines()
        .skip_while(|l| !l.contains("rake: 3 mm"))
        .nth(1)
        .expect("marker line");
    let col = line.find("3 mm").expect("col");
    let line_chars: Vec<char> = line.chars().collect();
    let char_col = line_chars.iter().take_while(|_| true).collect::<String>()[..col]
        .chars()
        .count();
    let marker_col = marker
        .chars()
        .position(|c| c == '─' || c == '┬')
        .expect("marker");
    assert_eq!(marker_col, char_col, "\n{line}\n{marker}");
}

/// Nothing from a file reaches the terminal raw: ESC, an OSC sequence
/// ended by BEL, a C1 control (U+009B, a one-character CSI) and a
/// right-to-left override in a job file are shown escaped by `check`,
/// and ESC in a program's line by `verify`, in the source line and in the
/// messages that quote it.
#[test]
fn control_characters_are_escaped_on_the_terminal() {
    let dir = tempfile::tempdir().expect("tempdir");
    let job = "let a = 1 mm\nlet b = a + \u{1b}]0;pwned\u{7}\u{9b}31m\u{202e}zz\n";
    std::fs::write(dir.path().join("esc.lens"), job).expect("write");
    let out = crate::common::lensc(dir.path(), &["check", "esc.lens"]);
    let err = crate::common::text(&out.stderr);
    assert!(!out.status.success(), "{err}");
    for raw in ['\u{1b}', '\u{7}', '\u{9b}', '\u{202e}'] {
        assert!(!err.contains(raw), "{raw:?} raw in:\n{err}");
    }
    assert!(err.contains("\\u{1b}"), "{err}");
    assert!(err.contains("esc.lens:2:"), "{err}");

    let program = std::fs::read_to_string(
        crate::common::root().join("tests/bad_programs/e0302_unknown_g_code.ngc"),
    )
    .expect("program")
    .replace(
        "G66 X3. Z1.5",
        "G66 X3. Z1.5 (\u{1b}[2J\u{1b}]8;;http://x\u{7})",
    );
    std::fs::write(dir.path().join("esc.ngc"), program).expect("write");
    let out = crate::common::lensc(dir.path(), &["verify", "esc.ngc"]);
    let err = crate::common::text(&out.stderr);
    assert!(err.contains("E0302"), "{err}");
    assert!(!err.contains('\u{1b}') && !err.contains('\u{7}'), "{err}");
    assert!(err.contains("\\u{1b}[2J"), "{err}");
}

/// A diagnostic on a very long line prints a window around its label and
/// the rest summarised: the same few hundred bytes for a line of 100 kB
/// as for one of 4 MB, with the label's line and column those of the
/// file.
#[test]
fn a_long_line_is_shown_in_a_window() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mut sizes = Vec::new();
    for n in [100_000, 4_000_000] {
        let job = format!("let a = 1 mm\nlet b = {}zz + a\n", " ".repeat(n));
        std::fs::write(dir.path().join("long.lens"), job).expect("write");
        let out = crate::common::lensc(dir.path(), &["check", "long.lens"]);
        let err = crate::common::text(&out.stderr);
        assert!(err.contains("E0100"), "{err}");
        assert!(err.contains(&format!("long.lens:2:{} ]", n + 9)), "{err}");
        assert!(err.contains(&format!("…({} bytes)…", n + 8 - 80)), "{err}");
        assert!(err.len() < 2_000, "{} bytes", err.len());
        sizes.push(err.len());
    }
    assert!(sizes[1] - sizes[0] < 10, "{sizes:?}");
}
