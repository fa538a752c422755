//! The tool's control point (issue #28, item 1): a program written for
//! the tool's tip and one written for its centre move the machine by the
//! tool's radius apart, and read back (the build's own simulation, which
//! takes the header's control point off again as `lensc verify` reads
//! it) cut the same part.

use crate::common::{lensc, text};
use std::path::Path;

/// Builds `source` in a fresh directory; the directory and the exit code.
fn build(source: &str, args: &[&str]) -> (tempfile::TempDir, Option<i32>, String) {
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::write(dir.path().join("job.lens"), source).expect("write job");
    let mut all = vec!["build", "job.lens", "-q"];
    all.extend_from_slice(args);
    let out = lensc(dir.path(), &all);
    let code = out.status.code();
    (dir, code, text(&out.stderr))
}

fn read(dir: &Path, name: &str) -> String {
    std::fs::read_to_string(dir.join("out").join(name)).expect(name)
}

/// Every `letter` word of the program's motion blocks, in order.
fn motion_words(program: &str, letter: char) -> Vec<f64> {
    let motion = ["G0", "G1", "G2", "G3", "G00", "G01", "G02", "G03"];
    let mut modal = false;
    let mut out = Vec::new();
    for line in program
        .lines()
        .filter(|l| !l.starts_with('(') && !l.starts_with(';'))
    {
        let words: Vec<&str> = line.split_whitespace().collect();
        if words.iter().any(|w| motion.contains(w)) {
            modal = true;
        }
        // Moves in machine coordinates (G53, SUPA, G28) are no tool's.
        let machine = |w: &&str| w.starts_with("G53") || *w == "SUPA" || w.starts_with("G28");
        if words.iter().any(machine) || !modal {
            continue;
        }
        out.extend(
            words
                .iter()
                .filter_map(|w| w.strip_prefix(letter).and_then(|v| v.parse::<f64>().ok())),
        );
    }
    out
}

/// Every `letter` word of `centre` less the same word of `tip`: the
/// programs move alike, by a constant apart.
fn shifts(centre: &str, tip: &str, letter: char) -> Vec<f64> {
    let (c, t) = (motion_words(centre, letter), motion_words(tip, letter));
    assert_eq!(c.len(), t.len(), "{letter} words: {c:?} against {t:?}");
    assert!(!c.is_empty(), "no {letter} words in\n{centre}");
    c.iter().zip(&t).map(|(c, t)| c - t).collect()
}

fn all_near(shifts: &[f64], expected: f64) -> bool {
    shifts.iter().all(|d| (d - expected).abs() < 1e-9)
}

/// The simulation's figures of a report, as numbers.
fn figures(report: &str, keys: &[&str]) -> Vec<f64> {
    let v: serde_json::Value = serde_json::from_str(report).expect("report JSON");
    let sim = &v["simulation"];
    keys.iter()
        .map(|k| {
            sim.pointer(k)
                .and_then(serde_json::Value::as_f64)
                .unwrap_or_else(|| panic!("no {k} in {sim}"))
        })
        .collect()
}

const MILL: &str = "use std::machines::generic_3axis_mill
surface dome = sphere { radius: 5 mm, sense: convex, aperture: circle(diameter: 0.4 mm) }
tool tip_ball = ball_end { diameter: 1 mm, control_point: tool_tip }
tool centre_ball = ball_end { diameter: 1 mm, control_point: tool_centre }
tool plain_ball = ball_end { diameter: 1 mm }
strategy mill_it = raster { along: x, stepover: 50 um, feed: 200 mm/min, spindle_speed: 20000 rpm, chord_tolerance: 200 nm }
job at_tip { surface: dome, tool: tip_ball, machine: generic_3axis_mill, strategy: mill_it, simulate: { x: -0.1 mm .. 0.1 mm, y: -0.1 mm .. 0.1 mm, spacing: 10 um } }
job at_centre { surface: dome, tool: centre_ball, machine: generic_3axis_mill, strategy: mill_it, simulate: { x: -0.1 mm .. 0.1 mm, y: -0.1 mm .. 0.1 mm, spacing: 10 um } }
job unstated { surface: dome, tool: plain_ball, machine: generic_3axis_mill, strategy: mill_it, simulate: { x: -0.1 mm .. 0.1 mm, y: -0.1 mm .. 0.1 mm, spacing: 10 um } }
";

#[test]
fn a_ball_end_programmed_at_its_tip_cuts_the_part_its_centre_program_cuts() {
    let (dir, code, err) = build(MILL, &[]);
    assert_eq!(code, Some(0), "{err}");
    let (tip, centre) = (
        read(dir.path(), "at_tip.ngc"),
        read(dir.path(), "at_centre.ngc"),
    );
    // The programs move the machine a ball radius apart in Z, not in X.
    let dz = shifts(&centre, &tip, 'Z');
    assert!(all_near(&dz, 0.5), "centre Z - tip Z: {dz:?}");
    let dx = shifts(&centre, &tip, 'X');
    assert!(all_near(&dx, 0.0), "centre X - tip X: {dx:?}");
    // Arc centres are incremental from the arc's start: the same.
    let dk = shifts(&centre, &tip, 'K');
    assert!(all_near(&dk, 0.0), "centre K - tip K: {dk:?}");
    // Each header says what it is written for.
    assert!(tip.contains("(control point tip at X+0 Y+0 Z-0.5 mm from the tool centre [stated]"));
    assert!(
        centre.contains("(control point centre at X+0 Y+0 Z+0 mm from the tool centre [stated]")
    );
    // A mill's tool that states none is set to its tip, and says so.
    let unstated = read(dir.path(), "unstated.ngc");
    assert!(
        unstated.contains("(control point tip at X+0 Y+0 Z-0.5 mm from the tool centre [the default on a mill_3axis]"),
        "{unstated}"
    );
    // Read back, both cut the same part.
    let keys = [
        "/height_map/surface/pv_nm",
        "/height_map/surface/rms_nm",
        "/height_map/contact/pv_nm",
    ];
    let (a, b) = (
        figures(&read(dir.path(), "at_tip.report.json"), &keys),
        figures(&read(dir.path(), "at_centre.report.json"), &keys),
    );
    for ((k, a), b) in keys.iter().zip(&a).zip(&b) {
        assert!((a - b).abs() < 1e-3, "{k}: tip {a} nm, centre {b} nm");
    }
    // The contact: the cut against the design where the ball touched.
    assert!(
        a[2] < 10.0,
        "the tip program's part is out by {} nm PV",
        a[2]
    );
}

const LATHE: &str = "use std::machines::linuxcnc_lathe
surface lens = sphere { radius: 20 mm, sense: convex, aperture: circle(diameter: 4 mm) }
tool tip_nose = round_nose { nose_radius: 0.5 mm, clearance: 10 deg, control_point: tool_tip }
tool centre_nose = round_nose { nose_radius: 0.5 mm, clearance: 10 deg, control_point: tool_centre }
strategy s = profile_turning { feed: 5 um/rev, spindle_speed: 1000 rpm, chord_tolerance: 200 nm }
job at_tip { surface: lens, tool: tip_nose, machine: linuxcnc_lathe, strategy: s }
job at_centre { surface: lens, tool: centre_nose, machine: linuxcnc_lathe, strategy: s }
";

#[test]
fn a_lathe_tool_programmed_at_its_imaginary_tip_cuts_the_part_its_centre_program_cuts() {
    for dialect in ["linuxcnc", "fanuc_0i_lathe", "siemens_840d_lathe"] {
        let (dir, code, err) = build(LATHE, &["--dialect", dialect]);
        assert_eq!(code, Some(0), "{dialect}: {err}");
        let ext = if dialect == "linuxcnc" {
            "ngc"
        } else if dialect.starts_with("fanuc") {
            "nc"
        } else {
            "MPF"
        };
        let (tip, centre) = (
            read(dir.path(), &format!("at_tip.{ext}")),
            read(dir.path(), &format!("at_centre.{ext}")),
        );
        // Fanuc's X is the diameter: the tip is a nose diameter in.
        let x_scale = if dialect.starts_with("fanuc") {
            2.0
        } else {
            1.0
        };
        let dz = shifts(&centre, &tip, 'Z');
        let dx = shifts(&centre, &tip, 'X');
        assert!(all_near(&dz, 0.5), "{dialect}: centre Z - tip Z: {dz:?}");
        assert!(
            all_near(&dx, 0.5 * x_scale),
            "{dialect}: centre X - tip X: {dx:?}"
        );
        let keys = ["/form_error_pv_nm", "/form_error_rms_nm"];
        let (a, b) = (
            figures(&read(dir.path(), "at_tip.report.json"), &keys),
            figures(&read(dir.path(), "at_centre.report.json"), &keys),
        );
        for ((k, a), b) in keys.iter().zip(&a).zip(&b) {
            assert!(
                (a - b).abs() < 1e-3,
                "{dialect} {k}: tip {a} nm, centre {b} nm"
            );
        }
    }
}

#[test]
fn a_tip_on_a_servo_table_that_states_the_nose_centre_is_refused_and_nothing_is_written() {
    let source = "use std::machines::nanoform_x_fts5000
surface lenslet = sphere { radius: 20 mm, sense: concave, aperture: circle(diameter: 1.7 mm) }
tool nose = round_nose { nose_radius: 0.496 mm, clearance: 10 deg, control_point: tool_tip }
strategy coarse = fts_spiral { feed: 50 um/rev, surface_speed: 5 m/min, spindle_cap: 1000 rpm, settling_time: 1 ms, chord_tolerance: 50 nm }
job servo { surface: lenslet, tool: nose, machine: nanoform_x_fts5000, strategy: coarse }
";
    let (dir, code, err) = build(source, &["--dialect", "ultra_precision_lathe_gcode"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("E0178"), "{err}");
    assert!(
        err.contains("ultra_precision_lathe_gcode") && err.contains("nanoform_x_fts5000"),
        "{err}"
    );
    let out = dir.path().join("out");
    let written = std::fs::read_dir(&out).map_or(0, |d| d.count());
    assert_eq!(written, 0, "files written in {}", out.display());
}
