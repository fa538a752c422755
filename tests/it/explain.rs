//! `lensc explain`: every code lensc emits has a long explanation
//! (compiler/lang/explain/CODE.md), and every example in one does what it
//! says: a `lens error` example makes `lensc check` (or, for what only
//! planning finds, `lensc build`) report the code; a `lens fix` example
//! checks without errors and without the code.

use std::path::Path;

use lensc_lang::explain::{self, Expect};

use crate::common::{lensc, root, text};

/// What a new code's author must add, said once for every failure.
fn how_to_add(code: &str) -> String {
    format!(
        "{code} has no long explanation: add compiler/lang/explain/{code}.md \
         (compiler/lang/build.rs picks it up; nothing else to edit). Copy \
         compiler/lang/explain/E0147.md for its shape: a first line \
         `# {code}: what it means`, paragraphs on why it happens and what to \
         write instead, a ```lens error block that `lensc check` or `lensc \
         build` (saved as example.lens) answers with {code}, and a ```lens fix \
         block, the same file corrected. If no small file can cause it, give a \
         ```console block instead and the line \
         `<!-- no lens example: why -->`."
    )
}

#[test]
fn every_code_has_an_explanation_with_a_title_and_an_example() {
    let mut problems = Vec::new();
    for code in explain::every_code() {
        let Some((_, text)) = explain::explain(code) else {
            problems.push(how_to_add(code));
            continue;
        };
        if !text.starts_with(&format!("# {code}: ")) || explain::title(text).is_empty() {
            problems.push(format!(
                "compiler/lang/explain/{code}.md must start with `# {code}: what it means`"
            ));
        }
        let has_error_example = explain::examples(text)
            .iter()
            .any(|e| e.expect == Expect::Error);
        if !has_error_example && !text.contains("<!-- no lens example: ") {
            problems.push(format!(
                "compiler/lang/explain/{code}.md has no ```lens error example (nor a \
                 `<!-- no lens example: why -->` line saying why none can be given)"
            ));
        }
    }
    let codes: Vec<&str> = explain::every_code().collect();
    for (code, _) in explain::all() {
        if !codes.contains(code) {
            problems.push(format!(
                "compiler/lang/explain/{code}.md explains a code that is not in \
                 codes::ALL (or lensc_grammar's codes::ALL): add the code there, or \
                 remove the file"
            ));
        }
    }
    assert!(problems.is_empty(), "\n{}\n", problems.join("\n\n"));
}

/// `lensc check`, then (when `then_build` and the check found no error)
/// `lensc build` with `args`; what each printed on stderr, and whether the
/// build ran.
fn run(dir: &Path, args: &[String], then_build: bool) -> (String, bool) {
    let checked = text(&lensc(dir, &["check", "example.lens", "--color", "never"]).stderr);
    if !then_build || checked.lines().any(|l| l.starts_with("[E")) {
        return (checked, false);
    }
    let mut build = vec!["build", "example.lens", "--out", "out", "--color", "never"];
    build.extend(args.iter().map(String::as_str));
    (
        format!("{checked}{}", text(&lensc(dir, &build).stderr)),
        true,
    )
}

#[test]
fn every_example_gives_its_code_and_every_fix_does_not() {
    let mut failures = Vec::new();
    let mut tried = 0;
    for (code, md) in explain::all() {
        let tag = format!("[{code}]");
        // A code the checker finds needs no build of its fix.
        let mut needs_build = false;
        for ex in explain::examples(md) {
            tried += 1;
            let dir = tempfile::tempdir().expect("tmp");
            std::fs::write(dir.path().join("example.lens"), &ex.source).expect("write");
            match ex.expect {
                Expect::Error => {
                    let checked = run(dir.path(), &ex.args, false).0;
                    if checked.contains(&tag) {
                        continue;
                    }
                    needs_build = true;
                    let (out, _) = run(dir.path(), &ex.args, true);
                    if !out.contains(&tag) {
                        failures.push(format!(
                            "{code}.md: its `lens error` example does not give {code}:\n{out}"
                        ));
                    }
                }
                Expect::Fix => {
                    let (out, _) = run(dir.path(), &ex.args, needs_build);
                    if out.contains(&tag) || out.lines().any(|l| l.starts_with("[E")) {
                        failures.push(format!(
                            "{code}.md: its `lens fix` example still gives {code} or an error:\n{out}"
                        ));
                    }
                }
            }
        }
    }
    assert!(tried > 100, "only {tried} examples");
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

#[test]
fn explain_prints_the_explanation_and_its_json() {
    let out = lensc(&root(), &["explain", "E0147"]);
    assert_eq!(out.status.code(), Some(0));
    let human = text(&out.stdout);
    insta::with_settings!({ snapshot_path => "../snapshots/cli", prepend_module_to_snapshot => false, omit_expression => true }, {
        insta::assert_snapshot!("explain_E0147", human);
    });
    // Written however a person types it.
    let lower = lensc(&root(), &["explain", "e147"]);
    assert_eq!(text(&lower.stdout), human);

    let json = lensc(&root(), &["explain", "E0147", "--format", "json"]);
    let v: serde_json::Value = serde_json::from_slice(&json.stdout).expect("JSON");
    assert_eq!(v["code"], "E0147");
    assert_eq!(v["severity"], "error");
    assert_eq!(
        v["title"],
        "a fast axis that would accelerate beyond its limit"
    );
    assert!(
        v["text"]
            .as_str()
            .expect("text")
            .contains("max_acceleration")
    );
    assert_eq!(v["examples"][0]["expect"], "error");
    assert_eq!(v["examples"][1]["expect"], "fix");

    let unknown = lensc(&root(), &["explain", "E0999"]);
    assert_eq!(unknown.status.code(), Some(2));
    assert!(text(&unknown.stderr).contains("lensc explain --list"));
}
