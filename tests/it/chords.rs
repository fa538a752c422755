//! Chords on either side of the curve (#15, item 5): a strategy's
//! `chords: on_path | straddle | straddle_long | clear`, built and
//! simulated, against what each promises: on the path, convex stretches
//! gouge by up to the chords' sag; straddling, the error within ±half of
//! it (half the PV), inflections included (chords split there);
//! straddling long chords, within ±the sag with fewer points; clear, no
//! gouge beyond the machine's resolution (the points are raised half of it
//! more, so rounding cannot cut either). For spirals, helices, rasters and
//! profile turning. And the default: the fewest points whose promise meets
//! the job's criteria.
//!
//!
//! What each placement promises is a property of its chords between the
//! path's inflections, so those tests read a 0.2 mm window of the part
//! (away from the rim and the roller's seam, between two inflections of
//! the waves). What the default placement promises is the part's: that it
//! meets the job's criteria, so those tests judge the whole part, as every
//! job is judged by default. The criteria are stated: the defaults are
//! what the machine holds (10 nm + its resolution), which the 200 and
//! 400 nm tolerances here do not loosen (issue #29), and a test of that
//! closes the file.

use crate::common::{lensc, text};

/// The machines' resolution here (mm): both state 1 nm.
const RESOLUTION_NM: f64 = 1.0;

/// A fast-tool-servo job on waves across x, 2 µm high, 0.5 mm long: along
/// the spiral W rises and falls, so half the chords are on convex
/// stretches; a 200 nm tolerance gives the chords 50 nm (T/4), far above
/// the resolution.
fn waves(chords: &str, accept: &str) -> String {
    waves_judged(
        chords,
        "simulate: { x: 0.4 mm .. 0.6 mm, y: -0.1 mm .. 0.1 mm }",
        accept,
    )
}

/// The waves judged on `judged` (a `simulate` block, or empty for the
/// whole part). Their servo is led by its controller: the points the
/// program cuts are then the planner's, which the placements are
/// compared on (where lensc leads the servo it adds points beside the
/// path's bends, more or fewer as a placement moves W).
fn waves_judged(chords: &str, judged: &str, accept: &str) -> String {
    let judged = if judged.is_empty() {
        String::new()
    } else {
        format!(", {judged}")
    };
    format!(
        "surface waves = freeform {{\n\
             z(x, y) = 2 um * cos(12.566370614359172 rad/mm * x)\n\
             domain: circle(diameter: 2 mm)\n\
         }}\n\
         use std::machines::nanoform_x_fts5000\n\
         use std::tools::diamond_r496um\n\
         machine led = nanoform_x_fts5000 {{ fast_axis: {{ feed_forward: inverse_model }} }}\n\
         strategy s = fts_spiral {{ feed: 20 um/rev, spindle_speed: 60 rpm, chord_tolerance: 200 nm{chords} }}\n\
         job waves {{ surface: waves, tool: diamond_r496um, machine: led, strategy: s{judged}{accept} }}\n"
    )
}

/// A roller job: twelve ripples 2 µm high around a 1 mm roller (0.52 mm
/// long, so the design closes at the seam), cut with a 1° C step: chords
/// of 17.45 µm of arc on the design's 3.47 mm convex radius sag by
/// 17.45² / (8 × 3.47) µm = 11 nm (the nose centre's path, 0.1 mm
/// further out, a little less). Judged on the whole part, at the limits
/// the job states.
fn ripples(chords: &str) -> String {
    format!(
        "surface ripples = freeform {{\n\
             z(x, y) = 2 um * cos(12 rad/mm * y) - 2 um\n\
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
    let tp = &r["toolpath"];
    let sim = &r["simulation"];
    // A height map's contacts, or a profile's radii.
    let (c, pv, rms, mean) = match sim.get("height_map") {
        Some(map) => (&map["contact"], "pv_nm", "rms_nm", "mean_nm"),
        None => (
            sim,
            "form_error_pv_nm",
            "form_error_rms_nm",
            "form_error_mean_nm",
        ),
    };
    let figures = Figures {
        chords: tp["chords"].as_str().expect("chords").to_string(),
        points: tp["cut_points"].as_u64().expect("points"),
        pv: num(&c[pv]),
        rms: num(&c[rms]),
        mean: num(&c[mean]),
        gouge: num(&c["max_gouge_nm"]["value"]),
        residual: num(&c["max_residual_nm"]["value"]),
    };
    eprintln!("{job}: {figures:?}");
    figures
}

/// Job `job` of `source(", chords: WORD")` built on the path, straddling
/// and clear, each report stating the placement it was given.
fn each_placement(job: &str, source: impl Fn(&str) -> String) -> [Figures; 3] {
    let built =
        ["on_path", "straddle", "clear"].map(|w| build(&source(&format!(", chords: {w}")), job));
    let words = built.each_ref().map(|f| f.chords.as_str());
    assert_eq!(words, ["on_path", "straddle", "clear"]);
    built
}

/// Each placement against its promise, for chords that sag up to `sag`
/// (nm) on the path.
fn each_meets_its_promise(sag: f64, job: &str, source: impl Fn(&str) -> String) {
    let [on, straddle, clear] = each_placement(job, |chords| source(chords));
    // Clear moves the same points; straddling splits the chords where a
    // chord bending one way meets one bending the other (on the waves
    // 3,779 points against 3,528; on the ripples, whose C step is fixed,
    // none).
    assert!(on.points == clear.points, "{on:?} {clear:?}");
    assert!(
        straddle.points >= on.points && straddle.points <= on.points + on.points / 10,
        "{straddle:?} {on:?}"
    );
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

/// What the waves' 200 nm tolerance allows, stated (the defaults are the
/// machine's 10 nm + 1 nm, whatever the tolerance): ±(T + r), so PV 402
/// nm, RMS 100.5 nm; and the servo's lag, measured up to 17.4 nm at the
/// rim (r 0.97–1.0 mm, where the waves pass fastest), within 20 nm.
const TOLERANCE_BAND: &str = ", accept: { max_gouge: 201 nm, max_residual: 201 nm, form_pv: 402 nm, form_rms: 100.5 nm, max_following_error: 20 nm }";

/// The band with a `max_gouge` or `form_rms` of its own.
fn band_with(limit: &str) -> String {
    let name = limit.split(':').next().expect("a name");
    let kept: Vec<&str> = TOLERANCE_BAND
        .trim_start_matches(", accept: { ")
        .trim_end_matches(" }")
        .split(", ")
        .filter(|l| !l.starts_with(name))
        .collect();
    format!(", accept: {{ {limit}, {} }}", kept.join(", "))
}

#[test]
fn on_a_fast_tool_servo_spiral_each_placement_meets_its_promise() {
    // Measured: on the path PV 92.0, RMS 19.7, gouge 49.3 nm (3,528
    // points); straddling 46.4, 9.0, gouge 22.2, residual 24.2 nm (3,779
    // points; 49.7, 10.3, 25.3 before chords were split at inflections);
    // clear 50.0, 11.6, 0.00 nm.
    each_meets_its_promise(50.0, "waves", |c| waves(c, TOLERANCE_BAND));
}

#[test]
fn straddling_long_chords_takes_fewer_points_for_the_same_error() {
    // Chords sampled to twice the share (100 nm), straddled: each within
    // ±50 nm, the error of points on the path, with about 1/√2 of them.
    // Measured: 2,633 points against 3,528 on the path; PV 87.5, RMS 18.9,
    // gouge 49.0, residual 38.6 nm (on the path 92.0, 19.7, 49.3, 42.7).
    let sag = 50.0;
    let on = build(&waves(", chords: on_path", TOLERANCE_BAND), "waves");
    let long = build(&waves(", chords: straddle_long", TOLERANCE_BAND), "waves");
    assert_eq!(long.chords, "straddle_long");
    assert!(
        (long.points as f64) < 0.8 * on.points as f64,
        "{long:?} {on:?}"
    );
    assert!(
        long.gouge <= sag + RESOLUTION_NM && long.residual <= sag + RESOLUTION_NM,
        "{long:?}"
    );
    assert!(long.gouge > 0.75 * sag, "{long:?}");
}

#[test]
fn on_a_roller_helix_each_placement_meets_its_promise() {
    // Measured over the whole roller: on the path PV 22.1, RMS 5.76,
    // gouge 11.0 nm; straddling 11.2, 2.61, 5.6 nm; clear 11.5, 2.9,
    // 0.00 nm (11.6 nm proud). (Until issue #29 the ripples were 0.5 mm
    // long, 12.57 of them around, leaving a 3.8 µm step at the seam: the
    // tests read a window away from it.)
    each_meets_its_promise(12.0, "ripples", ripples);
}

#[test]
fn by_default_the_fewest_points_whose_promise_meets_the_criteria() {
    // The whole part judged, at the limits stated.
    let chosen = |accept: &str| build(&waves_judged("", "", accept), "waves");
    // Chords sag up to 50 nm on the path. Within the band of the 200 nm
    // tolerance (gouge and residual 201 nm, PV 402, RMS 100.5) and with a
    // 60 nm gouge limit, long straddled chords promise ±50 nm with fewer
    // points; a 30 nm limit needs every point, straddled (±25 nm); 1 nm,
    // clear. Measured over the whole part: long chords 2,633 points
    // against 3,528 on the path, PV 106, RMS 17.7, gouge 49.6, residual
    // 56.2 nm (at the rim); straddled PV 70.7, gouge 25.3; clear gouge
    // 0.011 nm, 76.0 nm proud.
    let by_default = chosen(TOLERANCE_BAND);
    assert_eq!(by_default.chords, "straddle_long");
    let on_path = build(
        &waves_judged(", chords: on_path", "", TOLERANCE_BAND),
        "waves",
    );
    assert!(
        (by_default.points as f64) < 0.8 * on_path.points as f64,
        "{by_default:?} {on_path:?}"
    );
    // What long straddled chords promise: no deeper than the sag.
    assert!(by_default.gouge <= 50.0 + RESOLUTION_NM, "{by_default:?}");
    assert_eq!(
        chosen(&band_with("max_gouge: 60 nm")).chords,
        "straddle_long"
    );
    let straddled = chosen(&band_with("max_gouge: 30 nm"));
    assert_eq!(straddled.chords, "straddle");
    assert!(straddled.gouge <= 30.0, "{straddled:?}");
    // A 25 nm RMS: only straddling promises it (half its ±25 nm band).
    assert_eq!(chosen(&band_with("form_rms: 25 nm")).chords, "straddle");
    // A gouge limit of the resolution: clear, and the gate passes the
    // whole part (0.011 nm deep at most, against clear's promise of
    // nothing below the path beyond the rounding of the resolution).
    let clear = chosen(&band_with("max_gouge: 1 nm"));
    assert_eq!(clear.chords, "clear");
    assert!(clear.gouge <= RESOLUTION_NM, "{clear:?}");
}

#[test]
fn a_looser_tolerance_does_not_loosen_the_default_limits() {
    // The waves with their 200 nm tolerance and no `accept` block: the
    // defaults are the machine's (10 nm + its 1 nm resolution: PV 22 nm),
    // not ±(200 + 1) nm, so the whole part (106 nm PV with long chords,
    // 70.7 straddled, 76.0 clear) is refused, with no program written.
    let dir = tempfile::tempdir().expect("tmp");
    std::fs::write(dir.path().join("job.lens"), waves_judged("", "", "")).expect("write");
    let out_dir = dir.path().join("out");
    let out = lensc(
        dir.path(),
        &[
            "build",
            "job.lens",
            "--out",
            out_dir.to_str().expect("utf8"),
        ],
    );
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("misses `form_pv`") && stderr.contains("default limit of 22 nm"),
        "{stderr}"
    );
    assert!(
        stderr.contains("the least of the path tolerance 200 nm and the 10 nm the machine holds"),
        "{stderr}"
    );
    assert!(!out_dir.join("waves.ngc").exists());
}

#[test]
fn a_roller_helix_by_default_keeps_every_point() {
    // Its points are a fixed C step apart, so long chords are not offered:
    // on the path its 11 nm chords promise ±11 nm, within the job's
    // stated 200 nm limits, over the whole roller.
    let chosen = build(&ripples(""), "ripples");
    assert_eq!(chosen.chords, "on_path");
}

/// LinuxCNC's dialect with no arc planes: the optimiser writes only
/// straight moves, so the programs keep the planner's chords (merging only
/// points collinear within the fitting share).
const LINES_ONLY: &str = "dialect lines_only = gcode {\n\
    extension: \"ngc\"\n\
    comment: parentheses\n\
    lathe_setup: [\"G18 G21 G90 G8 G40 G49 G80 G94\"]\n\
    mill_setup: [\"G17 G21 G90 G40 G49 G80 G94\"]\n\
    lathe_tool_call: [\"T{tool} M6 G43\"]\n\
    mill_tool_call: [\"T{tool} M6 G43 H{offset}\"]\n\
    constant_rpm: \"G97\"\n\
    spindle_orient: [\"M19 R0\"]\n\
    coolant_flood: \"M8\"\n\
    coolant_mist: \"M7\"\n\
    coolant_off: \"M9\"\n\
    word_formats: [\"S5\", \"T5\", \"H5\", \"M3\"]\n\
    path_tolerance: [\"G64 P{tolerance}\"]\n\
    surface_speed: [\"G96 D{cap} S{speed}\"]\n\
    end: [\"M2\"]\n\
    lathe_x: radius\n\
    arc_planes: []\n\
    arc_centre: incremental\n\
    per_minute: \"G94\"\n\
    per_revolution: \"G95\"\n\
    inverse_time: \"G93\"\n\
    max_line_length: 255\n\
}\n";

/// A convex dome (R 5 mm, Ø 4 mm) turned with a 400 nm tolerance on a
/// 1 nm lathe: the chords take 40 nm (T/10), the fitted lines and arcs
/// 60 nm (3T/20); `lines` writes straight moves only.
fn turned_dome(chords: &str, lines: bool, accept: &str) -> String {
    let machine = if lines {
        "machine m = ultra_precision_lathe { dialect: lines_only, other_dialects: [] }"
    } else {
        "machine m = ultra_precision_lathe { }"
    };
    format!(
        "use std::machines::ultra_precision_lathe\n\
         use std::tools::diamond_r500um\n\
         {LINES_ONLY}\
         {machine}\n\
         surface dome = sphere {{ radius: 5 mm, sense: convex, aperture: circle(diameter: 4 mm) }}\n\
         strategy s = profile_turning {{ feed: 5 um/rev, spindle_speed: 1000 rpm, chord_tolerance: 400 nm{chords} }}\n\
         job dome {{ surface: dome, tool: diamond_r500um, machine: m, strategy: s, accept: {accept} }}\n"
    )
}

/// A ball-end raster (Ø 1 mm) over a convex dome (R 5 mm, Ø 1 mm) with a
/// 400 nm tolerance on a 1 nm mill: chords 40 nm, fits 60 nm. Judged on
/// a 0.2 mm window half way out (the chords' promise, away from the rim).
fn rastered_dome(chords: &str, lines: bool, accept: &str) -> String {
    rastered_dome_judged(
        chords,
        lines,
        ", simulate: { x: 0 mm .. 0.2 mm, y: -0.1 mm .. 0.1 mm }",
        accept,
    )
}

/// The rastered dome judged on `judged` (`, simulate: …`, or empty for
/// the whole part).
fn rastered_dome_judged(chords: &str, lines: bool, judged: &str, accept: &str) -> String {
    let dialect = if lines {
        "dialect: lines_only, other_dialects: [], "
    } else {
        ""
    };
    format!(
        "use std::machines::generic_3axis_mill\n\
         {LINES_ONLY}\
         machine m = generic_3axis_mill {{ {dialect}resolution: 1 nm }}\n\
         surface dome = sphere {{ radius: 5 mm, sense: convex, aperture: circle(diameter: 1 mm) }}\n\
         tool ball = ball_end {{ diameter: 1 mm }}\n\
         strategy s = raster {{ along: x, stepover: 50 um, chord_tolerance: 400 nm, feed: 100 mm/min, spindle_speed: 10000 rpm{chords} }}\n\
         job dome {{ surface: dome, tool: ball, machine: m, strategy: s{judged}, accept: {accept} }}\n"
    )
}

/// The optimised strategies' placements against their promises, with the
/// program's straight moves the planner's chords (sag up to 40 nm): on the
/// path the convex dome is gouged by about the sag; straddling, by at most
/// half of it either way; clear, not at all.
fn optimised_meet_their_promises(source: impl Fn(&str, bool, &str) -> String) {
    let sag = 40.0;
    let [on, straddle, clear] = each_placement("dome", |chords| source(chords, true, "none"));
    assert!(on.points == clear.points, "{on:?} {clear:?}");
    assert!(
        on.gouge > 0.5 * sag && on.gouge <= sag + RESOLUTION_NM,
        "{on:?}"
    );
    let half = 0.5 * sag + RESOLUTION_NM;
    assert!(
        straddle.gouge <= half && straddle.residual <= half,
        "{straddle:?}"
    );
    assert!(straddle.gouge < 0.6 * on.gouge, "{straddle:?} {on:?}");
    assert!(clear.gouge <= RESOLUTION_NM, "{clear:?}");
    assert!(clear.residual <= sag + 2.0 * RESOLUTION_NM, "{clear:?}");
    // With arcs fitted (LinuxCNC's dialect), clear's fits are held above
    // its points: still no gouge beyond the resolution.
    let arcs = build(&source(", chords: clear", false, "none"), "dome");
    assert!(arcs.gouge <= RESOLUTION_NM, "{arcs:?}");
}

#[test]
fn in_profile_turning_each_placement_meets_its_promise() {
    // Measured (straight moves only): on the path gouge 34.7 nm; straddling
    // 17.2 nm deep, 14.6 nm proud; clear 0.00 deep, 32.0 proud. With arcs,
    // clear: no gouge.
    optimised_meet_their_promises(turned_dome);
}

#[test]
fn in_a_raster_each_placement_meets_its_promise() {
    // Measured (straight moves only): on the path gouge 27.1 nm; straddling
    // 13.8 nm deep, 11.0 nm proud; clear 0.00 deep, 24.9 proud. With arcs,
    // clear: no gouge.
    optimised_meet_their_promises(rastered_dome);
}

/// What the domes' 400 nm tolerance allows besides the gouge, stated (the
/// defaults are the machine's, whatever the tolerance): residual 401 nm,
/// PV 802 nm, RMS 200.5 nm.
const DOME_BAND: &str = "max_residual: 401 nm, form_pv: 802 nm, form_rms: 200.5 nm";

#[test]
fn an_optimised_strategy_by_default_meets_max_gouge() {
    // On the path the chords and fits may gouge T/10 + 3T/20 = 100 nm:
    // a 150 nm limit keeps the points there, 80 nm straddles them (20 + 60
    // nm), 10 nm places them clear, and the gate passes the whole dome
    // with no gouge. Measured over the whole dome: residual at the
    // contacts 6.0 / 18.9 / 33.7 nm, PV 5.8 / 13.7 / 23.3 nm, no gouge.
    // (Until issue #29's fix the circular window's edge, crossing a
    // column just past a cusp, left one row of the pass beyond it, the
    // top of its 50 µm scallop, read as a contact: 551 / 564 / 579 nm.)
    let chosen = |max_gouge: &str| {
        build(
            &rastered_dome_judged(
                "",
                false,
                "",
                &format!("{{ max_gouge: {max_gouge}, {DOME_BAND} }}"),
            ),
            "dome",
        )
    };
    assert_eq!(chosen("150 nm").chords, "on_path");
    assert_eq!(chosen("80 nm").chords, "straddle");
    let clear = chosen("10 nm");
    assert_eq!(clear.chords, "clear");
    assert!(clear.gouge <= RESOLUTION_NM, "{clear:?}");
}

#[test]
fn profile_turning_by_default_meets_max_gouge() {
    // `max_gouge: 0`: only clear chords promise it, and the gate passes
    // every radius of the profile (measured: 0.00 nm deep, 34.8 nm proud,
    // PV 7.84 nm).
    let turned = build(
        &turned_dome("", false, &format!("{{ max_gouge: 0 nm, {DOME_BAND} }}")),
        "dome",
    );
    assert_eq!(turned.chords, "clear");
    assert!(turned.gouge <= RESOLUTION_NM, "{turned:?}");
}
