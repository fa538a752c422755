//! The plan-time checks fire on deliberately bad jobs: each file in
//! tests/bad_builds/ is built, and what `lensc build` says is compared with
//! its reviewed snapshot (tests/snapshots/bad_builds/). A file whose only
//! findings are warnings builds (exit 0); any error means exit 1 and no
//! program.

use crate::common::{judged_whole_and_passed, lensc, root, text};

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
        } else {
            // Issue #29: a job that builds is judged on its whole part
            // and passes, or says it is not judged (`accept: none`).
            for report in reports_in(dir.path()) {
                if report["acceptance"]["mode"] != "none" {
                    judged_whole_and_passed(&report)
                        .unwrap_or_else(|why| panic!("{rel}: {}: {why}", report["job"]));
                }
            }
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
        "E0195",
        "the acceptance gate compares the part the planned program cuts",
    ),
    (
        "E0196",
        "what the simulation of the planned program cannot measure",
    ),
    (
        "W0004",
        "the pip at the centre is found on the planned moves",
    ),
    (
        "W0005",
        "the chords over tolerance are found on the planned spiral",
    ),
    ("W0030", "the cutting time is the planned path's"),
    (
        "W0031",
        "the approach is the planned program's first feed move",
    ),
    (
        "W0032",
        "the time in the air is summed over the planned moves",
    ),
    (
        "E0380",
        "a part's own lines are known once the program is written",
    ),
    ("E0381", "the joins are the written program's retracts"),
    ("E0382", "the program's size is known once it is written"),
    (
        "W0050",
        "the bytes and the cutting time are the written program's",
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

/// `--accept=warn` turns a job's acceptance errors into warnings: the
/// program and its report are written, the report's `acceptance` says
/// which criterion failed, by the figure measured.
#[test]
fn accept_warn_writes_the_program_and_reports_the_miss() {
    let dir = tempfile::tempdir().expect("tmp");
    let out = dir.path().to_str().expect("utf-8");
    let file = "tests/bad_builds/accept_form_pv_missed.lens";
    let gated = lensc(&root(), &["build", file, "--out", out]);
    assert_eq!(gated.status.code(), Some(1));
    assert!(text(&gated.stderr).contains("[E0195]"));
    assert_eq!(std::fs::read_dir(dir.path()).expect("out").count(), 0);
    let warned = lensc(&root(), &["build", file, "--out", out, "--accept=warn"]);
    let stderr = text(&warned.stderr);
    assert_eq!(warned.status.code(), Some(0), "{stderr}");
    assert!(
        stderr.contains("[W0020]") && !stderr.contains("[E0195]"),
        "{stderr}"
    );
    assert!(dir.path().join("sphere.ngc").exists());
    let report: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("sphere.report.json")).expect("report"),
    )
    .expect("json");
    let a = &report["acceptance"];
    assert_eq!(a["mode"], "warn");
    assert_eq!(a["passed"], false);
    let pv = a["criteria"]
        .as_array()
        .expect("criteria")
        .iter()
        .find(|c| c["criterion"] == "form_pv")
        .expect("form_pv");
    assert_eq!(pv["passed"], false);
    assert_eq!(pv["source"], "stated");
    assert_eq!(pv["limit"], 50.0);
    // The figure the report's simulation gives, not another.
    assert_eq!(pv["measured"], report["simulation"]["form_error_pv_nm"]);
    assert!(pv["measured"].as_f64().expect("measured") > 50.0);
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

/// The reports a build wrote into `dir`.
fn reports_in(dir: &std::path::Path) -> Vec<serde_json::Value> {
    let mut reports = Vec::new();
    for entry in std::fs::read_dir(dir).expect("out dir") {
        let path = entry.expect("entry").path();
        if path.to_string_lossy().ends_with(".report.json") {
            let text = std::fs::read_to_string(&path).expect("report");
            reports.push(serde_json::from_str(&text).expect("json"));
        }
    }
    assert!(!reports.is_empty(), "{}: no report", dir.display());
    reports
}

/// Issue #33: every strategy refuses a part beyond the machine's travel in
/// `check`, before anything is planned, as the spiral did (E0141, naming
/// the part's reach and the travel). Until then the turning, grinding and
/// raster jobs here were refused only by their planned path, at `build`,
/// and the roller's by the read-back of its program (E0313): `check`
/// passed all four.
#[test]
fn check_refuses_a_part_beyond_the_travel_for_every_strategy() {
    // Each file, how many axes it is beyond, and what the refusals say.
    let cases: [(&str, usize, &[&str]); 4] = [
        (
            "turning_part_beyond_travel.lens",
            1,
            &[
                "reaches 200 mm from the spindle axis",
                "X travel -10 .. 150 mm",
            ],
        ),
        (
            "grinding_part_beyond_travel.lens",
            1,
            &[
                "reaches 200 mm from the spindle axis",
                "X travel -50 .. 50 mm",
            ],
        ),
        (
            "raster_part_beyond_travel.lens",
            2,
            &["X travel -250 .. 250 mm", "Y travel -200 .. 200 mm"],
        ),
        (
            "roller_blank_beyond_travel.lens",
            2,
            &[
                "starts outside it at X 302.427567 mm",
                "Z travel -150 .. 150 mm",
            ],
        ),
    ];
    for (file, axes, says) in cases {
        let rel = format!("tests/bad_builds/{file}");
        let out = lensc(&root(), &["check", &rel]);
        let stderr = text(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{rel}: {stderr}");
        let refusals: Vec<&str> = stderr
            .lines()
            .filter(|l| l.starts_with("[E0141]") && l.contains("beyond the machine's"))
            .collect();
        assert_eq!(refusals.len(), axes, "{rel}: {stderr}");
        for words in says {
            assert!(
                refusals.iter().any(|l| l.contains(words)),
                "{rel}: {words}: {stderr}"
            );
        }
    }
}
