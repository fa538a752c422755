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

/// The fast-tool-servo simulation of a row of four seed 003 lenslets
/// (centres at 1.75 and 5.25 mm from the axis) cut at `speed`.
fn following_over_a_row(speed: &str) -> Vec<(f64, f64, f64)> {
    let dir = tempfile::tempdir().expect("tmp");
    let file = dir.path().join("row.lens");
    std::fs::write(
        &file,
        format!(
            "surface lenslet = sphere {{ radius: 20 mm, sense: concave, aperture: circle(diameter: 1.7 mm) }}\n\
             surface row = grid(lenslet, pitch_x: 3.5 mm, pitch_y: 3.5 mm, count_x: 4, count_y: 1)\n\
             use std::machines::nanoform_x_fts5000\n\
             use std::tools::diamond_r496um\n\
             strategy s = fts_spiral {{ feed: 50 um/rev, {speed}, settling_time: 1 ms, chord_tolerance: 50 nm }}\n\
             job row_fts {{ surface: row, tool: diamond_r496um, machine: nanoform_x_fts5000, strategy: s }}\n"
        ),
    )
    .expect("write");
    let out = lensc(
        dir.path(),
        &[
            "build",
            "row.lens",
            "--out",
            dir.path().to_str().expect("utf8"),
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let r: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("row_fts.report.json")).expect("report"),
    )
    .expect("json");
    let sim = &r["simulation"];
    assert!(sim["servo_samples"].as_u64().expect("samples") > 100_000);
    sim["lenslets"]
        .as_array()
        .expect("lenslets")
        .iter()
        .map(|l| {
            assert!(l["samples"].as_u64().expect("n") > 1000);
            (
                l["radius_mm"].as_f64().expect("r"),
                l["rms_error_nm"].as_f64().expect("rms"),
                l["waviness_urad"].as_f64().expect("waviness"),
            )
        })
        .collect()
}

/// Mean RMS error and waviness of the outer lenslets over the inner ones.
fn outer_over_inner(lenslets: &[(f64, f64, f64)]) -> (f64, f64) {
    let mean = |outer: bool, k: usize| {
        let v: Vec<f64> = lenslets
            .iter()
            .filter(|l| (l.0 > 3.0) == outer)
            .map(|l| if k == 1 { l.1 } else { l.2 })
            .collect();
        assert_eq!(v.len(), 2);
        v.iter().sum::<f64>() / 2.0
    };
    (
        mean(true, 1) / mean(false, 1),
        mean(true, 2) / mean(false, 2),
    )
}

#[test]
fn at_constant_rpm_the_outer_lenslets_wave_more_and_constant_surface_speed_evens_them() {
    // Seed 003, qualitatively: at a constant spindle speed the tool crosses
    // the outer lenslets three times faster than the inner ones, and the
    // servo lags and rings more there; at constant surface speed every
    // lenslet is crossed alike.
    let rpm = outer_over_inner(&following_over_a_row("spindle_speed: 300 rpm"));
    let css = outer_over_inner(&following_over_a_row(
        "surface_speed: 5 m/min, spindle_cap: 1000 rpm",
    ));
    println!(
        "outer/inner at constant rpm: error {:.2}, waviness {:.2}",
        rpm.0, rpm.1
    );
    println!(
        "outer/inner at constant surface speed: error {:.2}, waviness {:.2}",
        css.0, css.1
    );
    // The error follows the crossing speed (3x); its slope, partly the
    // ringing at each lenslet's edge, less so but clearly.
    assert!(rpm.0 > 2.5 && rpm.1 > 1.5, "{rpm:?}");
    assert!(
        (css.0 - 1.0).abs() < 0.1 && (css.1 - 1.0).abs() < 0.1,
        "{css:?}"
    );
}
