//! Chords on either side of the curve (#15, item 5): a strategy's
//! `chords: on_path | straddle | clear`, built and simulated, against what
//! each promises: the same points; on the path, convex stretches gouge by
//! up to the chords' sag; straddling, the error split to about ±half of
//! it (half the PV); clear, no gouge beyond the machine's resolution (the
//! points are raised half of it more, so rounding cannot cut either). And
//! the default: the least displacement that meets the job's `max_gouge`.

use crate::common::{lensc, text};

/// The machines' resolution here (mm): both state 1 nm.
const RESOLUTION_NM: f64 = 1.0;

/// A fast-tool-servo job on waves across x, 2 µm high, 0.5 mm long: along
/// the spiral W rises and falls, so half the chords are on convex
/// stretches; a 200 nm tolerance gives the chords 50 nm (T/4), far above
/// the resolution.
fn waves(chords: &str, accept: &str) -> String {
    format!(
        "surface waves = freeform {{\n\
             z(x, y) = 2 um * cos(12.566370614359172 rad/mm * x)\n\
             domain: circle(diameter: 2 mm)\n\
         }}\n\
         use std::machines::nanoform_x_fts5000\n\
         use std::tools::diamond_r496um\n\
         strategy s = fts_spiral {{ feed: 20 um/rev, spindle_speed: 60 rpm, chord_tolerance: 200 nm{chords} }}\n\
         job waves {{ surface: waves, tool: diamond_r496um, machine: nanoform_x_fts5000, strategy: s{accept} }}\n"
    )
}

/// A roller job: ripples 2 µm high, 0.5 mm long around a 1 mm roller, cut
/// with a 1° C step: chords of 17.45 µm of arc on the design's 3.17 mm
/// convex radius sag by 17.45² / (8 × 3.17) µm = 12 nm (the nose centre's
/// path, 0.1 mm further out, a little less).
fn ripples(chords: &str) -> String {
    format!(
        "surface ripples = freeform {{\n\
             z(x, y) = 2 um * cos(12.566370614359172 rad/mm * y) - 2 um\n\
             domain: rect(x: 0 mm .. 0.4 mm, y: 0 mm .. 6.283185307179586 mm)\n\
         }}\n\
         surface roller_ripples = wrap(ripples, onto: roller(radius: 1 mm))\n\
         use std::machines::moore_nanotech_450fg\n\
         tool nose = round_nose {{ nose_radius: 0.1 mm, clearance: 12 deg, included_angle: 100 deg }}\n\
         strategy s = roller_helix {{ finish: {{ c_step: 1 deg, pitch: 5 um }}, z: 0.1 mm .. 0.3 mm, spindle_speed: 60 rpm{chords} }}\n\
         job ripples {{ surface: roller_ripples, tool: nose, machine: moore_nanotech_450fg, strategy: s,\n\
             accept: {{ max_gouge: 200 nm, max_residual: 200 nm, form_pv: 200 nm, form_rms: 100 nm }} }}\n"
    )
}

/// What the build's simulation found at the contacts, and the plan.
#[derive(Debug)]
struct Figures {
    chords: String,
    points: u64,
    pv: f64,
    rms: f64,
    mean: f64,
    gouge: f64,
    residual: f64,
}

/// Builds `source` (exit 0) and reads job `job`'s report.
fn build(source: &str, job: &str) -> Figures {
    let dir = tempfile::tempdir().expect("tmp");
    std::fs::write(dir.path().join("job.lens"), source).expect("write");
    let out_dir = dir.path().to_str().expect("utf8");
    let out = lensc(dir.path(), &["build", "job.lens", "--out", out_dir]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let path = dir.path().join(format!("{job}.report.json"));
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).expect("report")).expect("json");
    let num = |v: &serde_json::Value| v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"));
    let c = &r["simulation"]["height_map"]["contact"];
    let tp = &r["toolpath"];
    Figures {
        chords: tp["chords"].as_str().expect("chords").to_string(),
        points: tp["cut_points"].as_u64().expect("points"),
        pv: num(&c["pv_nm"]),
        rms: num(&c["rms_nm"]),
        mean: num(&c["mean_nm"]),
        gouge: num(&c["max_gouge_nm"]["value"]),
        residual: num(&c["max_residual_nm"]["value"]),
    }
}

/// Each placement against its promise, for chords that sag up to `sag`
/// (nm) on the path.
fn each_meets_its_promise(sag: f64, job: &str, source: impl Fn(&str) -> String) {
    let [on, straddle, clear] =
        ["on_path", "straddle", "clear"].map(|w| build(&source(&format!(", chords: {w}")), job));
    assert_eq!(
        (
            on.chords.as_str(),
            straddle.chords.as_str(),
            clear.chords.as_str()
        ),
        ("on_path", "straddle", "clear")
    );
    // The same points, moved.
    assert!(on.points == straddle.points && on.points == clear.points);
    // On the path the convex stretches gouge by about the sag.
    assert!(
        on.gouge > 0.75 * sag && on.gouge <= sag + RESOLUTION_NM,
        "{on:?}"
    );
    // Straddling: half of it either way, half the PV and RMS.
    let half = 0.5 * sag + RESOLUTION_NM;
    assert!(
        straddle.gouge <= half && straddle.residual <= half,
        "{straddle:?}"
    );
    assert!(
        straddle.pv <= 0.6 * on.pv && straddle.rms <= 0.6 * on.rms,
        "{straddle:?} {on:?}"
    );
    assert!(straddle.mean.abs() <= 0.1 * sag, "{straddle:?}");
    // Clear: no gouge beyond the resolution (none at all, measured), the
    // part proud by up to the sag instead.
    assert!(clear.gouge <= RESOLUTION_NM, "{clear:?}");
    assert!(clear.residual <= sag + 2.0 * RESOLUTION_NM, "{clear:?}");
    assert!(clear.mean > straddle.mean, "{clear:?} {straddle:?}");
}

#[test]
fn on_a_fast_tool_servo_spiral_each_placement_meets_its_promise() {
    // Measured: on the path PV 92.0, RMS 19.7, gouge 49.3 nm; straddling
    // 49.7, 10.3, 25.3 nm; clear 50.0, 11.6, 0.00 nm.
    each_meets_its_promise(50.0, "waves", |c| {
        waves(c, ", accept: { max_gouge: 200 nm }")
    });
}

#[test]
fn on_a_roller_helix_each_placement_meets_its_promise() {
    // Measured: on the path PV 21.8, RMS 5.5, gouge 10.0 nm; straddling
    // 11.2, 2.5, 5.5 nm; clear 11.9, 2.9, 0.00 nm.
    each_meets_its_promise(12.0, "ripples", ripples);
}

#[test]
fn by_default_the_least_displacement_that_meets_max_gouge() {
    let chosen = |accept: &str| build(&waves("", accept), "waves");
    // Chords sag up to 50 nm on the path: a 60 nm limit keeps them there,
    // 30 nm needs them straddled (25 nm), 0 nm clear; with no limit
    // stated they stay on the path.
    assert_eq!(chosen("").chords, "on_path");
    assert_eq!(chosen(", accept: { max_gouge: 60 nm }").chords, "on_path");
    assert_eq!(chosen(", accept: { max_gouge: 30 nm }").chords, "straddle");
    // `max_gouge: 0` passes the gate: nothing cut below the design.
    let clear = chosen(", accept: { max_gouge: 0 nm }");
    assert_eq!(clear.chords, "clear");
    assert_eq!(clear.gouge, 0.0, "{clear:?}");
}
