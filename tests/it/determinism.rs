//! The same input gives the same bytes: a job is built on one thread and
//! on as many as the machine has (`RAYON_NUM_THREADS`, which the parallel
//! planners use), and every program and report must be byte-identical.
//!
//! The examples whose programs run to tens of millions of points (seed
//! 002's rollers, seed 003's array) prove nothing here that their small
//! copies in tests/jobs/ do not: the same planners with the same batching,
//! in fewer revolutions. Those copies stand in for them; every other
//! example is rebuilt on one thread and compared with its one build on
//! many ([`built_examples`]).

use std::collections::BTreeMap;

use crate::common::{Built, Written, build_into, built_examples, read_written, root};

/// Every file of both builds must be the same bytes.
fn assert_same(what: &str, one: &BTreeMap<String, Written>, many: &BTreeMap<String, Written>) {
    assert_eq!(
        one.keys().collect::<Vec<_>>(),
        many.keys().collect::<Vec<_>>(),
        "{what}: different files"
    );
    for (name, a) in one {
        let (Written::Whole(a), Written::Whole(b)) = (a, &many[name]) else {
            panic!("{what}: {name} is too large to compare here");
        };
        assert!(a == b, "{name} differs between 1 thread and many");
    }
}

/// Whether every file of a build was kept whole (is small enough).
fn small(built: &Built) -> bool {
    built.files.values().all(|f| matches!(f, Written::Whole(_)))
}

#[test]
fn one_thread_and_many_build_the_same_bytes() {
    let mut compared = 0;
    for built in built_examples().iter().filter(|b| small(b)) {
        let (one, _) = build_into(&built.example, Some("1"));
        let one = read_written(one.path());
        assert_same(&built.example, &one, &built.files);
        compared += one.len();
    }
    assert!(compared >= 20, "{compared} files");
}

#[test]
fn the_small_copies_of_the_largest_jobs_build_the_same_bytes() {
    let mut jobs: Vec<String> = std::fs::read_dir(root().join("tests/jobs"))
        .expect("tests/jobs")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|name| name.ends_with(".lens"))
        .map(|name| format!("tests/jobs/{name}"))
        .collect();
    jobs.sort();
    assert!(jobs.len() >= 3, "{jobs:?}");
    for job in jobs {
        let (one, _) = build_into(&job, Some("1"));
        let (many, _) = build_into(&job, None);
        assert_same(&job, &read_written(one.path()), &read_written(many.path()));
    }
}

/// A whole-part simulation in tiles (issue #15) reports the same on one
/// thread as on two: seed 003's 2 × 2 corner lenslet by lenslet (two runs
/// of columns each at 2 µm) and the small roller in runs of columns, the
/// statistics merged in the tiles' order whichever thread finished first.
#[test]
fn a_whole_part_in_tiles_reports_the_same_on_any_number_of_threads() {
    let dir = tempfile::tempdir().expect("tmp");
    // Both coarse copies miss their criteria away from their default
    // windows (the corner 175 nm PV, the roller 153): they are built here
    // for their figures, not to pass.
    let roller_accept = "accept: { form_pv: 200 nm, form_rms: 50 nm, max_gouge: 100 nm, max_residual: 100 nm, uncut_area: 0 } }";
    let corner_accept = "accept: { form_pv: 200 nm, form_rms: 10 nm, max_residual: 200 nm, max_following_error: 500 nm } }";
    for (job, stated) in [
        ("fts_small_array", corner_accept),
        ("roller_small", roller_accept),
    ] {
        let src = std::fs::read_to_string(root().join(format!("tests/jobs/{job}.lens")))
            .expect("the small job")
            .replace(stated, "accept: none }");
        let (end, extra) = ("accept: none }", "");
        assert!(src.contains(end), "{job}'s job line");
        let whole = src.replace(
            end,
            &format!(
                "{}{extra}, simulate: {{ spacing: 2 um }} }}",
                &end[..end.len() - 2]
            ),
        );
        let path = dir.path().join(format!("{job}.lens"));
        std::fs::write(&path, whole).expect("write");
        let file = path.to_str().expect("utf8");
        let (one, _) = build_into(file, Some("1"));
        let (two, _) = build_into(file, Some("2"));
        let (one, two) = (read_written(one.path()), read_written(two.path()));
        assert_same(job, &one, &two);
        let report = one
            .iter()
            .find(|(name, _)| name.ends_with(".report.json"))
            .map(|(_, w)| match w {
                Written::Whole(bytes) => String::from_utf8_lossy(bytes).into_owned(),
                _ => panic!("a small report"),
            })
            .expect("a report");
        let report: serde_json::Value = serde_json::from_str(&report).expect("JSON");
        let tiles = report["simulation"]["height_map"]["grid"]["tiles"]
            .as_u64()
            .expect("tiles");
        assert!(tiles >= 5, "{job}: {tiles} tiles");
    }
}
