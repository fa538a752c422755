//! Ball-end raster planning speed: µs per tool-centre point of a whole
//! `plan_raster` over a sphere (the tape lensc's own lowering builds, run
//! by the JIT kernel), against a baseline in the same run: the same
//! planner over a hand-written sphere with its derivatives written out.
//! Also the surface evaluations per point and the kernel calls they take
//! (a counting wrapper; the planner asks for a chord's probes in one
//! batch) and the kernel's own ns per evaluation, so the profile reads as
//! calls × cost.
//!
//! Goal (issue #18): ≤ 0.5 µs per point on the JIT kernel. Run:
//!     cargo bench -p lensc-build --bench raster_points

use std::cell::Cell;
use std::hint::black_box;
use std::time::Duration;

use lensc_runtime::plan::raster::{Axis, Raster, RasterTool, plan_raster};
use lensc_runtime::surface::analysis::Domain;
use lensc_runtime::surface::ir::{SurfaceFn, SurfaceTape};
use lensc_runtime::surface::jit::JitSurface;

#[path = "../../../runtime/benches/support/timing.rs"]
mod timing;
use timing::{best_of, best_run, cpu_seconds};

/// The sphere's radius and the aperture's (mm), the ball's radius (mm).
const RADIUS: f64 = 2.0;
const APERTURE: f64 = 1.0;
const BALL: f64 = 0.2;
const RUNS: usize = 5;

/// The tape lensc itself builds for the sphere.
fn sphere_tape() -> SurfaceTape {
    let src = format!(
        "surface s = sphere {{ radius: {RADIUS} mm, sense: convex, aperture: circle(radius: {APERTURE} mm) }}"
    );
    let c =
        lensc_build::driver::check_text(&lensc_lang::loader::RealFs, "bench.lens", src.as_bytes());
    assert!(!c.has_errors(), "bench source has errors");
    lensc_build::driver::declared_surface(&c, "s")
        .expect("lowers")
        .tape
}

/// The convex sphere by hand: z = −s/(1 + q), s = c(x² + y²),
/// q = √(1 − c s), its derivatives written out.
struct SphereByHand;

impl SurfaceFn for SphereByHand {
    fn eval_batch(&self, xs: &[f64], ys: &[f64], out: &mut [f64]) {
        let c = 1.0 / RADIUS;
        for ((&x, &y), o) in xs.iter().zip(ys).zip(out.chunks_exact_mut(6)) {
            let u = 1.0 - c * c * (x * x + y * y);
            let root = u.sqrt();
            let z = -c * (x * x + y * y) / (1.0 + root);
            let g = -c / root;
            let h = -c * c * c / (u * root);
            o.copy_from_slice(&[z, g * x, g * y, g + h * x * x, h * x * y, g + h * y * y]);
        }
    }
}

/// Counts the points a planner asks a surface for, and its calls (a
/// batch of points is one call of the kernel).
struct Counting<'a> {
    inner: &'a dyn SurfaceFn,
    points: Cell<usize>,
    calls: Cell<usize>,
}

impl SurfaceFn for Counting<'_> {
    fn eval_batch(&self, xs: &[f64], ys: &[f64], out: &mut [f64]) {
        self.points.set(self.points.get() + xs.len());
        self.calls.set(self.calls.get() + 1);
        self.inner.eval_batch(xs, ys, out);
    }
}

fn main() {
    let jit = JitSurface::compile(&sphere_tape()).expect("compiles");
    let raster = Raster {
        along: Axis::X,
        zigzag: true,
        stepover: 0.01,
        chord_tolerance: 2e-7,
        max_step: None,
        lin_angle: None,
        retract: 0.5,
        chords: lensc_runtime::plan::chords::ChordPlacement::OnPath,
    };
    let tool = RasterTool::Ball { radius: BALL };
    let aperture = Domain::Circle { radius: APERTURE };
    let plan = |s: &dyn SurfaceFn| plan_raster(&raster, &tool, s, &aperture).expect("plans");
    let (points, same) = {
        let (a, b) = (plan(&jit), plan(&SphereByHand));
        (a.point_count, a.passes == b.passes)
    };
    let counting = Counting {
        inner: &jit,
        points: Cell::new(0),
        calls: Cell::new(0),
    };
    plan(&counting);
    let evals = counting.points.get() as f64 / points as f64;
    let calls = counting.calls.get() as f64 / points as f64;
    // The two alternate, best of RUNS each, so a change in the machine's
    // load falls on both; their CPU time is summed too (time waiting for
    // a core not counted: on a loaded machine the steadier figure).
    let (mut ours, mut base) = (Duration::MAX, Duration::MAX);
    let (mut ours_cpu, mut base_cpu) = (0.0, 0.0);
    for _ in 0..RUNS {
        let c = cpu_seconds();
        ours = ours.min(best_run(1, || black_box(plan(&jit).point_count)).0);
        ours_cpu += cpu_seconds() - c;
        let c = cpu_seconds();
        base = base.min(best_run(1, || black_box(plan(&SphereByHand).point_count)).0);
        base_cpu += cpu_seconds() - c;
    }
    let (xs, ys): (Vec<f64>, Vec<f64>) = (0..100_000)
        .map(|i| {
            let a = i as f64 * 0.001;
            (0.9 * a.cos() * (i % 97) as f64 / 97.0, 0.9 * a.sin())
        })
        .unzip();
    let eval_ns = best_of(RUNS, || {
        for (&x, &y) in xs.iter().zip(&ys) {
            black_box(jit.eval(x, y));
        }
    })
    .as_secs_f64()
        * 1e9
        / xs.len() as f64;
    let per = |d: Duration| d.as_secs_f64() * 1e6 / points as f64;
    println!(
        "ball-end raster, sphere R {RADIUS} mm, ball {BALL} mm, {points} points (same path by hand: {same})"
    );
    println!("  JIT kernel:            {:>8.3} µs/point", per(ours));
    println!("  hand-written sphere:   {:>8.3} µs/point", per(base));
    println!("  ratio:                 {:>8.2}×", per(ours) / per(base));
    let cpu = |s: f64| s * 1e6 / (RUNS * points) as f64;
    println!(
        "  CPU µs/point:          {:>8.3} JIT, {:.3} by hand (CPU time over all runs)",
        cpu(ours_cpu),
        cpu(base_cpu)
    );
    println!("  surface evaluations:   {evals:>8.1} per point, in {calls:.1} kernel calls");
    println!("  one JIT evaluation:    {eval_ns:>8.1} ns");
}
