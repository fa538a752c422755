//! A round nose's measured edge (`edge_profile`), through the `lensc`
//! binary: a turned conic, a tilted lens on a spiral and a pattern on a
//! roller helix, each cut by a tool whose edge carries a 50 nm
//! waviness. Each program is read back from its text by the controller
//! reader and swept with the real, wavy edge (`program_cut_by`): the
//! program planned for a circle prints the waviness into the part, the
//! program planned for the measured edge does not. The header and the
//! report name the profile by its MD5; every bad profile is a coded
//! error at the tool's `edge_profile`, exit 1, nothing written.

use std::f64::consts::PI;
use std::path::Path;

use lensc_build::driver;
use lensc_lang::loader::RealFs;
use lensc_runtime::machine::edge::{EdgeProfile, Nose};
use lensc_runtime::reader::{self, MachineLimits};

use crate::common::{lensc, text};

/// The README's condenser front (slopes to 14.5° at its 3 mm rim),
/// turned with a 0.5 mm nose whose tool line is `TOOL`.
const FRONT: &str = "use std::machines::ultra_precision_lathe

surface front = conic {
    radius: 12 mm
    conic: -0.6
    sense: convex
    aperture: circle(diameter: 6 mm)
}

tool diamond = round_nose { nose_radius: 0.5 mm, clearance: 10°TOOL }

strategy finish = profile_turning { feed: 2 um/rev, spindle_speed: 1500 rpm, chord_tolerance: 4 nm }

job front_surface {
    surface: front
    tool: diamond
    machine: ultra_precision_lathe
    strategy: finish
    accept: none
}
";

/// A certificate's edge: 50 nm, 4 periods over ±45°, every 0.5°.
fn wavy_text() -> String {
    let mut t = String::from("# 0.5 mm nose, waviness\nangle_deg, deviation_um\n");
    for i in 0..=180 {
        let a = -45.0 + 0.5 * i as f64;
        t.push_str(&format!(
            "{a:.1}, {:.6}\n",
            0.05 * (4.0 * PI * a / 45.0).sin()
        ));
    }
    t
}

/// A project with FRONT, its tool given `tool` and the files given.
fn project(tool: &str, files: &[(&str, &str)]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("tmp");
    std::fs::write(dir.path().join("job.lens"), FRONT.replace("TOOL", tool)).expect("write");
    for (name, body) in files {
        std::fs::write(dir.path().join(name), body).expect("write");
    }
    dir
}

/// Builds the project; its program's text and its report.
fn build(dir: &Path) -> (String, serde_json::Value) {
    let out = lensc(dir, &["build", "job.lens"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let program = std::fs::read_to_string(dir.join("out/front_surface.ngc")).expect("program");
    let report = serde_json::from_str(
        &std::fs::read_to_string(dir.join("out/front_surface.report.json")).expect("report"),
    )
    .expect("json");
    (program, report)
}

/// PV (nm) of the part `program` cuts, read back from its text and swept
/// with `nose`, against the conic.
fn cut_pv(dir: &Path, program: &str, nose: &Nose) -> f64 {
    let c = driver::check_path(&RealFs, &dir.join("job.lens")).expect("checks");
    let (spec, _) = lensc_build::pipeline::lower(&c.checked.jobs[0], None, &Default::default())
        .expect("lowers");
    let machine = MachineLimits {
        lathe: true,
        travel: [None; 4],
        max_feed: None,
        max_spindle_rpm: None,
        servo: None,
    };
    let mut moves = reader::read_moves(program, &spec.head().dialect, &machine).1;
    let offset = reader::header_control_offset(program).expect("control point");
    reader::to_tool_centre(&mut moves, offset);
    // The conic: c = 1/12, k = −0.6, convex (material below).
    let design = |r: f64| {
        let c = 1.0 / 12.0;
        -c * r * r / (1.0 + (1.0 - 0.4 * c * c * r * r).sqrt())
    };
    let cut =
        lensc_runtime::verify::simulate::program_cut_by(&moves, nose, &design, (0.0, 2.99), 2000);
    assert_eq!(cut.uncut_area, 0.0);
    cut.pv * 1e6
}

#[test]
fn a_measured_edge_is_compensated_through_the_written_program() {
    let edge_text = wavy_text();
    let samples = lensc_runtime::machine::edge::parse(&edge_text).unwrap();
    let edge = EdgeProfile::from_samples(&samples).unwrap();
    let wavy = Nose {
        radius: 0.5,
        edge: Some(&edge),
    };
    // The tool as a circle: the program prints the edge into the part.
    let plain = project("", &[]);
    let (program, _) = build(plain.path());
    let circle = cut_pv(plain.path(), &program, &Nose::circle(0.5));
    let uncompensated = cut_pv(plain.path(), &program, &wavy);
    // The tool naming its measured edge.
    let named = project(
        ", edge_profile: \"edge.txt\"",
        &[("edge.txt", edge_text.as_str())],
    );
    let (program, report) = build(named.path());
    let compensated = cut_pv(named.path(), &program, &wavy);
    eprintln!(
        "PV nm: circle {circle:.2}, wavy edge uncompensated {uncompensated:.2}, compensated {compensated:.2}"
    );
    assert!(circle < 5.0, "{circle}");
    assert!(uncompensated > 60.0, "{uncompensated}");
    assert!(compensated < 5.0, "{compensated}");
    // The build's own simulation sweeps the measured edge.
    let simulated = report["simulation"]["form_error_pv_nm"].as_f64().unwrap();
    assert!(
        (simulated - compensated).abs() < 1.0,
        "{simulated} vs {compensated}"
    );
    // Which profile: its MD5 in the header's tool line and the report.
    let md5 = lensc_measure::md5_hex(edge_text.as_bytes());
    assert!(
        program.contains(&format!("edge profile edge.txt md5 {md5}")),
        "{program}"
    );
    let e = &report["toolpath"]["edge_profile"];
    assert_eq!(e["md5"], md5.as_str());
    assert_eq!(e["samples"], 181);
    assert_eq!(
        (e["from_deg"].as_f64(), e["to_deg"].as_f64()),
        (Some(-45.0), Some(45.0))
    );
    // The samples' largest, 0.5° apart: within 0.1 nm of the sinusoid's.
    let largest = e["largest_deviation_nm"].as_f64().unwrap();
    assert!(largest > 49.9 && largest <= 50.0, "{largest}");
}

/// Builds FRONT with `tool` and the files; asserts exit 1, `code`, the
/// tool's `edge_profile` shown, nothing written; returns stderr.
fn refused(tool: &str, files: &[(&str, &str)], code: &str) -> String {
    let dir = project(tool, files);
    build_refused(dir.path(), code, "edge_profile: \"")
}

/// Builds `job.lens` in `dir`; asserts exit 1, `code`, the field text
/// `shown` in the diagnostic, nothing written; returns stderr.
fn build_refused(dir: &std::path::Path, code: &str, shown: &str) -> String {
    let out = lensc(dir, &["build", "job.lens"]);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains(&format!("[{code}]")), "{code}: {err}");
    assert!(err.contains(shown), "the field is shown: {err}");
    let written = std::fs::read_dir(dir.join("out")).map_or(0, |d| d.count());
    assert_eq!(written, 0, "nothing is written: {err}");
    err
}

#[test]
fn bad_edge_profiles_are_coded_errors_at_the_tool() {
    let named = ", edge_profile: \"edge.txt\"";
    // No such file; a file outside the project.
    refused(named, &[], "E0103");
    refused(", edge_profile: \"../edge.txt\"", &[], "E0107");
    // A third column; a word; too few samples; angles going back.
    let err = refused(
        named,
        &[("edge.txt", "-20 0.01\n0 0.02 7\n20 0\n")],
        "E0374",
    );
    assert!(err.contains("edge.txt: line 2"), "{err}");
    refused(named, &[("edge.txt", "-20 0.01\n0 zero\n20 0\n")], "E0374");
    refused(named, &[("edge.txt", "-20 0.01\n20 0\n")], "E0374");
    let err = refused(named, &[("edge.txt", "-20 0\n10 0\n5 0\n20 0\n")], "E0374");
    assert!(err.contains("line 3"), "{err}");
    // Beyond the nose's arc: ±45° on a tool of 60° included angle.
    let wavy = wavy_text();
    let err = refused(
        ", included_angle: 60°, edge_profile: \"edge.txt\"",
        &[("edge.txt", wavy.as_str())],
        "E0375",
    );
    assert!(err.contains("±30°"), "{err}");
    // Measured over ±5°: the rim meets the nose at −14.5°.
    let err = refused(named, &[("edge.txt", "-5 0\n0 0.01\n5 0\n")], "E0375");
    assert!(err.contains("covers only -5° .. 5°"), "{err}");
    // Nanometres written where micrometres are read: 50 µm on a 0.5 mm
    // nose is 10 % of it.
    let err = refused(named, &[("edge.txt", "-45 0\n0 50\n45 0\n")], "E0376");
    assert!(err.contains("50 um"), "{err}");
}

/// A 12 mm convex sphere tilted 1° on the spindle, 2 mm across: not of
/// revolution about the spindle axis, so the fast axis (or Z) rises and
/// falls every turn and the radial slope, the edge's angle of contact,
/// changes round each revolution (−4.8° .. 0° and beyond by ±1°).
/// `MACHINE`, `STRATEGY` and `TOOL` are filled in.
const TILTED: &str = "use std::machines::MACHINE

surface lens = sphere { radius: 12 mm, sense: convex, aperture: circle(diameter: 2.4 mm) }
surface tilted_lens = tilt(lens, about: y, angle: 1 deg, aperture: circle(diameter: 2 mm))

tool diamond = round_nose { nose_radius: 0.5 mm, clearance: 10°TOOL }

strategy spiral = STRATEGY

job tilted { surface: tilted_lens, tool: diamond, machine: MACHINE, strategy: spiral, accept: none }
";

/// A slow tool servo's spiral (Z carries the surface) and a fast tool
/// servo's (W in the table beside the program), each with its machine.
const STS: (&str, &str) = (
    "moore_nanotech_450fg",
    "spiral_turning { feed: 10 um/rev, spindle_speed: 50 rpm, chord_tolerance: 2 nm }",
);
// Its controller leads the servo (`feed_forward: inverse_model`, as
// machine `led`): the table's W is then the path, which this test sweeps
// as the nose's. Where lensc leads the servo itself the table holds the
// led command, the servo's input and not where the nose goes
// (tests/it/servo_lead.rs judges that table through the servo).
const FTS: (&str, &str) = (
    "nanoform_x_fts5000",
    "fts_spiral { feed: 10 um/rev, spindle_speed: 300 rpm, chord_tolerance: 2 nm }
machine led = nanoform_x_fts5000 { fast_axis: { stroke: 5 mm, max_acceleration: 25 G, resonance: 1367 Hz, resonant_peak: 1.0, data_rate: 20 kHz, feed_forward: inverse_model } }",
);

/// TILTED on `machine` with `strategy`, its tool given `tool`, and the
/// edge's file.
fn spiral_project((machine, strategy): (&str, &str), tool: &str) -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("tmp");
    let mut job = TILTED
        .replace("MACHINE", machine)
        .replace("STRATEGY", strategy)
        .replace("TOOL", tool);
    // A strategy that brings its own machine (`led`) is cut on it.
    if strategy.contains("\nmachine led = ") {
        job = job.replace(&format!("machine: {machine},"), "machine: led,");
    }
    std::fs::write(dir.path().join("job.lens"), job).expect("write");
    std::fs::write(dir.path().join("edge.txt"), wavy_text()).expect("write");
    dir
}

/// A commanded nose-centre point (C rad, X, W), or None for a rapid.
type Commanded = Option<(f64, f64, f64)>;

/// The nose-centre points a spiral's output commands, as (C rad, X, W),
/// read from its text alone: the program's moves as the controller reads
/// them (Z carrying W, or the tip Z + W where the machine gives its servo
/// the letter W), or, where the dialect drives the fast tool servo
/// from a table, the table's rows (C X W). Rapids start a new pass (None).
fn spiral_points(dir: &Path, args: &[&str]) -> (Vec<Commanded>, serde_json::Value) {
    let mut all = vec!["build", "job.lens"];
    all.extend_from_slice(args);
    let out = lensc(dir, &all);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let report: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join("out/tilted.report.json")).expect("report"),
    )
    .expect("json");
    if let Ok(table) = std::fs::read_to_string(dir.join("out/tilted.fts")) {
        let mut pts = vec![None];
        for l in table.lines().filter(|l| !l.starts_with('#')) {
            let v: Vec<f64> = l.split(' ').map(|v| v.parse().expect("number")).collect();
            pts.push(Some((v[0].to_radians(), v[1], v[2])));
        }
        return (pts, report);
    }
    let program = std::fs::read_to_string(dir.join("out/tilted.ngc")).expect("program");
    let c = driver::check_path(&RealFs, &dir.join("job.lens")).expect("checks");
    let (spec, _) = lensc_build::pipeline::lower(&c.checked.jobs[0], None, &Default::default())
        .expect("lowers");
    // The job's own machine: its servo's letter, if it has one.
    let machine = MachineLimits {
        servo: lensc_lang::lower::read_back::job_machine(&c.checked.jobs[0]).servo,
        lathe: true,
        travel: [None; 4],
        max_feed: None,
        max_spindle_rpm: None,
    };
    let mut moves = reader::read_moves(&program, &spec.head().dialect, &machine).1;
    let offset = reader::header_control_offset(&program).expect("control point");
    reader::to_tool_centre(&mut moves, offset);
    let mut at = [0.0; 4];
    let mut pts = Vec::new();
    for m in &moves {
        for (a, v) in at.iter_mut().zip(m.to) {
            if let Some(v) = v {
                *a = v;
            }
        }
        match m.path {
            reader::Path::Rapid => pts.push(None),
            reader::Path::Line => pts.push(Some((at[3].to_radians(), at[0], at[2]))),
            reader::Path::Arc { .. } => panic!("an arc in a spiral"),
        }
    }
    (pts, report)
}

/// The contact PV (nm: the path's form error, scallops left out) of the
/// part the spiral `pts` cut with `nose`, on a polar grid of 90 spindle
/// angles and radii 0.02 .. 0.9 mm every 2 µm, against the design (the
/// job's own surface, compiled).
fn spiral_cut_pv(dir: &Path, pts: &[Option<(f64, f64, f64)>], edge: Option<&EdgeProfile>) -> f64 {
    use lensc_runtime::verify::heightmap::{Frame, Grid, Sweep};
    let c = driver::check_path(&RealFs, &dir.join("job.lens")).expect("checks");
    let (spec, _) = lensc_build::pipeline::lower(&c.checked.jobs[0], None, &Default::default())
        .expect("lowers");
    let design = lensc_build::evaluate::evaluator(&spec.head().surface.lowered.tape).0;
    let n_s = 90;
    let grid = Grid {
        s0: 0.0,
        ds: 2.0 * PI / n_s as f64,
        ns: n_s,
        u0: 0.02,
        du: 0.002,
        nu: 441,
        period: Some(2.0 * PI),
        j0: 0,
        i0: 0,
    };
    let mut sweep = Sweep::with_edge(grid, 0.5, edge.map(|e| std::sync::Arc::new(e.clone())));
    for p in pts {
        match *p {
            None => sweep.lift(),
            Some((c, x, w)) => sweep.point(c, x, w),
        }
    }
    struct Part<'a>(&'a (dyn lensc_runtime::surface::ir::SurfaceFn + Sync));
    impl Frame for Part<'_> {
        fn design(&self, points: &[(f64, f64)], out: &mut [f64]) {
            for (o, &(s, u)) in out.iter_mut().zip(points) {
                *o = self.0.eval(u * s.cos(), u * s.sin())[0];
            }
        }
        fn xy(&self, s: f64, u: f64) -> (f64, f64) {
            (u * s.cos(), u * s.sin())
        }
        fn inside(&self, x: f64, y: f64) -> bool {
            x.hypot(y) <= 0.9
        }
    }
    let map = sweep.finish(&Part(design.as_ref()));
    assert_eq!(map.uncut, 0);
    map.contact.expect("contacts").pv * 1e6
}

/// Spiral turning with a slow or a fast tool servo: the program (or the
/// servo's table) planned for a circle, cut by the wavy edge, prints the
/// waviness into the part; planned for the measured edge, it does not.
/// Each read back from its text and swept with the edge; the build's own
/// simulation sweeps the measured edge too.
fn spiral_compensated(servo: (&str, &str), args: &[&str]) -> [f64; 3] {
    let edge_text = wavy_text();
    let edge = EdgeProfile::from_samples(&lensc_runtime::machine::edge::parse(&edge_text).unwrap())
        .unwrap();
    let plain = spiral_project(servo, "");
    let (pts, plain_report) = spiral_points(plain.path(), args);
    let circle = spiral_cut_pv(plain.path(), &pts, None);
    let uncompensated = spiral_cut_pv(plain.path(), &pts, Some(&edge));
    let named = spiral_project(servo, ", edge_profile: \"edge.txt\"");
    let (pts, report) = spiral_points(named.path(), args);
    let compensated = spiral_cut_pv(named.path(), &pts, Some(&edge));
    eprintln!(
        "{}: contact PV nm: circle {circle:.2}, wavy edge uncompensated {uncompensated:.2}, compensated {compensated:.2}",
        servo.1
    );
    // The build's simulation of the whole part sweeps the measured edge:
    // the compensated program's form is the circle's, within the
    // chords' few nanometres (swept with a circle it would show the
    // waviness, inverted).
    let pv = |r: &serde_json::Value| {
        r["simulation"]["height_map"]["contact"]["pv_nm"]
            .as_f64()
            .expect("pv")
    };
    assert!(
        (pv(&report) - pv(&plain_report)).abs() < 2.0,
        "{} vs {}",
        pv(&report),
        pv(&plain_report)
    );
    let md5 = lensc_measure::md5_hex(edge_text.as_bytes());
    assert_eq!(report["toolpath"]["edge_profile"]["md5"], md5.as_str());
    assert!(plain_report["toolpath"]["edge_profile"].is_null());
    [circle, uncompensated, compensated]
}

#[test]
fn a_slow_tool_servo_spiral_compensates_a_measured_edge_off_the_axis() {
    let [circle, uncompensated, compensated] = spiral_compensated(STS, &[]);
    assert!(circle < 2.0, "{circle}");
    assert!(uncompensated > 30.0, "{uncompensated}");
    assert!(compensated < 2.0, "{compensated}");
}

#[test]
fn a_fast_tool_servo_table_compensates_a_measured_edge_off_the_axis() {
    let [circle, uncompensated, compensated] =
        spiral_compensated(FTS, &["--dialect", "ultra_precision_lathe_gcode"]);
    assert!(circle < 2.0, "{circle}");
    assert!(uncompensated > 30.0, "{uncompensated}");
    assert!(compensated < 2.0, "{compensated}");
}

/// Builds `job` (with the wavy edge beside it); asserts exit 1, `code`
/// at the tool's `edge_profile`, nothing written; returns stderr.
fn job_refused(job: &str, edge: &str, code: &str) -> String {
    let dir = tempfile::tempdir().expect("tmp");
    std::fs::write(dir.path().join("job.lens"), job).expect("write");
    std::fs::write(dir.path().join("edge.txt"), edge).expect("write");
    build_refused(dir.path(), code, "edge_profile: \"edge.txt\"")
}

#[test]
fn a_spiral_whose_contact_angles_the_edge_does_not_cover_is_refused() {
    // Measured over ±3°; the tilted lens meets the nose at up to −5.8°.
    let job = TILTED
        .replace("MACHINE", STS.0)
        .replace("STRATEGY", STS.1)
        .replace("TOOL", ", edge_profile: \"edge.txt\"");
    let err = job_refused(&job, "-3 0\n0 0.01\n3 0\n", "E0375");
    assert!(err.contains("covers only -3° .. 3°"), "{err}");
    assert!(err.contains("the spiral meets the nose at -5."), "{err}");
}

/// A pattern that varies along the roller only (axial slopes to ±5.7°,
/// the same all the way round, so the helix's chords around the roller
/// lie on the path), wrapped onto seed 002's 3 mm roller and cut over
/// 1 mm of its length by table 1's 1.417567 mm nose whose tool line is
/// `TOOL`.
const ROLLER: &str = "surface pattern = freeform {
    z(x, y) = 0.02 mm * sin(5 rad/mm * x) - 0.04 mm
    domain: rect(x: 0 mm .. 6.283185307179586 mm, y: 0 mm .. 18.84955592153876 mm)
}
surface on_roller = wrap(pattern, onto: roller(radius: 3 mm))
use std::machines::moore_nanotech_450fg
tool diamond = round_nose { nose_radius: 1.417567 mm, clearance: 12.5 deg, included_angle: 100 degTOOL }
strategy fine = roller_helix {
    finish: { c_step: 1 deg, pitch: 20 um }
    z: 0.5 mm .. 1.5 mm
    spindle_speed: 60 rpm
    blank_radius: 3.01 mm
}
job roller { surface: on_roller, tool: diamond, machine: moore_nanotech_450fg, strategy: fine, accept: none }
";

/// ROLLER, its tool given `tool`, and the wavy edge's file.
fn roller_project(tool: &str) -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("tmp");
    std::fs::write(dir.path().join("job.lens"), ROLLER.replace("TOOL", tool)).expect("write");
    std::fs::write(dir.path().join("edge.txt"), wavy_text()).expect("write");
    dir
}

/// Builds the roller project in `dir`: the nose-centre points its
/// program commands, as (C rad, Z, X) read from its text by the
/// controller reader (a rapid, None, starts a pass), and its report.
fn roller_points(dir: &Path) -> (Vec<Commanded>, serde_json::Value) {
    let out = lensc(dir, &["build", "job.lens"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let report: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join("out/roller.report.json")).expect("report"),
    )
    .expect("json");
    let program = std::fs::read_to_string(dir.join("out/roller.ngc")).expect("program");
    let c = driver::check_path(&RealFs, &dir.join("job.lens")).expect("checks");
    let (spec, _) = lensc_build::pipeline::lower(&c.checked.jobs[0], None, &Default::default())
        .expect("lowers");
    let machine = MachineLimits {
        lathe: true,
        travel: [None; 4],
        max_feed: None,
        max_spindle_rpm: None,
        servo: None,
    };
    let mut moves = reader::read_moves(&program, &spec.head().dialect, &machine).1;
    let offset = reader::header_control_offset(&program).expect("control point");
    reader::to_tool_centre(&mut moves, offset);
    let mut at = [0.0; 4];
    let mut pts = Vec::new();
    for m in &moves {
        for (a, v) in at.iter_mut().zip(m.to) {
            if let Some(v) = v {
                *a = v;
            }
        }
        match m.path {
            reader::Path::Rapid => pts.push(None),
            reader::Path::Line => pts.push(Some((at[3].to_radians(), at[2], at[0]))),
            reader::Path::Arc { .. } => panic!("an arc in a helix"),
        }
    }
    (pts, report)
}

/// The contact PV (nm: the path's form error, scallops left out) of the
/// roller the helix `pts` cut with `nose`, on a grid of 90 spindle
/// angles and design x 0.7 .. 1.3 mm every 2 µm, against the pattern
/// (radius 3 mm + 0.02 sin 5x − 0.04).
fn roller_cut_pv(pts: &[Commanded], edge: Option<&EdgeProfile>) -> f64 {
    use lensc_runtime::verify::heightmap::{Frame, Grid, Sweep};
    let n_s = 90;
    let grid = Grid {
        s0: 0.0,
        ds: 2.0 * PI / n_s as f64,
        ns: n_s,
        u0: 0.7,
        du: 0.002,
        nu: 301,
        period: Some(2.0 * PI),
        j0: 0,
        i0: 0,
    };
    let mut sweep = Sweep::with_edge(grid, 1.417567, edge.map(|e| std::sync::Arc::new(e.clone())));
    for p in pts {
        match *p {
            None => sweep.lift(),
            Some((c, z, x)) => sweep.point(c, z, x),
        }
    }
    struct Roller;
    impl Frame for Roller {
        fn design(&self, points: &[(f64, f64)], out: &mut [f64]) {
            for (o, &(_, u)) in out.iter_mut().zip(points) {
                *o = 3.0 + 0.02 * (5.0 * u).sin() - 0.04;
            }
        }
        fn xy(&self, s: f64, u: f64) -> (f64, f64) {
            (u, 3.0 * s)
        }
        fn inside(&self, _x: f64, _y: f64) -> bool {
            true
        }
    }
    let map = sweep.finish(&Roller);
    assert_eq!(map.uncut, 0);
    map.contact.expect("contacts").pv * 1e6
}

#[test]
fn a_roller_helix_compensates_a_measured_edge() {
    // The helix planned for a circle, cut by the wavy edge, prints the
    // waviness into the roller (the axial slope sweeps the angle of
    // contact over ±5.7°); planned for the measured edge, it does not.
    // Each program read back from its text and swept with the edge.
    let edge_text = wavy_text();
    let edge = EdgeProfile::from_samples(&lensc_runtime::machine::edge::parse(&edge_text).unwrap())
        .unwrap();
    let plain = roller_project("");
    let (pts, plain_report) = roller_points(plain.path());
    let circle = roller_cut_pv(&pts, None);
    let uncompensated = roller_cut_pv(&pts, Some(&edge));
    let named = roller_project(", edge_profile: \"edge.txt\"");
    let (pts, report) = roller_points(named.path());
    let compensated = roller_cut_pv(&pts, Some(&edge));
    eprintln!(
        "roller helix: contact PV nm: circle {circle:.2}, wavy edge uncompensated {uncompensated:.2}, compensated {compensated:.2}"
    );
    assert!(circle < 5.0, "{circle}");
    assert!(uncompensated > 50.0, "{uncompensated}");
    assert!(compensated < 5.0, "{compensated}");
    // The build's own simulation sweeps the measured edge: the
    // compensated roller's form is the circle's.
    let pv = |r: &serde_json::Value| {
        r["simulation"]["height_map"]["contact"]["pv_nm"]
            .as_f64()
            .expect("pv")
    };
    eprintln!(
        "report contact PV nm: plain {:.2}, compensated {:.2}",
        pv(&plain_report),
        pv(&report)
    );
    assert!(
        (pv(&report) - pv(&plain_report)).abs() < 2.0,
        "{} vs {}",
        pv(&report),
        pv(&plain_report)
    );
    let md5 = lensc_measure::md5_hex(edge_text.as_bytes());
    assert_eq!(report["toolpath"]["edge_profile"]["md5"], md5.as_str());
    assert!(plain_report["toolpath"]["edge_profile"].is_null());
    let program = std::fs::read_to_string(named.path().join("out/roller.ngc")).expect("program");
    assert!(
        program.contains(&format!("edge profile edge.txt md5 {md5}")),
        "the header names the edge"
    );
}

#[test]
fn a_roller_helix_whose_contact_angles_the_edge_does_not_cover_is_refused() {
    // Measured over ±3°; the pattern meets the nose at up to ±5.7°.
    let job = ROLLER.replace("TOOL", ", edge_profile: \"edge.txt\"");
    let err = job_refused(&job, "-3 0\n0 0.01\n3 0\n", "E0375");
    assert!(err.contains("covers only -3° .. 3°"), "{err}");
    assert!(err.contains("the helix meets the nose at -5.7"), "{err}");
}

#[test]
fn a_roller_helix_over_concave_corners_refuses_a_measured_edge() {
    // A V-groove along the roller: its corner makes the planner scan each
    // nose window, a circle's search, so the edge is refused, not cut as
    // a circle.
    let job = ROLLER
        .replace(
            "0.02 mm * sin(5 rad/mm * x) - 0.04 mm",
            "0.02 * abs(x - 1 mm) - 0.04 mm",
        )
        .replace("TOOL", ", edge_profile: \"edge.txt\"");
    let err = job_refused(&job, &wavy_text(), "E0375");
    assert!(
        err.contains("a measured edge is compensated only along smooth sections"),
        "{err}"
    );
}
