//! Every example checks clean (no errors, no warnings) and builds.

use crate::common::{Written, built_examples, examples, lensc, root, surface_names, text};

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

/// Builds every example (they must all build) and compares each program
/// with its reviewed snapshot; programs above `WHOLE_SNAPSHOT_LIMIT` are
/// snapshot abridged (see `common::abridged`).
#[test]
fn example_programs_match_their_snapshots() {
    let mut programs: Vec<(&String, &Written)> = built_examples()
        .iter()
        .flat_map(|b| &b.files)
        .filter(|(name, _)| name.ends_with(".ngc"))
        .collect();
    programs.sort_by_key(|(name, _)| *name);
    assert!(programs.len() >= 20, "{} programs", programs.len());
    for (name, file) in programs {
        let (name, program) = (name.clone(), file.snapshot());
        insta::with_settings!({ snapshot_path => "../snapshots/programs", prepend_module_to_snapshot => false, omit_expression => true }, {
            insta::assert_snapshot!(name, program);
        });
    }
}

/// The first 40 lines, the number of lines and bytes with the FNV-1a 64
/// hash of the whole text, and the last 3 lines.
#[test]
fn every_surface_of_every_example_samples() {
    for ex in examples() {
        for name in surface_names(&ex) {
            let out = lensc(
                &root(),
                &[
                    "sample",
                    ex.to_str().expect("utf8"),
                    "--surface",
                    &name,
                    "--grid",
                    "5",
                ],
            );
            assert_eq!(
                out.status.code(),
                Some(0),
                "{} {name}: {}",
                ex.display(),
                text(&out.stderr)
            );
            let csv = text(&out.stdout);
            let mut lines = csv.lines();
            assert_eq!(
                lines.next(),
                Some("x,y,z,dzdx,dzdy,curvature_x,curvature_y")
            );
            let rows: Vec<Vec<f64>> = lines
                .map(|l| l.split(',').map(|c| c.parse().expect("number")).collect())
                .collect();
            assert!(!rows.is_empty(), "{} {name}: no points", ex.display());
            assert!(
                rows.iter().flatten().all(|v| v.is_finite()),
                "{} {name}: {csv}",
                ex.display()
            );
        }
    }
}
