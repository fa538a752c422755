//! The big builds against their own planning, measured in one run (issue
//! #18's first three rows):
//!
//! - seed 003's 10 × 10 array (`examples/hashimoto2025_lens_array.lens`,
//!   11.65 M lines, 502 MB): `build` (planned, formatted, simulated, the
//!   program spooled, read back and put in place, as `lensc build` makes
//!   it) against its planning alone (the planner's points counted,
//!   nothing else). Goal: ≤ 1.2×.
//! - seed 002's microlens roller (`examples/liu_roller_microlens.lens`,
//!   21.6 M points, 709 MB): `build`, goal ≤ 6 s; and `report` (planned
//!   and simulated, no program formatted, the plots drawn) against its
//!   planning alone plus its simulation alone (the printed points swept
//!   over the height map's grid from memory, and the map finished). Goal:
//!   ≤ 1.05×.
//!
//! Each figure is the best of `RUNS`, wall and the process's CPU time
//! (user + system, all threads): the machine is shared, and CPU time is
//! the steadier figure when it is loaded. The program is written into a
//! temporary directory beside the target directory and deleted.
//!
//! Run: cargo bench -p lensc-build --bench pipeline (about a minute per
//! run on a quiet 2-core machine; too slow for CI). `PIPELINE_RUNS=N`
//! changes the number of runs (default 2).

#[path = "../../../runtime/benches/support/timing.rs"]
mod timing;

use std::path::Path;
use std::time::Instant;

use lensc_build::job::Limits;
use lensc_build::output::Destination;
use lensc_build::strategy::JobSpec;
use lensc_lang::Checked;
use lensc_runtime::post::Provenance;

/// Wall and CPU time (s) of one run.
#[derive(Clone, Copy)]
struct Times {
    wall: f64,
    cpu: f64,
}

impl Times {
    fn min(self, o: Times) -> Times {
        Times {
            wall: self.wall.min(o.wall),
            cpu: self.cpu.min(o.cpu),
        }
    }
    fn plus(self, o: Times) -> Times {
        Times {
            wall: self.wall + o.wall,
            cpu: self.cpu + o.cpu,
        }
    }
}

fn timed<R>(f: impl FnOnce() -> R) -> (Times, R) {
    let (t, c) = (Instant::now(), timing::cpu_seconds());
    let r = f();
    let times = Times {
        wall: t.elapsed().as_secs_f64(),
        cpu: timing::cpu_seconds() - c,
    };
    (times, r)
}

fn runs() -> usize {
    std::env::var("PIPELINE_RUNS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(2)
}

/// The example checked, and its one job lowered as a build lowers it.
fn lowered(example: &str) -> (Checked, JobSpec) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let c = lensc_build::driver::check_path(&lensc_lang::loader::RealFs, &root.join(example))
        .expect("example");
    assert!(!c.has_errors(), "{example} checks");
    let (spec, _) = lensc_build::pipeline::lower(&c.checked.jobs[0], None, &Limits::default())
        .unwrap_or_else(|_| panic!("{example} lowers"));
    (c, spec)
}

fn provenance() -> Provenance {
    Provenance {
        source: "bench.lens".into(),
        source_hash: 0,
        lensc_version: "bench".into(),
    }
}

/// `lensc build` of the example's job (lowered to `spec`) into `dir`:
/// built (spooled there, read back as it is spooled), the program put in
/// place, then removed. Returns its size (bytes).
fn build(c: &Checked, spec: &JobSpec, dir: &Path) -> u64 {
    let job = &c.checked.jobs[0];
    let built = lensc_build::pipeline::build_and_read_back(
        job,
        spec,
        &provenance(),
        Destination::Spool(dir),
    )
    .unwrap_or_else(|_| panic!("builds and reads back"));
    let bytes = built.program.bytes();
    let path = dir.join(&built.program_name);
    built.program.write_to(&path).expect("program written");
    std::fs::remove_file(&path).expect("program removed");
    bytes
}

/// `lensc report` of one lowered job: planned and simulated, no program
/// formatted, the plots drawn (not written).
fn report(spec: &JobSpec) -> usize {
    let built = lensc_build::pipeline::build(spec, &provenance(), Destination::Nowhere)
        .unwrap_or_else(|_| panic!("builds"));
    let svgs = lensc_build::plots::render("bench", &built.plots).expect("plots");
    svgs.iter().map(|(_, s)| s.len()).sum()
}

/// Seed 003's planning alone: the spiral's points counted.
fn plan_spiral(spec: &JobSpec) -> usize {
    let JobSpec::Spiral(s) = spec else {
        panic!("a spiral")
    };
    let prepared = lensc_build::strategy::spiral::Prepared::of(s);
    let mut n = 0;
    prepared
        .planner()
        .plan(&s.fast_axis, |p| n += p.len())
        .expect("plans");
    n
}

/// Seed 002's planning alone; with `keep`, the points as printed, pass by
/// pass (for the simulation alone).
fn plan_roller(spec: &JobSpec, keep: Option<&mut Vec<Vec<[f64; 3]>>>) -> usize {
    let JobSpec::Roller(s) = spec else {
        panic!("a roller")
    };
    let tape = &s.head.surface.lowered.tape;
    let (kernel, _) = lensc_build::evaluate::evaluator(tape);
    // The contact searches on the axial section's kernel, as the builder's.
    let (section, _) = lensc_build::evaluate::evaluator(&tape.axial_section());
    let mut n = 0;
    let resolution = s.head.resolution;
    let printed_at = lensc_runtime::verify::simulate::Printed::new(resolution);
    let printed = |v: f64| printed_at.round(v);
    let mut keep = keep;
    lensc_runtime::plan::roller::plan_roller_helix_sectioned(
        &s.helix,
        s.tool.nose_radius,
        kernel.as_ref(),
        section.as_ref(),
        |pass, pts| {
            n += pts.len();
            if let Some(k) = keep.as_deref_mut() {
                k.resize_with(k.len().max(pass + 1), Vec::new);
                k[pass].extend(pts.iter().map(|q| [q.c, printed(q.z), printed(q.x)]));
            }
        },
    )
    .expect("plans");
    n
}

/// Seed 002's simulation alone, as its builder runs it: every printed
/// point swept over the window's grid, the map finished against the design.
fn simulate_roller(spec: &JobSpec, passes: &[Vec<[f64; 3]>]) -> usize {
    use lensc_build::height_map::{self, RollerFrame, Simulation};
    use lensc_runtime::verify::heightmap::NosePath;
    let JobSpec::Roller(s) = spec else {
        panic!("a roller")
    };
    let (head, helix) = (&s.head, &s.helix);
    let lowered = &head.surface.lowered;
    let (kernel, _) = lensc_build::evaluate::evaluator(&lowered.tape);
    let (design_y, z) = (s.design_y, (helix.z_start, helix.z_end));
    let window = height_map::window(
        head,
        height_map::roller_extent(&lowered.domain, z, design_y),
        height_map::WHOLE_CELLS_NOSE,
        |w| {
            lensc_runtime::verify::window::split(
                &w.roller(helix.roller_radius, helix.y_start),
                None,
            )
        },
    );
    let grid = window.roller(helix.roller_radius, helix.y_start);
    let tiles = lensc_runtime::verify::window::split(&grid, None);
    let mut sweep = Simulation::new(grid, tiles, s.tool.nose_radius);
    for pass in passes {
        sweep.path().lift();
        for &[c, z, x] in pass {
            sweep.path().point(c, z, x);
        }
    }
    let frame = RollerFrame {
        kernel: kernel.as_ref(),
        correction: None,
        window,
        roller_radius: helix.roller_radius,
        y_start: helix.y_start,
        domain: lowered.domain,
        lenslets: None,
    };
    let map = sweep.finish(&frame, &window, window.spacing);
    std::hint::black_box(&map);
    passes.iter().map(Vec::len).sum()
}

fn best<R>(mut f: impl FnMut() -> R) -> (Times, R) {
    let (mut t, r) = timed(&mut f);
    for _ in 1..runs() {
        t = t.min(timed(&mut f).0);
    }
    (t, r)
}

fn line(what: &str, t: Times) {
    println!("  {what:<44} {:>7.2} s wall {:>7.2} s CPU", t.wall, t.cpu);
}

fn ratio(what: &str, a: Times, b: Times, goal: &str) {
    println!(
        "  {what:<44} {:>7.2}× wall {:>7.2}× CPU   (goal {goal})",
        a.wall / b.wall,
        a.cpu / b.cpu
    );
}

fn main() {
    let target = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target");
    let dir = tempfile::tempdir_in(&target).expect("a temporary directory");
    println!(
        "issue #18's pipeline figures, best of {} runs, {} planner threads",
        runs(),
        rayon::current_num_threads()
    );

    let (checked, array) = lowered("examples/hashimoto2025_lens_array.lens");
    println!("seed 003 10 x 10 array");
    let (plan, points) = best(|| plan_spiral(&array));
    let (built, bytes) = best(|| build(&checked, &array, dir.path()));
    println!("  {points} points, {:.0} MB", bytes as f64 / 1e6);
    line("planning alone", plan);
    line("build", built);
    ratio("build / planning", built, plan, "≤ 1.2×");
    drop((checked, array));

    let (checked, roller) = lowered("examples/liu_roller_microlens.lens");
    println!("seed 002 microlens roller");
    let (plan, points) = best(|| plan_roller(&roller, None));
    let mut passes = Vec::new();
    plan_roller(&roller, Some(&mut passes));
    let (sim, _) = best(|| simulate_roller(&roller, &passes));
    drop(passes);
    let (built, bytes) = best(|| build(&checked, &roller, dir.path()));
    let (reported, _) = best(|| report(&roller));
    println!("  {points} points, {:.0} MB", bytes as f64 / 1e6);
    line("planning alone", plan);
    line("simulation alone (points from memory)", sim);
    line("build", built);
    println!(
        "  {:<44} {:>7.2}   (goal ≤ 6 s wall)",
        "build, s", built.wall
    );
    line("report", reported);
    ratio(
        "report / (planning + simulation)",
        reported,
        plan.plus(sim),
        "≤ 1.05×",
    );
    ratio("report / build", reported, built, "< 1");
    println!(
        "  peak resident memory (the simulation's points held in memory): {:.0} MB",
        timing::peak_resident_mb()
    );
}
