//! The plan-time checks fire on deliberately bad jobs: each file in
//! tests/bad_builds/ is built, and what `lensc build` says is compared with
//! its reviewed snapshot (tests/snapshots/bad_builds/). A file whose only
//! findings are warnings builds (exit 0); any error means exit 1 and no
//! program.

use crate::common::{lensc, root, text};

#[test]
fn every_bad_build_is_reported_and_snapshotted() {
    let mut files: Vec<_> = std::fs::read_dir(root().join("tests/bad_builds"))
        .expect("tests/bad_builds")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "lens"))
        .collect();
    files.sort();
    assert!(files.len() >= 10, "the corpus has {} files", files.len());
    for path in files {
        let dir = tempfile::tempdir().expect("tmp");
        let rel = path
            .strip_prefix(root())
            .expect("inside the repo")
            .to_str()
            .expect("utf-8")
            .to_string();
        let out = lensc(
            &root(),
            &["build", &rel, "--out", dir.path().to_str().expect("utf-8")],
        );
        let stderr = text(&out.stderr).replace(dir.path().to_str().expect("utf-8"), "OUT");
        let has_error = stderr.lines().any(|l| l.starts_with("[E"));
        assert_eq!(
            out.status.code(),
            Some(if has_error { 1 } else { 0 }),
            "{rel}: {stderr}"
        );
        assert!(
            stderr
                .lines()
                .any(|l| l.starts_with("[E") || l.starts_with("[W")),
            "{rel} reports nothing: {stderr}"
        );
        let written = std::fs::read_dir(dir.path()).map_or(0, |d| d.count());
        if has_error {
            assert_eq!(written, 0, "{rel}: output left behind");
        }
        let name = path
            .file_stem()
            .expect("stem")
            .to_string_lossy()
            .to_string();
        insta::with_settings!({ snapshot_path => "../snapshots/bad_builds", prepend_module_to_snapshot => false, omit_expression => true }, {
            insta::assert_snapshot!(name, stderr);
        });
    }
}

/// What only planning finds, and why: these codes come from the planned
/// path, for every file and strategy; every other code `build` reports,
/// `check` reports too.
const PLANNING_ONLY: &[(&str, &str)] = &[
    ("E0141", "the travel is checked against the planned moves"),
    (
        "E0146",
        "the stroke the spiral needs is known once it is planned",
    ),
    (
        "E0147",
        "the fast axis's acceleration is known once the spiral is planned",
    ),
    ("W0003", "the seams are found on the planned envelope"),
    (
        "W0004",
        "the pip at the centre is found on the planned moves",
    ),
    (
        "W0005",
        "the chords over tolerance are found on the planned spiral",
    ),
];

#[test]
fn check_reports_every_bad_build_error_that_needs_no_toolpath() {
    let codes = |stderr: &str| -> Vec<String> {
        stderr
            .lines()
            .filter(|l| l.starts_with("[E") || l.starts_with("[W"))
            .filter_map(|l| l.get(1..6).map(str::to_string))
            .collect()
    };
    let mut files: Vec<_> = std::fs::read_dir(root().join("tests/bad_builds"))
        .expect("tests/bad_builds")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "lens"))
        .collect();
    files.sort();
    for path in files {
        let rel = path.strip_prefix(root()).expect("inside the repo");
        let rel = rel.to_str().expect("utf-8");
        let dir = tempfile::tempdir().expect("tmp");
        let out = dir.path().to_str().expect("utf-8");
        let built = codes(&text(&lensc(&root(), &["build", rel, "--out", out]).stderr));
        let checked = lensc(&root(), &["check", rel]);
        let found = codes(&text(&checked.stderr));
        for code in &built {
            let planning = PLANNING_ONLY.iter().any(|(c, _)| c == code);
            if !planning {
                assert!(
                    found.contains(code),
                    "{rel}: `check` misses {code}: {found:?}"
                );
            }
        }
        let errors = found.iter().any(|c| c.starts_with('E'));
        assert_eq!(checked.status.code(), Some(i32::from(errors)), "{rel}");
    }
}

/// `--dialect` misspelled, or naming a dialect the machine does not offer:
/// the help names the one meant, or says how to add it to the machine.
#[test]
fn a_dialect_the_machine_does_not_offer_is_explained() {
    let dir = tempfile::tempdir().expect("tmp");
    let out = dir.path().to_str().expect("utf-8");
    let job = "examples/even_asphere_turning.lens";
    let mut seen = String::new();
    for dialect in [
        "siemens_840d_lath",
        "fanuc_0i_lath",
        "fanuc_0i_lathe",
        "fanuk",
    ] {
        let run = lensc(
            &root(),
            &[
                "build",
                job,
                "--out",
                out,
                "--dialect",
                dialect,
                "--color",
                "never",
            ],
        );
        assert_eq!(run.status.code(), Some(1), "{dialect}");
        seen.push_str(&format!("--- --dialect {dialect}\n{}", text(&run.stderr)));
    }
    insta::with_settings!({ snapshot_path => "../snapshots/bad_builds", prepend_module_to_snapshot => false, omit_expression => true }, {
        insta::assert_snapshot!("dialect_not_offered", seen);
    });
}
