//! A compensated build against the plain build of the same job, in one
//! run (issue #30: at most 1.3×). The job is the off-axis paraboloid
//! segment of `examples/off_axis_and_tilt.lens` (`oap_sts`: a 10 mm
//! segment on a slow-tool-servo lathe, 56,588 lines); the measurement is
//! a 1000 × 1000 X3P map over its aperture (the design, 30 nm of
//! astigmatism, 10 nm of ripple 2 mm long and 1 nm of noise), written
//! once. Each build is what `lensc build` does after reading the file:
//! check, lower (for the compensated job: the measurement read, thinned,
//! registered, fitted and the corrected surface analysed), plan, write
//! the program into a temporary directory beside the target directory
//! (spooled and read back), then remove it. The two alternate, best of
//! `RUNS` each, wall and CPU time. First, each job's surface kernel (the
//! corrected one for the compensated job) is timed alone, a point.
//!
//! Run: cargo bench -p lensc-build --bench compensate (`COMPENSATE_RUNS=N`,
//! default 3).

#[path = "../../../runtime/benches/support/timing.rs"]
mod timing;

use std::path::Path;
use std::time::Instant;

use lensc_build::job::Limits;
use lensc_build::output::Destination;
use lensc_measure::HeightMap;
use lensc_runtime::post::Provenance;

const JOB: &str = "use std::machines::moore_nanotech_450fg
use std::tools::diamond_r500um
surface parent = conic { radius: 50 mm, conic: -1, sense: concave, aperture: circle(radius: 30 mm) }
surface oap = off_axis(parent, x: 20 mm, y: 0 mm, tilt: remove, aperture: circle(diameter: 10 mm))
strategy sts_fine = spiral_turning { feed: 20 um/rev, spindle_speed: 50 rpm, chord_tolerance: 5 nm }
job oap_sts { surface: oap, tool: diamond_r500um, machine: moore_nanotech_450fg, strategy: sts_fine, accept: { form_pv: 5 nm, form_rms: 1 nm, max_gouge: 5 nm, uncut_area: 0 }COMPENSATE }
";

fn provenance() -> Provenance {
    Provenance {
        source: "bench.lens".into(),
        source_hash: 0,
        lensc_version: "bench".into(),
    }
}

/// Checks, lowers and builds `file` (one job) into `dir`, the program put
/// in place and removed; its size (bytes) and the CPU time (s) of the
/// check and lowering alone (for the compensated job, where the
/// measurement is read, registered and fitted).
fn build(file: &Path, dir: &Path) -> (u64, f64) {
    // As a fresh `lensc build` process: no kernel compiled before.
    lensc_build::evaluate::compiled::COMPILED.clear();
    let cpu = timing::cpu_seconds();
    let c = lensc_build::driver::check_path(&lensc_lang::loader::RealFs, file).expect("reads");
    assert!(!c.has_errors(), "checks");
    let job = &c.checked.jobs[0];
    let (spec, _) = lensc_build::pipeline::lower(job, None, &Limits::default())
        .unwrap_or_else(|d| panic!("lowers: {d:?}"));
    let lowering = timing::cpu_seconds() - cpu;
    let built = lensc_build::pipeline::build_and_read_back(
        job,
        &spec,
        &provenance(),
        Destination::Spool(dir),
    )
    .unwrap_or_else(|d| panic!("builds: {d:?}"));
    let bytes = built.program.bytes();
    let path = dir.join(&built.program_name);
    built.program.write_to(&path).expect("program written");
    std::fs::remove_file(&path).expect("program removed");
    (bytes, lowering)
}

/// The measured part: the design's heights on a 1000 × 1000 grid over the
/// aperture with a known error and noise.
fn measurement(file: &Path) -> Vec<u8> {
    let c = lensc_build::driver::check_path(&lensc_lang::loader::RealFs, file).expect("reads");
    let (spec, _) = lensc_build::pipeline::lower(&c.checked.jobs[0], None, &Limits::default())
        .unwrap_or_else(|d| panic!("lowers: {d:?}"));
    let lowered = &spec.head().surface.lowered;
    let (f, _) = lensc_build::evaluate::evaluator(&lowered.tape);
    let n = 1000;
    let dx = 10.0 / (n - 1) as f64;
    let (mut xs, mut ys) = (Vec::with_capacity(n * n), Vec::with_capacity(n * n));
    for j in 0..n {
        for i in 0..n {
            xs.push(-5.0 + i as f64 * dx);
            ys.push(-5.0 + j as f64 * dx);
        }
    }
    let mut out = vec![0.0; 6 * n * n];
    f.eval_batch(&xs, &ys, &mut out);
    let mut seed: u64 = 0x9e37_79b9_7f4a_7c15;
    let mut noise = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 3.46e-6
    };
    let z: Vec<f64> = (0..n * n)
        .map(|k| {
            let (x, y) = (xs[k], ys[k]);
            if x * x + y * y > 4.95 * 4.95 {
                return f64::NAN;
            }
            let error = 30e-6 * (x * x - y * y) / 25.0
                + 10e-6 * (2.0 * std::f64::consts::PI * x / 2.0).sin();
            out[6 * k] + error + noise()
        })
        .collect();
    lensc_measure::write::x3p(&HeightMap::from_heights(n, n, (dx, dx), z), "bench")
}

/// The job's surface kernel (the corrected one for the compensated job):
/// ns a point for all six outputs and for the height alone, best of 3
/// passes over 200,000 points across the aperture.
fn kernel_cost(file: &Path) -> (f64, f64) {
    let c = lensc_build::driver::check_path(&lensc_lang::loader::RealFs, file).expect("reads");
    let (spec, _) = lensc_build::pipeline::lower(&c.checked.jobs[0], None, &Limits::default())
        .unwrap_or_else(|d| panic!("lowers: {d:?}"));
    let tape = &spec.head().surface.lowered.tape;
    let mut heights = tape.clone();
    let nan = heights.graph.constant_node(f64::NAN);
    heights.outputs = [tape.outputs[0], nan, nan, nan, nan, nan];
    let n = 200_000;
    let xs: Vec<f64> = (0..n)
        .map(|k| -4.9 + 9.8 * (k % 500) as f64 / 500.0)
        .collect();
    let ys: Vec<f64> = (0..n)
        .map(|k| -4.9 + 9.8 * (k / 500) as f64 / 400.0)
        .collect();
    let mut out = vec![0.0; 6 * n];
    let mut time = |t: &lensc_runtime::surface::ir::SurfaceTape| {
        let (f, _) = lensc_build::evaluate::evaluator(t);
        (0..3)
            .map(|_| {
                let s = Instant::now();
                f.eval_batch(&xs, &ys, &mut out);
                s.elapsed().as_secs_f64() * 1e9 / n as f64
            })
            .fold(f64::INFINITY, f64::min)
    };
    (time(tape), time(&heights))
}

fn main() {
    let runs: usize = std::env::var("COMPENSATE_RUNS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(3);
    let target = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target");
    let dir = tempfile::tempdir_in(&target).expect("a temporary directory");
    let plain = dir.path().join("plain.lens");
    let compensated = dir.path().join("compensated.lens");
    std::fs::write(&plain, JOB.replace("COMPENSATE", "")).unwrap();
    std::fs::write(
        &compensated,
        JOB.replace(
            "COMPENSATE",
            ", compensate: { measurement: \"part.x3p\", gain: 0.8, smoothing: 1 mm }",
        ),
    )
    .unwrap();
    let bytes = measurement(&plain);
    std::fs::write(dir.path().join("part.x3p"), &bytes).unwrap();
    println!(
        "measurement: 1000 x 1000 X3P, {:.1} MB",
        bytes.len() as f64 / 1e6
    );
    for (name, file) in [("plain", &plain), ("compensated", &compensated)] {
        let (full, heights) = kernel_cost(file);
        println!(
            "{name:>12}: surface kernel {full:.1} ns a point (all six outputs), {heights:.1} ns (height only)"
        );
    }
    let out = dir.path().join("out");
    std::fs::create_dir_all(&out).unwrap();
    let mut best = [(f64::INFINITY, f64::INFINITY); 2];
    let mut sizes = [0u64; 2];
    let mut lowering = [f64::INFINITY; 2];
    for _ in 0..runs {
        for (k, file) in [&plain, &compensated].into_iter().enumerate() {
            let (t, c) = (Instant::now(), timing::cpu_seconds());
            let (size, lower) = build(file, &out);
            sizes[k] = size;
            lowering[k] = lowering[k].min(lower);
            let (wall, cpu) = (t.elapsed().as_secs_f64(), timing::cpu_seconds() - c);
            best[k] = (best[k].0.min(wall), best[k].1.min(cpu));
        }
    }
    for (k, name) in ["plain", "compensated"].iter().enumerate() {
        println!(
            "{name:>12}: {:.3} s wall, {:.3} s CPU (check and lowering {:.3} s CPU), program {} bytes",
            best[k].0, best[k].1, lowering[k], sizes[k]
        );
    }
    println!(
        "compensated / plain: {:.3}x wall, {:.3}x CPU (goal <= 1.3x)",
        best[1].0 / best[0].0,
        best[1].1 / best[0].1
    );
    // The ratios mean little on a loaded machine: say how loaded it was.
    println!(
        "load average (1, 5, 15 min): {}",
        std::fs::read_to_string("/proc/loadavg")
            .unwrap_or_default()
            .split_whitespace()
            .take(3)
            .collect::<Vec<_>>()
            .join(", ")
    );
}
