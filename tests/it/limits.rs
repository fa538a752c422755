//! Limits stated up front: every example's estimate (the report's
//! `estimate`, made before planning) is within 2× of the points and
//! program bytes its build wrote, and the limits are enforced by `build`,
//! `report` and `check` alike (the refusals themselves are snapshotted in
//! tests/bad_builds/limits_*.lens).

use crate::common::{built_examples, lensc, root, text};

#[test]
fn every_example_estimate_is_within_twice_what_its_build_writes() {
    let mut checked = 0;
    for b in built_examples() {
        for r in b.reports() {
            let job = r["job"].as_str().expect("job").to_string();
            let pairs = [
                (
                    "cut points",
                    &r["estimate"]["cut_points"],
                    &r["toolpath"]["cut_points"],
                ),
                (
                    "program bytes",
                    &r["estimate"]["program_bytes"],
                    &r["program"]["bytes"],
                ),
            ];
            for (what, est, actual) in pairs {
                let (est, actual) = (
                    est.as_f64().expect("estimate"),
                    actual.as_f64().expect("actual"),
                );
                let ratio = est / actual;
                assert!(
                    (0.5..=2.0).contains(&ratio),
                    "{} job {job}: {what} estimated {est}, written {actual} (×{ratio:.2})",
                    b.example
                );
            }
            checked += 1;
        }
    }
    assert!(checked >= 20, "only {checked} jobs checked");
}

#[test]
fn max_program_size_is_enforced_by_build_report_and_check() {
    let file = "examples/kim2008_convex_asphere.lens";
    let dir = tempfile::tempdir().expect("tmp");
    let out = dir.path().to_str().expect("utf-8");
    for args in [
        vec!["build", file, "--out", out, "--max-program-size", "2kB"],
        vec!["report", file, "--out", out, "--max-program-size", "2kB"],
        vec!["check", file, "--max-program-size", "2kB"],
    ] {
        let o = lensc(&root(), &args);
        let stderr = text(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(stderr.contains("[E0161]"), "{args:?}: {stderr}");
        assert!(stderr.contains("--max-program-size"), "{args:?}: {stderr}");
    }
    assert_eq!(std::fs::read_dir(dir.path()).expect("out").count(), 0);
    // Raised, the same file checks and builds.
    let o = lensc(&root(), &["check", file, "--max-program-size", "1GiB"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let o = lensc(&root(), &["check", file, "--max-program-size", "4 parsecs"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
}
