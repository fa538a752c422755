//! Delivery (issue 31, item 3): a program larger than its machine's
//! `delivery` allows is split into parts a main program calls, and the set
//! reads back as the whole: `lensc verify` follows the calls and finds
//! nothing, the moves read back from the set are those of the unsplit
//! build, and LinuxCNC's own interpreter makes the same canonical moves.

use std::path::Path;

use crate::common::{lensc, text};
use lensc_runtime::dialect::{Dialect, PartCalls};
use lensc_runtime::reader::{self, MachineLimits};

/// Lin's oblate scraped on the generic mill (LinuxCNC), with `delivery`.
fn job(delivery: &str) -> String {
    format!(
        "use std::machines::generic_3axis_mill\n\
         use std::tools::microshaper_r85um\n\
         machine m = generic_3axis_mill {{ {delivery} }}\n\
         surface s = conic {{ radius: 3 mm, conic: 10, sense: convex, aperture: circle(diameter: 1.6 mm) }}\n\
         strategy scrape = raster {{ along: x, direction: one_way, stepover: 10 um, chord_tolerance: 200 nm, lin_angle: 5 deg, feed: 100 mm/min, retract: 0.5 mm }}\n\
         job sp {{ surface: s, tool: microshaper_r85um, machine: m, strategy: scrape, accept: none }}\n"
    )
}

fn build(dir: &Path, delivery: &str) -> std::path::PathBuf {
    std::fs::write(dir.join("job.lens"), job(delivery)).expect("write");
    let out = lensc(dir, &["build", "job.lens", "--out", "out"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    dir.join("out")
}

/// LinuxCNC's part calls as `stdlib/dialects.lens` states them.
fn linuxcnc() -> Dialect {
    Dialect {
        parts: Some(PartCalls {
            call: "O<{part}> call".into(),
            name: "{job}_{k}".into(),
            extension: "ngc".into(),
            start: vec!["O<{part}> sub".into()],
            end: vec!["O<{part}> endsub".into(), "M2".into()],
            continuous: true,
        }),
        ..Dialect::linuxcnc()
    }
}

const MILL: MachineLimits = MachineLimits {
    lathe: false,
    travel: [None; 4],
    max_feed: None,
    max_spindle_rpm: None,
    servo: None,
};

#[test]
fn a_split_program_reads_back_as_the_whole() {
    let split_dir = tempfile::tempdir().expect("tmp");
    let whole_dir = tempfile::tempdir().expect("tmp");
    let limit = 20_000;
    let split = build(
        split_dir.path(),
        &format!("delivery: {{ link: data_server, file_limit: {limit}, rate: 1000000 }}"),
    );
    let whole = build(whole_dir.path(), "delivery: { link: disk }");
    let whole_text = std::fs::read_to_string(whole.join("sp.ngc")).expect("whole program");
    assert!(whole_text.len() > 3 * limit, "{} bytes", whole_text.len());
    let main = std::fs::read_to_string(split.join("sp.ngc")).expect("main program");
    let d = linuxcnc();
    let parts = reader::parts::part_files(&main, &d, "sp");
    assert!(parts.len() >= 3, "{} parts:\n{main}", parts.len());
    for p in &parts {
        let bytes = std::fs::metadata(split.join(p)).expect("a part").len();
        assert!(bytes <= limit as u64, "{p}: {bytes} bytes");
    }
    // The report names the parts.
    let report: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(split.join("sp.report.json")).expect("report"),
    )
    .expect("json");
    let listed = report["program"]["delivery"]["parts"]
        .as_array()
        .expect("parts listed")
        .len();
    assert_eq!(listed, parts.len());
    // `lensc verify` reads the set as one program and finds nothing.
    let v = lensc(split_dir.path(), &["verify", "out/sp.ngc"]);
    assert_eq!(v.status.code(), Some(0), "{}", text(&v.stderr));
    assert!(
        text(&v.stderr).contains("nothing found"),
        "{}",
        text(&v.stderr)
    );
    // The moves read back from the set are the whole program's.
    let mut load = |n: &str| std::fs::read_to_string(split.join(n)).map_err(|e| e.to_string());
    let assembled = reader::parts::assemble(&main, &d, "sp", &mut load).expect("assembles");
    let (found, moves) = reader::read_moves(&assembled, &d, &MILL);
    let (_, whole_moves) = reader::read_moves(&whole_text, &d, &MILL);
    assert!(found.is_empty(), "{found:?}");
    assert!(whole_moves.len() > 2000);
    assert_eq!(moves, whole_moves);
    // A part removed: verify refuses the set.
    std::fs::remove_file(split.join(&parts[1])).expect("remove");
    let v = lensc(split_dir.path(), &["verify", "out/sp.ngc"]);
    assert_eq!(v.status.code(), Some(1), "{}", text(&v.stderr));
}

/// LinuxCNC's interpreter (`rs274`, where installed) follows the O-word
/// calls from the main program's directory and makes the same canonical
/// moves as from the whole program.
#[test]
fn rs274_runs_the_split_set_as_the_whole() {
    if std::process::Command::new("rs274")
        .arg("-h")
        .output()
        .is_err()
    {
        eprintln!("rs274 not installed: skipped");
        return;
    }
    let split_dir = tempfile::tempdir().expect("tmp");
    let whole_dir = tempfile::tempdir().expect("tmp");
    let split = build(
        split_dir.path(),
        "delivery: { link: data_server, file_limit: 20000, rate: 1000000 }",
    );
    let whole = build(whole_dir.path(), "delivery: { link: disk }");
    let canonical = |dir: &Path| -> Vec<String> {
        let out = std::process::Command::new("rs274")
            .current_dir(dir)
            .args(["-g", "sp.ngc"])
            .output()
            .expect("rs274");
        assert!(out.status.success(), "{}", text(&out.stdout));
        text(&out.stdout)
            .lines()
            .filter(|l| l.contains("STRAIGHT_") || l.contains("ARC_FEED"))
            .map(|l| l.split_once("N..... ").map_or(l, |(_, m)| m).to_string())
            .collect()
    };
    let (a, b) = (canonical(&split), canonical(&whole));
    assert!(b.len() > 2000);
    assert_eq!(a, b);
}

/// A spiral program that must not stop on the surface (a slow-tool-servo
/// spiral_turning job) and a fast-tool-servo program, each split by its
/// machine's `delivery` in LinuxCNC's dialect (`part_joins: continuous`):
/// the set reads back as the whole (`lensc verify` clean, the very moves
/// of the unsplit build, the same simulated figures), and every join is at
/// a point the control passes without stopping: between two feed moves,
/// with no rapid (no retract on the surface) at either side, and the part
/// after it restating every modal word in force there in the whole
/// program.
#[test]
fn spiral_and_servo_programs_split_at_joins_the_control_passes_and_read_back_whole() {
    const SPIRAL: &str = "use std::machines::moore_nanotech_450fg\n\
        use std::tools::diamond_r500um\n\
        machine m = moore_nanotech_450fg { DELIVERY }\n\
        surface lens = sphere { radius: 12 mm, sense: convex, aperture: circle(diameter: 6 mm) }\n\
        surface tilted = tilt(lens, about: y, angle: 3 deg, aperture: circle(diameter: 1.5 mm))\n\
        strategy sts = spiral_turning { feed: 50 um/rev, spindle_speed: 50 rpm, chord_tolerance: 50 nm }\n\
        job sp { surface: tilted, tool: diamond_r500um, machine: m, strategy: sts, accept: none }\n";
    let servo_file =
        std::fs::read_to_string(crate::common::root().join("tests/jobs/fts_small_array.lens"))
            .expect("fts_small_array.lens");
    let servo = servo_file
        .replace(
            "use std::machines::nanoform_x_fts5000\n",
            "use std::machines::nanoform_x_fts5000\nmachine m = nanoform_x_fts5000 { DELIVERY }\n",
        )
        .replace("machine: nanoform_x_fts5000", "machine: m")
        .replace("job corner_fts {", "job sp {");
    assert!(servo.contains("{ DELIVERY }") && servo.contains("job sp {"));
    let d = linuxcnc();
    for (what, source, limit) in [
        ("spiral", SPIRAL, 10_000usize),
        ("servo", servo.as_str(), 100_000),
    ] {
        let split_dir = tempfile::tempdir().expect("tmp");
        let whole_dir = tempfile::tempdir().expect("tmp");
        let build = |dir: &Path, delivery: &str| {
            std::fs::write(dir.join("job.lens"), source.replace("DELIVERY", delivery))
                .expect("write");
            let out = lensc(dir, &["build", "job.lens", "--out", "out"]);
            assert_eq!(out.status.code(), Some(0), "{what}: {}", text(&out.stderr));
            dir.join("out")
        };
        let split = build(
            split_dir.path(),
            &format!("delivery: {{ link: data_server, file_limit: {limit}, rate: 100000000 }}"),
        );
        let whole = build(whole_dir.path(), "delivery: { link: disk }");
        let whole_text = std::fs::read_to_string(whole.join("sp.ngc")).expect("whole program");
        assert!(
            whole_text.len() > 3 * limit,
            "{what}: {} bytes",
            whole_text.len()
        );
        let main = std::fs::read_to_string(split.join("sp.ngc")).expect("main program");
        let parts = reader::parts::part_files(&main, &d, "sp");
        assert!(parts.len() >= 3, "{what}: {} parts", parts.len());
        // `lensc verify` reads the set as one program and finds nothing.
        let v = lensc(split_dir.path(), &["verify", "out/sp.ngc"]);
        assert_eq!(v.status.code(), Some(0), "{what}: {}", text(&v.stderr));
        assert!(
            text(&v.stderr).contains("nothing found"),
            "{what}: {}",
            text(&v.stderr)
        );
        // The very moves of the whole program (the servo job's machine,
        // the standard library's, gives its servo the letter W).
        let machine = MachineLimits {
            lathe: true,
            servo: (what == "servo").then_some(reader::ServoAxis {
                letter: 'W',
                max_velocity: 45_000.0,
                stroke: 5.0,
            }),
            ..MILL
        };
        let mut load = |n: &str| std::fs::read_to_string(split.join(n)).map_err(|e| e.to_string());
        let assembled = reader::parts::assemble(&main, &d, "sp", &mut load).expect("assembles");
        let (found, moves) = reader::read_moves(&assembled, &d, &machine);
        let (_, whole_moves) = reader::read_moves(&whole_text, &d, &machine);
        assert!(found.is_empty(), "{what}: {found:?}");
        assert!(
            whole_moves.len() > 500,
            "{what}: {} moves",
            whole_moves.len()
        );
        assert_eq!(moves, whole_moves, "{what}");
        // The same simulated figures: the reports' simulations agree.
        let report = |dir: &Path| -> serde_json::Value {
            serde_json::from_str(
                &std::fs::read_to_string(dir.join("sp.report.json")).expect("report"),
            )
            .expect("json")
        };
        let (rs, rw) = (report(&split), report(&whole));
        assert!(rw["simulation"].is_object(), "{what}: {rw}");
        assert_eq!(rs["simulation"], rw["simulation"], "{what}");
        assert_eq!(rs["acceptance"], rw["acceptance"], "{what}");
        // Each join: the part's body continues the whole program's body.
        let whole_lines: Vec<&str> = whole_text.lines().collect();
        let is_move = |l: &str| {
            l.split_whitespace()
                .any(|w| ["G0", "G1", "G2", "G3"].contains(&w))
        };
        let is_rapid = |l: &str| l.split_whitespace().any(|w| w == "G0");
        let mut at = None::<usize>;
        let mut mid_cut = 0;
        for (k, name) in parts.iter().enumerate() {
            let part = std::fs::read_to_string(split.join(name)).expect("part");
            let lines: Vec<&str> = part.lines().collect();
            // The part's body: after its opening, its comment and its
            // restated words, before its closing `O<…> endsub` and `M2`.
            let first_move = lines.iter().position(|l| is_move(l)).expect("a move");
            // (A later part's body starts at a move: its join is between
            // two.)
            let body_start = if k == 0 { 2 } else { first_move };
            let body = &lines[body_start..lines.len() - 2];
            let start = match at {
                None => whole_lines
                    .iter()
                    .position(|l| *l == body[0])
                    .expect("the first part's body in the whole"),
                Some(s) => s,
            };
            assert_eq!(
                &whole_lines[start..start + body.len()],
                body,
                "{what}: {name}"
            );
            if k > 0 {
                // In the air (after a rapid) or mid-cut, between two feed
                // moves the control runs through (the part continues the
                // whole program's lines: nothing added at the join).
                let before = whole_lines[..start]
                    .iter()
                    .rev()
                    .find(|l| is_move(l))
                    .expect("a move before");
                let after = body.iter().find(|l| is_move(l)).expect("a move after");
                if !is_rapid(before) && !is_rapid(after) {
                    mid_cut += 1;
                }
                // Every modal word in force at the join, restated: each
                // group's last word before it in the whole program.
                let restated: Vec<&str> = lines[..first_move]
                    .iter()
                    .flat_map(|l| l.split_whitespace())
                    .collect();
                let groups: [&[&str]; 6] = [
                    &["G17", "G18", "G19"],
                    &["G20", "G21"],
                    &["G90", "G91"],
                    &["G93", "G94", "G95"],
                    &["G96", "G97"],
                    &["G61", "G61.1", "G64"],
                ];
                let words_before = whole_lines[..start]
                    .iter()
                    .filter(|l| !l.starts_with('('))
                    .flat_map(|l| l.split_whitespace());
                let mut last: Vec<Option<&str>> = vec![None; groups.len() + 2];
                for w in words_before {
                    if let Some(g) = groups.iter().position(|g| g.contains(&w)) {
                        last[g] = Some(w);
                    } else if w.starts_with('F') {
                        last[groups.len()] = Some(w);
                    } else if w.starts_with('S') {
                        last[groups.len() + 1] = Some(w);
                    }
                }
                let inverse = last[3] == Some("G93");
                for (g, w) in last.iter().enumerate() {
                    let Some(w) = w else { continue };
                    if inverse && g == groups.len() {
                        continue; // under G93 every move states its own F
                    }
                    assert!(
                        restated.contains(w),
                        "{what}: {name} does not restate {w}: {restated:?}"
                    );
                }
            }
            at = Some(start + body.len());
        }
        // The cut is long: it is split inside, where the control does not
        // stop.
        assert!(mid_cut >= 1, "{what}: no join inside the cut");
    }
}

/// A profile turned at constant surface speed (faster in rpm toward the
/// axis, up to the cap) in straight moves (LinuxCNC's dialect without
/// arcs), on the ultra-precision lathe with `delivery`.
fn css_job(delivery: &str) -> String {
    format!(
        "use std::machines::ultra_precision_lathe\n\
         use std::tools::diamond_r500um\n\
         dialect lines = linuxcnc {{ arc_planes: [] }}\n\
         machine m = ultra_precision_lathe {{ dialect: lines, {delivery} }}\n\
         surface insert = conic {{ radius: 8.5 mm, conic: -0.62, sense: convex, aperture: circle(diameter: 6 mm) }}\n\
         strategy css = profile_turning {{ feed: 2 um/rev, surface_speed: 30 m/min, spindle_cap: 3000 rpm }}\n\
         job sp {{ surface: insert, tool: diamond_r500um, machine: m, strategy: css, accept: none }}\n"
    )
}

/// A link whose rate the program's average fits, but not a stretch of its
/// blocks (at constant surface speed the spindle turns faster toward the
/// axis, and the control runs the blocks there faster), with a buffer too
/// small to cover it: W0050 names the stretch (its lines), the buffer and
/// the feed that fits; with a buffer that covers it, or a link twice as
/// fast as the fastest block, none.
#[test]
fn a_stretch_of_short_blocks_faster_than_the_link_is_warned_of() {
    let built = |delivery: &str| -> (tempfile::TempDir, String) {
        let d = tempfile::tempdir().expect("tmp");
        std::fs::write(d.path().join("job.lens"), css_job(delivery)).expect("write");
        let out = lensc(d.path(), &["build", "job.lens", "--out", "out"]);
        assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
        assert!(
            d.path().join("out/sp.ngc").exists(),
            "a warning writes the program"
        );
        let err = text(&out.stderr);
        (d, err)
    };
    let (whole, _) = built("delivery: { link: disk }");
    let program = std::fs::read_to_string(whole.path().join("out/sp.ngc")).expect("program");
    let lathe = MachineLimits {
        lathe: true,
        ..MILL
    };
    let lines = reader::timing::line_times(&program, &linuxcnc(), &lathe);
    let bytes: f64 = lines.iter().map(|l| f64::from(l.bytes)).sum();
    let seconds: f64 = lines.iter().map(|l| l.seconds).sum();
    // A link 5 % faster than the program's average, a buffer of 300
    // bytes.
    let rate = (bytes / seconds * 1.05).ceil();
    let starved = lensc_build::delivery::starved(&lines, rate, 300.0, 1.0)
        .expect("a stretch of this profile outruns its average rate");
    // The stretch's own rate is above the link's.
    assert!(starved.bytes as f64 / starved.seconds > rate);
    let (_, err) = built(&format!(
        "delivery: {{ link: dnc, rate: {rate}, buffer: 300 }}"
    ));
    assert!(err.contains("[W0050]"), "{err}");
    assert!(
        err.contains(&format!(
            "lines {} to {} of sp.ngc need",
            starved.first + 1,
            starved.last + 1
        )) && err.contains("its buffer of 300 bytes")
            && err.contains("with the tool on the part")
            && err.contains("the feed that fits is"),
        "{err}"
    );
    let (_, err) = built(&format!(
        "delivery: {{ link: dnc, rate: {rate}, buffer: 300000 }}"
    ));
    assert!(
        !err.contains("[W0050]"),
        "a buffer of 300 kB covers it: {err}"
    );
    // A link twice as fast as the fastest block: nothing to warn of.
    let peak = lines
        .iter()
        .filter(|l| l.seconds > 0.0)
        .map(|l| f64::from(l.bytes) / l.seconds)
        .fold(0.0, f64::max);
    let (_, err) = built(&format!(
        "delivery: {{ link: dnc, rate: {}, buffer: 300 }}",
        (peak * 2.0).ceil()
    ));
    assert!(!err.contains("[W0050]"), "{err}");
}
