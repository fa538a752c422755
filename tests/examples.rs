//! Every example checks clean (no errors, no warnings) and builds.

mod common;

use common::{buildable_examples, examples, lensc, root, surface_names, text};

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

/// Programs above this size are snapshotted by their head, their tail,
/// their length and a hash of the whole (which still pins every byte): the
/// raster programs run to hundreds of kilobytes, the fast-tool-servo one
/// to hundreds of megabytes.
const WHOLE_SNAPSHOT_LIMIT: usize = 256 << 10;

/// Builds every example (they must all build) and compares each program
/// with its reviewed snapshot.
#[test]
fn example_programs_match_their_snapshots() {
    let dir = tempfile::tempdir().expect("tmp");
    for ex in buildable_examples() {
        let rel = ex
            .strip_prefix(root())
            .expect("inside repo")
            .to_str()
            .expect("utf8")
            .to_string();
        let out = lensc(
            &root(),
            &["build", &rel, "--out", dir.path().to_str().expect("utf8")],
        );
        assert_eq!(out.status.code(), Some(0), "{rel}: {}", text(&out.stderr));
    }
    let mut programs: Vec<_> = std::fs::read_dir(dir.path())
        .expect("out")
        .map(|e| e.expect("e").path())
        .filter(|p| p.extension().is_some_and(|e| e == "ngc"))
        .collect();
    programs.sort();
    for p in programs {
        let name = p.file_name().expect("name").to_string_lossy().to_string();
        let program = std::fs::read_to_string(&p).expect("program");
        let program = if program.len() > WHOLE_SNAPSHOT_LIMIT {
            abridged(&program)
        } else {
            program
        };
        insta::with_settings!({ snapshot_path => "snapshots/programs", prepend_module_to_snapshot => false, omit_expression => true }, {
            insta::assert_snapshot!(name, program);
        });
    }
}

/// The first 40 lines, the number of lines and bytes with the FNV-1a 64
/// hash of the whole text, and the last 3 lines.
fn abridged(program: &str) -> String {
    let lines: Vec<&str> = program.lines().collect();
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in program.bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    let mut out = lines[..40.min(lines.len())].join("\n");
    out.push_str(&format!(
        "\n… {} lines, {} bytes, fnv1a64 {h:016x} …\n",
        lines.len(),
        program.len()
    ));
    out.push_str(&lines[lines.len().saturating_sub(3)..].join("\n"));
    out.push('\n');
    out
}

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
