//! Whole-part simulation, the default since issue #29, against the 0.2 mm
//! window that was the default before, each build in the same run:
//!
//! - a ball-end cubic phase plate (`benches/jobs/cubic_phase_plate.lens`:
//!   z = 2e-4 mm⁻² (x³ + y³) over 4 mm, a 1 mm ball, 10 µm stepover) whole
//!   at `LENSC_BENCH_PLATE_SPACING_UM` (default 20, the goal: under
//!   10 s on two cores) against a 0.2 mm window at 1 µm half way out;
//! - seed 003's whole 10 × 10 lenslet array
//!   (`examples/hashimoto2025_lens_array.lens`, 11.6 million cut points)
//!   at `LENSC_BENCH_WHOLE_SPACING_UM` (default 2, the goal: no
//!   slower than its 33 s before) against a 0.2 mm window at 1 µm on its
//!   outermost lenslet.
//!
//! Prints each build's wall and CPU time, what the whole part adds (per
//! cell evaluated), the ratio of the two builds (wall), the figures and
//! the process's peak resident memory.
//!
//! Run: cargo bench -p lensc-build --bench whole_part
//! CI runs it with the plate at 50 µm and the array at 10 µm, to stay
//! cheap. Figures are printed, never gated on: the machine is shared.

#[path = "../../../runtime/benches/support/timing.rs"]
mod timing;

use std::time::{Duration, Instant};

fn build(src: &str) -> (Duration, f64, serde_json::Value) {
    let c =
        lensc_build::driver::check_text(&lensc_lang::loader::RealFs, "bench.lens", src.as_bytes());
    assert!(!c.has_errors(), "the bench's job checks");
    let (t, cpu) = (Instant::now(), timing::cpu_seconds());
    // The program spooled to a temporary file, as `lensc build` does, so
    // the peak memory is the simulation's, not the 500 MB program text's.
    let spool = std::env::temp_dir();
    let (built, _) = lensc_build::driver::plan_and_emit(
        &c,
        lensc_build::driver::Request::default(),
        "bench.lens",
        Some(spool.as_path()),
    );
    let (e, cpu) = (t.elapsed(), timing::cpu_seconds() - cpu);
    let report = built.into_iter().next().expect("one job").report.to_json();
    (e, cpu, report)
}

/// `source` with its (one) job's block given `simulate: { … }`.
fn simulated(source: &str, simulate: &str) -> String {
    let job = source
        .lines()
        .find(|l| l.starts_with("job "))
        .expect("the job line");
    let block = job.trim_end().strip_suffix('}').expect("a job block");
    source.replace(job, &format!("{block}, simulate: {{ {simulate} }} }}"))
}

fn env_um(name: &str, default: f64) -> f64 {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// Builds `source` windowed and whole and prints both.
fn compare(title: &str, source: &str, window: &str, spacing: f64) {
    let windowed = simulated(source, &format!("{window}, spacing: 1 um"));
    let whole = simulated(source, &format!("spacing: {spacing} um"));
    let (base, base_cpu, _) = build(&windowed);
    let (t, cpu, report) = build(&whole);
    let h = &report["simulation"]["height_map"];
    let cells = h["grid"]["cells_evaluated"].as_f64().unwrap_or(f64::NAN);
    let tiles = &h["grid"]["tiles"];
    let lenslets = h["lenslets"].as_array().map_or(0, Vec::len);
    let (c, s) = (&h["contact"], &h["surface"]);
    let (t, base) = (t.as_secs_f64(), base.as_secs_f64());
    println!("{title} whole at {spacing} um ({cells} cells in {tiles} tiles, {lenslets} lenslets)");
    println!(
        "  build, 0.2 mm window at 1 um (baseline): {base:>8.2} s wall, {base_cpu:>8.2} s CPU"
    );
    println!("  build, whole part:                       {t:>8.2} s wall, {cpu:>8.2} s CPU");
    println!(
        "  whole part / window: {:.2}x (wall), {:.2}x (CPU); the whole part adds {:.0} ns CPU a cell",
        t / base,
        cpu / base_cpu,
        (cpu - base_cpu) * 1e9 / cells
    );
    println!(
        "  whole part: contacts PV {} nm, RMS {} nm; surface PV {} nm, gouge {} nm; judged: {}",
        c["pv_nm"],
        c["rms_nm"],
        s["pv_nm"],
        s["max_gouge_nm"]["value"],
        report["acceptance"]["judged"]["words"]
    );
    if let Some(w) = h["worst_lenslet"].as_object() {
        println!(
            "  worst lenslet {} at {}: PV {} nm, RMS {} nm, residual {} nm; accepted: {}",
            w["index"],
            w["centre_mm"],
            w["pv_nm"],
            w["rms_nm"],
            w["max_residual_nm"],
            report["acceptance"]["passed"]
        );
    }
}

fn main() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let plate = std::fs::read_to_string(root.join("benches/jobs/cubic_phase_plate.lens"))
        .expect("the cubic phase plate");
    compare(
        "ball-end cubic phase plate",
        &plate,
        "x: 0.9 mm .. 1.1 mm, y: -0.1 mm .. 0.1 mm",
        env_um("LENSC_BENCH_PLATE_SPACING_UM", 20.0),
    );
    let array = std::fs::read_to_string(root.join("../../examples/hashimoto2025_lens_array.lens"))
        .expect("seed 003 example");
    compare(
        "seed 003 10 x 10 array",
        &array,
        "x: 15.65 mm .. 15.85 mm, y: 15.65 mm .. 15.85 mm",
        env_um("LENSC_BENCH_WHOLE_SPACING_UM", 2.0),
    );
    println!("peak resident memory: {:.0} MB", timing::peak_resident_mb());
}
