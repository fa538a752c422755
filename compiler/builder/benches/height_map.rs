//! Height-map simulation speed (issue #6): the whole build of a job —
//! planning, program text, servo following, report — with a large
//! simulation window against the same build with a 10 µm window, in the
//! same run; the difference is what the height map costs, per grid cell.
//!
//! - seed 002's roller finish (`examples/liu_roller_pattern.lens`) on a
//!   1 µm grid over 1 mm² of the pattern (1,002,001 cells);
//! - one seed 003 lenslet (R 20 mm concave, 1.7 mm, 2 µm/rev, 5 m/min
//!   capped at 1000 rpm, settling offset) on a 2 µm grid over its
//!   aperture's square.
//!
//! Run: cargo bench -p lensc --bench height_map
//! A plain harness: best of N runs with `Instant`, both variants alternated
//! so load changes fall on both.

use std::time::{Duration, Instant};

const RUNS: usize = 3;

fn build(src: &str) -> (Duration, serde_json::Value) {
    let c =
        lensc_build::driver::check_text(&lensc_lang::loader::RealFs, "bench.lens", src.as_bytes());
    assert!(!c.has_errors(), "the bench's job checks");
    let t = Instant::now();
    let (built, diags) = lensc_build::driver::plan_and_emit(
        &c,
        lensc_build::driver::Request::default(),
        "bench.lens",
        None,
    );
    let e = t.elapsed();
    assert!(
        diags.iter().all(|d| !d.is_error()),
        "the bench's job builds"
    );
    let report = built.into_iter().next().expect("one job").report.to_json();
    (e, report)
}

fn compare(name: &str, big: &str, small: &str) {
    let (mut best_big, mut best_small) = (Duration::MAX, Duration::MAX);
    let mut report = serde_json::Value::Null;
    for _ in 0..RUNS {
        let (t, r) = build(big);
        best_big = best_big.min(t);
        report = r;
        best_small = best_small.min(build(small).0);
    }
    let grid = &report["simulation"]["height_map"]["grid"];
    let cells =
        grid["columns"].as_f64().unwrap_or(f64::NAN) * grid["rows"].as_f64().unwrap_or(f64::NAN);
    let extra = best_big.as_secs_f64() - best_small.as_secs_f64();
    println!("{name}");
    println!(
        "  build, 10 um window:        {:>8.3} s",
        best_small.as_secs_f64()
    );
    println!(
        "  build, large window:        {:>8.3} s ({cells} cells)",
        best_big.as_secs_f64()
    );
    println!(
        "  height map:                 {:>8.3} s, {:.0} ns/cell, {:.2}x the rest of the build",
        extra,
        extra * 1e9 / cells,
        extra / best_small.as_secs_f64()
    );
}

fn main() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let roller = std::fs::read_to_string(root.join("examples/liu_roller_pattern.lens"))
        .expect("seed 002 example");
    let job_end = "strategy: helix }";
    assert!(roller.contains(job_end), "the roller example's job line");
    let with = |window: &str| {
        roller.replace(
            job_end,
            &format!("strategy: helix, simulate: {{ {window} }} }}"),
        )
    };
    compare(
        "seed 002 roller finish, 1 mm2 at 1 um",
        &with("x: 2.6 mm .. 3.6 mm, y: 8.9 mm .. 9.9 mm, spacing: 1 um"),
        &with("x: 3 mm .. 3.01 mm, y: 9 mm .. 9.01 mm, spacing: 1 um"),
    );

    let lenslet = |window: &str| {
        format!(
            "surface lenslet = sphere {{ radius: 20 mm, sense: concave, aperture: circle(diameter: 1.7 mm) }}\n\
             surface one = grid(lenslet, pitch_x: 3.5 mm, pitch_y: 3.5 mm, count_x: 1, count_y: 1)\n\
             use std::machines::nanoform_x_fts5000\n\
             use std::tools::diamond_r496um\n\
             strategy s = fts_spiral {{ feed: 2 um/rev, surface_speed: 5 m/min, spindle_cap: 1000 rpm, settling_time: 1 ms }}\n\
             job one_lenslet {{ surface: one, tool: diamond_r496um, machine: nanoform_x_fts5000, strategy: s, simulate: {{ {window} }} }}\n"
        )
    };
    compare(
        "seed 003 lenslet, its aperture's square at 2 um",
        &lenslet("x: -0.85 mm .. 0.85 mm, y: -0.85 mm .. 0.85 mm, spacing: 2 um"),
        &lenslet("x: 0.4 mm .. 0.41 mm, y: 0 mm .. 0.01 mm, spacing: 2 um"),
    );
}
