//! A fast tool servo whose controller feeds nothing forward (issue #29,
//! `feed_forward: none`): lensc leads it itself, writing the command the
//! servo needs, and the command as printed is what is judged. Here the
//! tables two builds write are read back from their text and the servo run
//! unled on each, as its machine would run it.

use crate::common::{self, lensc, root, text};
use lensc_runtime::machine::servo::SecondOrderServo;
use lensc_runtime::plan::spiral::SpiralPoint;
use lensc_runtime::verify::follow::{FollowingSimulation, RadialBins};

/// Seed 003's 2 × 2 corner at a constant 300 rpm, its servo's controller
/// leading it or not (`feed_forward`), with no settling plateau (so every
/// move cuts), held to 100 nm of following error.
fn job(feed_forward: &str) -> String {
    format!(
        "surface lenslet = sphere {{ radius: 20 mm, sense: concave, aperture: circle(diameter: 1.7 mm) }}
surface corner = grid(lenslet, pitch_x: 3.5 mm, pitch_y: 3.5 mm, count_x: 2, count_y: 2)
use std::machines::nanoform_x_fts5000
use std::tools::diamond_r496um
machine servo = nanoform_x_fts5000 {{ fast_axis: {{ stroke: 5 mm, max_acceleration: 25 G, resonance: 1367 Hz, resonant_peak: 1.0, data_rate: 20 kHz, feed_forward: {feed_forward} }} }}
strategy s = fts_spiral {{ feed: 50 um/rev, spindle_speed: 300 rpm, settle: none, chord_tolerance: 50 nm }}
job corner {{ surface: corner, tool: diamond_r496um, machine: servo, strategy: s, accept: {{ form_pv: 200 nm, form_rms: 10 nm, max_residual: 200 nm, max_following_error: 100 nm }} }}
"
    )
}

/// Builds `source` with the table-writing dialect: the exit code, the
/// table's rows (C in degrees, X, W in mm), the program's header and the
/// report.
fn build(source: &str) -> (i32, Vec<[f64; 3]>, String, serde_json::Value) {
    let dir = tempfile::tempdir().expect("tmp");
    let file = dir.path().join("corner.lens");
    std::fs::write(&file, source).expect("write");
    let out = lensc(
        &root(),
        &[
            "build",
            file.to_str().expect("utf8"),
            "--dialect",
            "ultra_precision_lathe_gcode",
            "--accept",
            "warn",
            "--out",
            dir.path().to_str().expect("utf8"),
        ],
    );
    let code = out.status.code().unwrap_or(-1);
    let read = |name: &str| std::fs::read_to_string(dir.path().join(name));
    let table = read("corner.fts").unwrap_or_else(|_| panic!("{}", text(&out.stderr)));
    let rows = table
        .lines()
        .filter_map(|l| {
            let v: Vec<f64> = l
                .split_whitespace()
                .map(|w| w.parse::<f64>())
                .collect::<Result<_, _>>()
                .ok()?;
            (v.len() == 3).then(|| [v[0], v[1], v[2]])
        })
        .collect();
    let report = serde_json::from_str(&read("corner.report.json").expect("report")).expect("json");
    (code, rows, read("corner.nc").expect("program"), report)
}

/// The rows as the servo takes them: at 300 rpm, C (degrees from the
/// start) is the time.
fn points(rows: &[[f64; 3]]) -> Vec<SpiralPoint> {
    let per_degree = 60.0 / 300.0 / 360.0;
    rows.iter()
        .map(|&[c, x, w]| SpiralPoint {
            x,
            c: c.to_radians(),
            w,
            t: c * per_degree,
        })
        .collect()
}

/// The largest |servo position − path| (mm) of the servo, unled, driven
/// by `commands`, the path being `path` (the same points' W).
fn unled_error(commands: &[SpiralPoint], path: &[SpiralPoint]) -> f64 {
    let servo = SecondOrderServo::from_resonance(1367.0, 1.0).expect("servo");
    let mut sim =
        FollowingSimulation::new(&servo, 20e3, &[], RadialBins::new(0.0, 5.0, 10)).expect("valid");
    let aims: Vec<f64> = path.iter().map(|p| p.w).collect();
    sim.extend_toward(commands, &aims);
    sim.finish().max_error
}

fn following_nm(report: &serde_json::Value) -> f64 {
    report["simulation"]["max_following_error_nm"]["value"]
        .as_f64()
        .expect("following error")
}

#[test]
fn a_servo_without_feed_forward_is_led_by_the_table_and_judged_from_its_text() {
    let (ctl_code, ctl_rows, ctl_header, ctl_report) = build(&job("inverse_model"));
    let (code, rows, header, report) = build(&job("none"));
    assert_eq!(ctl_code, 0, "{ctl_report}");
    assert_eq!(code, 0, "{report}");
    // Same spiral, with points added a data period beside its bends.
    assert!(
        rows.len() > ctl_rows.len(),
        "{} {}",
        rows.len(),
        ctl_rows.len()
    );
    let (path, led) = (points(&ctl_rows), points(&rows));
    // The path under each of the led table's rows: the controller-led
    // table (the path itself) at the row's time, linear between its rows.
    let under: Vec<SpiralPoint> = led
        .iter()
        .map(|p| {
            let i = path
                .partition_point(|q| q.t <= p.t)
                .clamp(1, path.len() - 1);
            let (a, b) = (path[i - 1], path[i]);
            let f = if b.t > a.t {
                ((p.t - a.t) / (b.t - a.t)).clamp(0.0, 1.0)
            } else {
                0.0
            };
            SpiralPoint {
                w: a.w + f * (b.w - a.w),
                ..*p
            }
        })
        .collect();
    // The path's own table, run on a servo with no feed-forward, misses
    // the 100 nm four times over (420 nm); the table lensc leads it by
    // keeps it (62 nm; the controller's lead, 32 nm).
    let unled = unled_error(&path, &path);
    let by_table = unled_error(&led, &under);
    eprintln!(
        "unled on the path {} nm, on the led table {} nm; reported {} nm (controller-led {} nm)",
        unled * 1e6,
        by_table * 1e6,
        following_nm(&report),
        following_nm(&ctl_report)
    );
    assert!(unled > 4.0 * 100e-6, "{unled}");
    assert!(by_table < 100e-6, "{by_table}");
    // The report's figure is the one the text gives (to the nanometre the
    // table prints; the report's simulation starts from the same rows).
    assert!((following_nm(&report) - by_table * 1e6).abs() < 1.0);
    // The header (and with it the set-up sheet) says who leads the servo.
    assert!(
        header.contains("feed_forward none: the servo led by this program"),
        "{header}"
    );
    assert!(
        ctl_header.contains("feed_forward inverse_model: the servo led by its controller"),
        "{ctl_header}"
    );
}

#[test]
fn a_lead_beyond_the_servo_is_refused() {
    // The same corner on a servo of 20 Hz with a 50 µm stroke: the path
    // spans less than the stroke, and a controller that leads the servo
    // is given the path; a servo with no feed-forward needs a lead that
    // spans far more (E0192), and nothing is written.
    let slow = |ff: &str| {
        job(ff)
            .replace(
                "machine servo = nanoform_x_fts5000 {",
                "machine servo = fts_lathe { dialect: ultra_precision_lathe_gcode, resolution: 1 nm, travel: { x: -10 mm .. 220 mm, z: -150 mm .. 150 mm }, max_feed: 1000 mm/min, spindle: { max_speed: 1000 rpm },",
            )
            .replace("stroke: 5 mm", "stroke: 50 um")
            .replace(
                "resonance: 1367 Hz, resonant_peak: 1.0",
                "natural_frequency: 20 Hz, damping: 0.5",
            )
            .replace("max_following_error: 100 nm", "max_following_error: 1 mm")
    };
    let run = |ff: &str| {
        let dir = tempfile::tempdir().expect("tmp");
        let file = dir.path().join("corner.lens");
        std::fs::write(&file, slow(ff)).expect("write");
        let out = lensc(
            &root(),
            &[
                "build",
                file.to_str().expect("utf8"),
                "--accept",
                "warn",
                "--out",
                dir.path().to_str().expect("utf8"),
            ],
        );
        (
            out.status.code(),
            text(&out.stderr),
            dir.path().join("corner.nc").exists(),
        )
    };
    let (code, said, written) = run("inverse_model");
    assert_eq!((code, written), (Some(0), true), "{said}");
    let (code, said, written) = run("none");
    assert_eq!(code, Some(1), "{said}");
    assert!(
        said.contains("E0192") && said.contains("more than its 50 um stroke"),
        "{said}"
    );
    assert!(!written);
}

/// Builds `source` (as `corner.lens`) in its machine's own dialect: the
/// exit code, what it said and the program written, if any.
fn build_own(source: &str) -> (Option<i32>, String, Option<String>) {
    let dir = tempfile::tempdir().expect("tmp");
    let file = dir.path().join("corner.lens");
    std::fs::write(&file, source).expect("write");
    let out = lensc(
        &root(),
        &[
            "build",
            file.to_str().expect("utf8"),
            "--color",
            "never",
            "--accept",
            "warn",
            "--out",
            dir.path().to_str().expect("utf8"),
        ],
    );
    let program = std::fs::read_to_string(dir.path().join("corner.ngc")).ok();
    (out.status.code(), text(&out.stderr), program)
}

/// The corner at `speed` (m/min) on the standard library's servo lathe
/// as a machine of its own (a restated block is merged with the
/// library's, whose servo has the letter W), in LinuxCNC's dialect, its
/// fast axis with `fast_axis` added (a letter of its own, or none), its
/// `max_feed` as `max_feed`.
fn linuxcnc_job(speed: &str, fast_axis: &str, max_feed: &str) -> String {
    format!(
        "surface lenslet = sphere {{ radius: 20 mm, sense: concave, aperture: circle(diameter: 1.7 mm) }}
surface corner = grid(lenslet, pitch_x: 3.5 mm, pitch_y: 3.5 mm, count_x: 2, count_y: 2)
use std::tools::diamond_r496um
machine servo = fts_lathe {{ dialect: linuxcnc, resolution: 1 nm, travel: {{ x: -10 mm .. 220 mm, z: -150 mm .. 150 mm }}, max_feed: {max_feed}, spindle: {{ max_speed: 1000 rpm }}, fast_axis: {{ stroke: 5 mm, max_acceleration: 25 G, resonance: 1367 Hz, resonant_peak: 1.0, data_rate: 20 kHz, feed_forward: none{fast_axis} }} }}
strategy coarse = fts_spiral {{ feed: 50 um/rev, surface_speed: {speed} m/min, spindle_cap: 1000 rpm, settling_time: 1 ms, chord_tolerance: 50 nm }}
job corner {{ surface: corner, tool: diamond_r496um, machine: servo, strategy: coarse, accept: none }}
"
    )
}

/// The feed moves of `program`, built from `source`, as the reader makes
/// them against the job's own machine and dialect (`lensc verify`'s and
/// the read-back's limits): no finding, and each move's end (X, Z, C).
fn read_feeds(source: &str, program: &str) -> Vec<[f64; 3]> {
    let dir = tempfile::tempdir().expect("tmp");
    let file = dir.path().join("corner.lens");
    std::fs::write(&file, source).expect("write");
    let c = lensc_build::driver::check_path(&lensc_lang::loader::RealFs, &file).expect("checks");
    let (spec, _) = lensc_build::pipeline::lower(&c.checked.jobs[0], None, &Default::default())
        .expect("lowers");
    let machine = lensc_lang::lower::read_back::job_machine(&c.checked.jobs[0]);
    let (found, moves) = lensc_runtime::reader::read_moves(program, &spec.head().dialect, &machine);
    assert!(found.is_empty(), "{found:?}");
    moves
        .iter()
        .filter(|m| m.path == lensc_runtime::reader::Path::Line)
        .map(|m| {
            let v = |i: usize| m.to[i].expect("stated");
            [v(0), v(2), v(3)]
        })
        .collect()
}

#[test]
fn a_servo_on_its_own_letter_is_written_there_and_reads_back_as_the_planned_cut() {
    // The corner at 5 m/min, its servo led by the program. On the
    // standard library's machine the servo is W: the program moves the
    // Z slide to 0 and the servo on W. The same job on a machine with no
    // letter and a slide fast enough for the lead writes the tip on Z:
    // both plans are the same, and the tip the reader makes of the W
    // program (Z + W) is, move for move, the Z program's Z.
    let w_job = linuxcnc_job("5", ", letter: W, max_velocity: 45 m/min", "1000 mm/min");
    let z_job = linuxcnc_job("5", "", "5000 mm/min");
    let (code, said, w_program) = build_own(&w_job);
    assert_eq!(code, Some(0), "{said}");
    let (code, said, z_program) = build_own(&z_job);
    assert_eq!(code, Some(0), "{said}");
    let (w_program, z_program) = (w_program.expect("written"), z_program.expect("written"));
    let words = |p: &str, letter: char| -> Vec<String> {
        p.lines()
            .filter(|l| !l.starts_with('('))
            .flat_map(|l| l.split_whitespace().map(str::to_string).collect::<Vec<_>>())
            .filter(|w| w.starts_with(letter))
            .collect()
    };
    assert!(words(&w_program, 'W').len() > 1000, "the servo on W");
    assert!(words(&z_program, 'W').is_empty(), "no W without the letter");
    // The slide: up, down to 0 with the plunge, held there, up again.
    let z: Vec<String> = words(&w_program, 'Z');
    assert_eq!(z.len(), 4, "{z:?}");
    assert_eq!(z[1], "Z0.", "{z:?}");
    // The header names the servo's axis.
    assert!(
        w_program
            .contains("while the fast tool servo moves on its own axis W [the tool tip at Z + W]"),
        "{}",
        &w_program[..2000]
    );
    let tip = read_feeds(&w_job, &w_program);
    let planned = read_feeds(&z_job, &z_program);
    assert_eq!(tip.len(), planned.len());
    assert!(tip.len() > 10_000, "{}", tip.len());
    let worst = tip
        .iter()
        .zip(&planned)
        .map(|(a, b)| (0..3).map(|i| (a[i] - b[i]).abs()).fold(0.0, f64::max))
        .fold(0.0, f64::max);
    assert!(worst < 1e-9, "the W program's tip strays {worst} mm");
}

#[test]
fn a_servo_move_faster_than_its_own_limit_is_refused_naming_both_figures() {
    // The corner at 5 m/min with the servo on W limited to 600 mm/min:
    // the lead's moves beside the rims drive it at over 1000 mm/min.
    let (code, said, program) = build_own(&linuxcnc_job(
        "5",
        ", letter: W, max_velocity: 600 mm/min",
        "1000 mm/min",
    ));
    assert_eq!(code, Some(1), "{said}");
    assert!(program.is_none(), "nothing is written");
    assert!(
        said.contains("E0192")
            && said.contains("drives the servo, written on W, at ")
            && said.contains("above its `max_velocity` of 600 mm/min"),
        "{said}"
    );
    let velocity = common::figure(&said, "written on W, at ", " mm/min");
    assert!(velocity > 1000.0 && velocity < 1100.0, "{velocity}");
    // The speed the help names builds, its every servo move within 600.
    let advised =
        common::between(&said, "a surface speed of ", " m/min").unwrap_or_else(|| panic!("{said}"));
    let (code, said, _) = build_own(&linuxcnc_job(
        advised,
        ", letter: W, max_velocity: 600 mm/min",
        "1000 mm/min",
    ));
    assert_eq!(code, Some(0), "{said}");
}

#[test]
fn a_lead_faster_than_the_machine_s_feed_is_refused_with_the_speed_that_fits() {
    // The corner on the standard library's servo lathe restated with no
    // letter for its servo: its dialect (LinuxCNC) then programs the fast
    // axis on Z, each move held by the controller to the machine's
    // 1000 mm/min, and at 5 m/min the lead's moves beside the lenslets'
    // rims would run at 1034.6 mm/min (the read-back refused it, E0314,
    // before the plan measured them).
    let job = |speed: &str| linuxcnc_job(speed, "", "1000 mm/min");
    let (code, said, program) = build_own(&job("5"));
    assert_eq!(code, Some(1), "{said}");
    assert!(program.is_none(), "nothing is written");
    assert!(
        said.contains("E0192")
            && said.contains("the command that leads the fast axis")
            && said.contains("above the machine's `max_feed` of 1000 mm/min"),
        "{said}"
    );
    // The move's feed, as the plan measured it.
    let feed = common::figure(&said, "written on Z, at ", " mm/min");
    assert!(feed > 1000.0 && feed < 1100.0, "{feed}");
    // The speed the help names, planned and checked: built at it, every
    // move fits, and the read-back (the controller's view) passes it.
    let advised =
        common::between(&said, "a surface speed of ", " m/min").unwrap_or_else(|| panic!("{said}"));
    let speed: f64 = advised.parse().expect("a speed");
    assert!(speed < 5.0 && speed > 4.0, "{speed}");
    let (code, said, program) = build_own(&job(advised));
    assert_eq!(code, Some(0), "{said}");
    let program = program.expect("written");
    assert!(program.contains("G93"), "inverse time");
}

#[test]
fn a_servo_letter_needs_its_velocity_limit_and_the_limit_its_letter() {
    for (stated, missing) in [
        (", letter: W", "`letter` needs its `max_velocity`"),
        (
            ", max_velocity: 45 m/min",
            "`max_velocity` needs its `letter`",
        ),
    ] {
        let dir = tempfile::tempdir().expect("tmp");
        let file = dir.path().join("corner.lens");
        std::fs::write(&file, linuxcnc_job("5", stated, "1000 mm/min")).expect("write");
        let out = lensc(
            &root(),
            &["check", file.to_str().expect("utf8"), "--color", "never"],
        );
        let said = text(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{said}");
        assert!(said.contains("E0121") && said.contains(missing), "{said}");
    }
    // A letter the control gives the slides is not the servo's.
    let dir = tempfile::tempdir().expect("tmp");
    let file = dir.path().join("corner.lens");
    std::fs::write(
        &file,
        linuxcnc_job("5", ", letter: z, max_velocity: 45 m/min", "1000 mm/min"),
    )
    .expect("write");
    let out = lensc(
        &root(),
        &["check", file.to_str().expect("utf8"), "--color", "never"],
    );
    let said = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{said}");
    assert!(said.contains("E0126"), "{said}");
}

#[test]
fn verify_holds_a_servo_on_its_own_letter_to_its_stroke() {
    // The corner's program as built reads clean; its last retract put
    // 5.5 mm out (the servo's positions then spanning from the cut's,
    // about 0.5 mm, to 5.5 mm) is over the 5 mm stroke of the machine its header names, whatever
    // the servo's zero.
    let dir = tempfile::tempdir().expect("tmp");
    let job = linuxcnc_job("5", ", letter: W, max_velocity: 45 m/min", "1000 mm/min");
    std::fs::write(dir.path().join("corner.lens"), job).expect("write");
    let built = lensc(
        dir.path(),
        &["build", "corner.lens", "--accept", "warn", "--out", "."],
    );
    assert!(built.status.success(), "{}", text(&built.stderr));
    let program = std::fs::read_to_string(dir.path().join("corner.ngc")).expect("written");
    let verify = |name: &str, body: &str| {
        std::fs::write(dir.path().join(name), body).expect("write");
        lensc(dir.path(), &["verify", name, "--source", "corner.lens"])
    };
    let v = verify("corner.ngc", &program);
    assert!(v.status.success(), "{}", text(&v.stderr));
    let at = program.rfind("G0 W0. ").expect("the servo's retract");
    let edited = format!("{}G0 W5.5 {}", &program[..at], &program[at + 7..]);
    let v = verify("edited.ngc", &edited);
    let said = text(&v.stderr);
    assert_eq!(v.status.code(), Some(1), "{said}");
    assert!(
        said.contains("policy over-travel: this move takes the fast tool servo's axis W to 5.5 mm")
            && said.contains(" .. 5.5 mm, ")
            && said.contains("more than its 5 mm stroke"),
        "{said}"
    );
}
