//! What the programs cut, simulated from the moves they command (after
//! optimisation, rounded to the machine's resolution), against the
//! design: issue #6's figures, read from the build reports.

mod common;

use common::{lensc, root, text};

/// Builds `example` and returns every report it wrote.
fn reports(example: &str) -> Vec<serde_json::Value> {
    let dir = tempfile::tempdir().expect("tmp");
    let out = lensc(
        &root(),
        &[
            "build",
            example,
            "--out",
            dir.path().to_str().expect("utf8"),
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let mut found: Vec<_> = std::fs::read_dir(dir.path())
        .expect("out")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.to_string_lossy().ends_with(".report.json"))
        .collect();
    found.sort();
    found
        .iter()
        .map(|p| serde_json::from_str(&std::fs::read_to_string(p).expect("report")).expect("json"))
        .collect()
}

#[test]
fn profile_programs_cut_within_a_nanometre_rms_and_five_pv() {
    // Every profile job with nothing the tool cannot reach: turning (seed
    // 004's method on the asphere, Forbes, even-asphere jobs) and the
    // paper's own grinding of seed 001 on Table 1's 2 nm machine. The
    // papers measured 100-270 nm on real machines: the program must be a
    // hundred times better than that.
    let mut seen = Vec::new();
    for example in [
        "examples/kim2008_convex_asphere.lens",
        "examples/kim2008_concave_asphere.lens",
        "examples/forbes_qcon_asphere.lens",
        "examples/forbes_qbfs_mould.lens",
        "examples/even_asphere_turning.lens",
    ] {
        for r in reports(example) {
            let job = r["job"].as_str().expect("job").to_string();
            let sim = &r["simulation"];
            let pv = sim["form_error_pv_nm"].as_f64().expect("pv");
            let rms = sim["form_error_rms_nm"].as_f64().expect("rms");
            assert!(
                r["toolpath"]["seams"]
                    .as_array()
                    .is_none_or(|s| s.is_empty()),
                "{job}"
            );
            assert!(sim["samples"].as_u64().expect("samples") > 10_000, "{job}");
            println!("{job}: PV {pv:.2} nm, RMS {rms:.2} nm");
            assert!(rms <= 1.0, "{job}: RMS {rms} nm");
            assert!(pv <= 5.0, "{job}: PV {pv} nm");
            // The error is measured, not zero: chords, arcs and rounding.
            assert!(rms > 0.01, "{job}: RMS {rms} nm");
            seen.push(job);
        }
    }
    for job in [
        "kim_convex",
        "kim_convex_grinding",
        "kim_concave",
        "kim_concave_grinding",
    ] {
        assert!(seen.iter().any(|j| j == job), "{job} not simulated");
    }
}

#[test]
fn where_the_nose_cannot_follow_the_report_says_how_much_and_where() {
    // Seed 004: the 0.5 mm nose cannot reach the seams between the
    // cylinders. The simulated cut leaves most material at the deepest
    // seam the planner found, as deep as it said.
    let r = reports("examples/lei2021_cylinder_array.lens").remove(0);
    let seams = r["toolpath"]["seams"].as_array().expect("seams");
    let deepest = seams
        .iter()
        .max_by(|a, b| {
            a["uncut_depth_mm"]
                .as_f64()
                .expect("depth")
                .total_cmp(&b["uncut_depth_mm"].as_f64().expect("depth"))
        })
        .expect("a seam");
    let depth_nm = deepest["uncut_depth_mm"].as_f64().expect("depth") * 1e6;
    let at = deepest["at_radius_mm"].as_f64().expect("at");
    let residual = &r["simulation"]["max_residual_nm"];
    let value = residual["value"].as_f64().expect("value");
    let where_ = residual["at_radius_mm"].as_f64().expect("at");
    assert!(
        (value - depth_nm).abs() < 0.001 * depth_nm,
        "{value} vs {depth_nm}"
    );
    assert!((where_ - at).abs() < 1e-3, "{where_} vs {at}");
    // Nowhere does the program cut into the design.
    let gouge = r["simulation"]["max_gouge_nm"]["value"]
        .as_f64()
        .expect("gouge");
    assert!(gouge < 2.0, "{gouge} nm");
}
