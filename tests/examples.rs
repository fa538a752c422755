//! Every example checks clean (no errors, no warnings) and builds.

mod common;

use common::{examples, lensc, root, text};

#[test]
fn every_example_checks_clean() {
    let list = examples();
    assert!(!list.is_empty());
    for ex in list {
        let out = lensc(&root(), &["check", ex.to_str().expect("utf8")]);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}: {}",
            ex.display(),
            text(&out.stderr)
        );
        assert!(
            out.stderr.is_empty(),
            "{} has warnings: {}",
            ex.display(),
            text(&out.stderr)
        );
    }
}

#[test]
fn every_example_builds() {
    let dir = tempfile::tempdir().expect("tmp");
    for ex in examples() {
        let out = lensc(
            &root(),
            &[
                "build",
                ex.to_str().expect("utf8"),
                "--out",
                dir.path().to_str().expect("utf8"),
            ],
        );
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}: {}",
            ex.display(),
            text(&out.stderr)
        );
    }
}
