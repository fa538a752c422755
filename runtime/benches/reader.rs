//! The read-back reader's speed (`reader::Reader`, what `lensc build` runs
//! on every program and `lensc verify` on any): nanoseconds a line with
//! the common block read in one pass (the default) against the whole
//! path (`Reader::set_fast_path(false)`), in the same run, on the same
//! text, with the same findings asserted.
//!
//! The text is two programs made here as lensc writes them for issue
//! #18's seeds, on their machines: a slow-tool-servo roller helix
//! (seed 002: `G1 X… C… F…`, every third line with Z) and a fast-tool-servo
//! spiral (seed 003: `G1 Z… C… F…`, a third with X). A real program can be
//! read instead: `READER_PROGRAM=path/to/program.ngc` (a LinuxCNC lathe
//! program; read on the roller's machine, whose limits both seeds keep).
//! `READER_ONLY=fast` times the fast path alone (for a profiler).
//!
//! Goal (issue #18): at most 80 ns a line. Run:
//!     cargo bench -p lensc-runtime --bench reader

use std::hint::black_box;

use lensc_runtime::dialect::Dialect;
use lensc_runtime::reader::{Finding, MachineLimits, Reader};

#[path = "support/timing.rs"]
mod timing;
use timing::{best_run, cpu_seconds};

/// Lines of each made program.
const LINES: usize = 2_000_000;

const ROLLER_HEAD: &str = "(lensc 0.1.0: job roller_microlenses_helix)
(units mm; X is the radius of the nose centre about the roller axis, Z along the roller,)
(  C the spindle angle in degrees counted on from the start)
(coordinates are the centre of the tool nose; feed in inverse time [G93, F = 1/min per move])
(machine moore_nanotech_450fg: linuxcnc slow-tool-servo lathe)
G18 G21 G90 G8 G40 G49 G80 G94
G64 P0.000001
T1 M6 G43
G0 X4.07424
G0 Z-3. C0.
G93 G1 X3.071765 F60.
";

const SPIRAL_HEAD: &str = "(lensc 0.1.0: job lens_array_fts)
(units mm; X is the radius, C the spindle angle in degrees counted on from the start, Z the fast tool servo's axis,)
(  +Z out of the material)
(machine nanoform_x_fts5000: linuxcnc fast-tool-servo lathe)
G18 G21 G90 G8 G40 G49 G80 G94
G64 P0.0000025
T1 M6 G43
G0 Z1.499719
G0 X24.748737 C0.
G93 G1 Z0.499719 F60.
";

/// Up to 6 decimals, trailing zeros dropped, the point kept (`3.`), as
/// the LinuxCNC writer prints.
fn num(v: f64, decimals: usize) -> String {
    let s = format!("{v:.decimals$}");
    let s = s.trim_end_matches('0');
    if s == "-0." { "0.".into() } else { s.into() }
}

fn roller() -> String {
    let mut t = String::from(ROLLER_HEAD);
    for i in 1..=LINES {
        let c = i as f64 * 0.025;
        let x = 3.07 + 0.0017 * (c.to_radians() * 40.0).sin();
        let z = -3.0 + 4e-3 * c / 360.0;
        if i % 3 == 0 {
            t += &format!("G1 X{} Z{} C{} F864000.\n", num(x, 6), num(z, 6), num(c, 5));
        } else {
            t += &format!("G1 X{} C{} F864000.\n", num(x, 6), num(c, 5));
        }
    }
    t + "G0 X4.07424\nM2\n"
}

fn spiral() -> String {
    let mut t = String::from(SPIRAL_HEAD);
    for i in 1..=LINES {
        let c = i as f64 * 2.1;
        let x = 24.748737 - 0.002 * c / 360.0;
        let z = 0.4997 - 0.018 * (c.to_radians() * 7.0).sin().powi(2);
        let f = num(32.0 + (i % 97) as f64 * 0.013, 3);
        if i % 3 == 0 {
            t += &format!("G1 X{} Z{} C{} F{f}\n", num(x, 6), num(z, 6), num(c, 5));
        } else {
            t += &format!("G1 Z{} C{} F{f}\n", num(z, 6), num(c, 5));
        }
    }
    t + "G0 Z1.499719\nM2\n"
}

/// Reads `text` line by line as the build's read-back does (`ReadAlong`).
fn read(text: &str, machine: &MachineLimits, fast: bool) -> Vec<Finding> {
    let mut r = Reader::new(&Dialect::linuxcnc(), machine);
    r.set_fast_path(fast);
    r.lines(text, 0);
    r.finish()
}

fn main() {
    let machine = MachineLimits {
        lathe: true,
        travel: [Some((-10.0, 220.0)), None, Some((-150.0, 150.0)), None],
        max_feed: Some(1500.0),
        max_spindle_rpm: Some(3000.0),
        servo: None,
    };
    let runs: usize = std::env::var("READER_RUNS")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(3);
    let programs: Vec<(String, String)> = match std::env::var("READER_PROGRAM") {
        Ok(path) => vec![(
            path.clone(),
            std::fs::read_to_string(&path).expect("READER_PROGRAM: a readable program"),
        )],
        Err(_) => vec![
            ("roller helix (seed 002's form)".into(), roller()),
            ("FTS spiral (seed 003's form)".into(), spiral()),
        ],
    };
    println!("reader: {runs} runs of each path");
    for (name, text) in &programs {
        let lines = text.lines().count() as f64;
        if std::env::var("READER_ONLY").is_ok_and(|o| o == "fast") {
            // For a profiler: the fast path alone.
            let (fast, _) = best_run(runs, || read(black_box(text), &machine, true));
            println!(
                "{name}: fast path {:.1} ns/line",
                fast.as_secs_f64() * 1e9 / lines
            );
            continue;
        }
        let cpu = cpu_seconds();
        let (whole, found_whole) = best_run(runs, || read(black_box(text), &machine, false));
        let cpu_whole = cpu_seconds() - cpu;
        let cpu = cpu_seconds();
        let (fast, found_fast) = best_run(runs, || read(black_box(text), &machine, true));
        let cpu_fast = cpu_seconds() - cpu;
        assert_eq!(found_fast, found_whole, "{name}: the two paths disagree");
        let ns = |d: std::time::Duration| d.as_secs_f64() * 1e9 / lines;
        // CPU a line, over every run (the wall's best run is the load's
        // on a shared machine; the CPU time is not).
        let cpu_ns = |s: f64| s * 1e9 / (lines * runs as f64);
        println!(
            "{name}: {lines} lines, {:.0} MB, {} findings",
            text.len() as f64 / 1e6,
            found_fast.len()
        );
        println!(
            "  whole path {:>6.1} ns/line CPU, best wall {:>6.1} ns/line",
            cpu_ns(cpu_whole),
            ns(whole),
        );
        println!(
            "  fast path  {:>6.1} ns/line CPU, best wall {:>6.1} ns/line: {:.2}x faster CPU, {:.2}x wall",
            cpu_ns(cpu_fast),
            ns(fast),
            cpu_whole / cpu_fast,
            whole.as_secs_f64() / fast.as_secs_f64()
        );
    }
}
