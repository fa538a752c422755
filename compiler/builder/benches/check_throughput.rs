//! `check` throughput on a generated job file of 10,000 lines.
//!
//! Prints lines per second for three stages measured in the same run, and
//! their ratios, so the figure is comparable across noisy shared machines:
//!   baseline  — a byte scan that counts lines (memory bandwidth bound)
//!   parse     — pest grammar and syntax tree only
//!   check     — parse + name resolution + units + every block's kind
//!
//! Then a flood: a file of 200,000 unused `let`s (200,000 warnings), its
//! parse and check timed once each (the `lensc check` binary prints only
//! 100 of them; issue 17 asks for the whole command under 1 s).
//!
//! Run: cargo bench -p lensc-build --bench check_throughput
//! For a profiler (callgrind counts instructions, steady on a loaded
//! machine): `CHECK_THROUGHPUT_ONCE=parse` or `=check` runs that stage once
//! on the 10,000-line file and nothing else.
//! A plain harness (no criterion): the figure wanted is a ratio of three
//! stages in one process, which criterion does not print.

use std::hint::black_box;
use std::time::{Duration, Instant};

use lensc_build::driver;
use lensc_lang::loader::RealFs;

#[path = "../../../runtime/benches/support/timing.rs"]
mod timing;
use timing::best_of;

/// A realistic job file: surfaces, tools, strategies, machines and jobs
/// that use each other, with comments and units of every kind.
fn generate(lines: usize) -> String {
    let mut s = String::from("use std::machines::linuxcnc_lathe\n");
    let mut i = 0;
    while s.lines().count() < lines {
        s.push_str(&format!(
            "// lens family {i}
let r{i} = {r} mm + {i} um
surface s{i} = asphere {{
    radius: r{i}
    conic: -{k}
    sense: convex
    aperture: circle(diameter: 1.6 mm)
    A4: {a4}e-4 mm^-3
    A6: -2.5e-6 mm^-5
}}
tool t{i} = round_nose {{ nose_radius: 85 um, clearance: 7 deg, rake: 0° }}
strategy g{i} = profile_turning {{
    feed: 2 um/rev
    spindle_speed: 500 rpm + {i} rpm / 100
    chord_tolerance: 10 nm
    retract: 0.5 mm
}}
machine m{i} = linuxcnc_lathe {{ resolution: 1 nm, spindle: {{ max_speed: 4000 rpm }} }}
job j{i} {{ surface: s{i}, tool: t{i}, machine: m{i}, strategy: g{i} }}
",
            r = 10 + i % 7,
            k = 0.5 + (i % 5) as f64 * 0.1,
            a4 = 1 + i % 9,
        ));
        i += 1;
    }
    s
}

fn main() {
    let src = generate(10_000);
    let lines = src.lines().count();
    match std::env::var("CHECK_THROUGHPUT_ONCE").as_deref() {
        Ok("parse") => {
            black_box(lensc_grammar::parse(&src, lensc_grammar::FileId(0)));
            return;
        }
        Ok("check") => {
            black_box(driver::check_text(&RealFs, "bench.lens", src.as_bytes()));
            return;
        }
        _ => {}
    }
    // Sanity: the generated file is valid, so check does all of its work.
    let c = driver::check_text(&RealFs, "bench.lens", src.as_bytes());
    assert!(!c.has_errors(), "generated file has errors");
    assert!(c.checked.jobs.len() > 500);

    let runs = 15;
    let baseline = best_of(runs * 10, || {
        black_box(
            black_box(src.as_bytes())
                .iter()
                .filter(|&&b| b == b'\n')
                .count(),
        );
    });
    let parse = best_of(runs, || {
        black_box(lensc_grammar::parse(
            black_box(&src),
            lensc_grammar::FileId(0),
        ));
    });
    let check = best_of(runs, || {
        black_box(driver::check_text(
            &RealFs,
            "bench.lens",
            black_box(src.as_bytes()),
        ));
    });
    let per_s = |d: Duration| lines as f64 / d.as_secs_f64();
    println!(
        "check_throughput: {lines} lines, {} bytes, best of {runs}",
        src.len()
    );
    println!("  baseline (line count) {:>14.0} lines/s", per_s(baseline));
    println!(
        "  parse                 {:>14.0} lines/s  ({:.1}x baseline time)",
        per_s(parse),
        parse.as_secs_f64() / baseline.as_secs_f64()
    );
    println!(
        "  check                 {:>14.0} lines/s  ({:.1}x baseline time, {:.2}x parse time)",
        per_s(check),
        check.as_secs_f64() / baseline.as_secs_f64(),
        check.as_secs_f64() / parse.as_secs_f64()
    );
    flood();
}

/// Parse and check of 200,000 unused `let`s, each timed once.
fn flood() {
    let mut src = String::new();
    for i in 0..200_000 {
        src.push_str(&format!("let a{i} = 1 mm\n"));
    }
    let t = Instant::now();
    black_box(lensc_grammar::parse(&src, lensc_grammar::FileId(0)));
    let parse = t.elapsed();
    let t = Instant::now();
    let c = driver::check_text(&RealFs, "flood.lens", src.as_bytes());
    let check = t.elapsed();
    assert_eq!(c.diags().len(), 200_000);
    println!("flood: 200,000 unused lets, {} bytes", src.len());
    println!("  parse {:>8.3} s", parse.as_secs_f64());
    println!("  check {:>8.3} s  (parse included)", check.as_secs_f64());
}
