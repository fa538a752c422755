//! Surface evaluation speed: ns per point for the six outputs (z and its
//! first and second derivatives) of two surfaces, four ways, measured in
//! the same run:
//!   interpreter — `lensc_runtime::ir::Interpreter` over the batch
//!   JIT scalar  — the cranelift kernel called once per point (`eval`)
//!   JIT batch   — the cranelift kernel called once for 10^5 points
//!   hand-written — a Rust function with the derivatives written out by
//!                  hand, `#[inline(never)]`, over the same batch
//! plus the JIT compile time per surface.
//!
//! Run: cargo bench -p lensc --bench surface_eval
//! A plain harness: best of N runs with `Instant`, ratios from one process.

use std::hint::black_box;
use std::time::{Duration, Instant};

use lensc::jit::JitSurface;
use lensc_runtime::ir::{Graph, Id, Interpreter, SurfaceFn, SurfaceTape, Unary};

const POINTS: usize = 100_000;
const RUNS: usize = 15;
const COMPILES: usize = 20;

/// Best of `runs` timings of `f` (the least disturbed by other load).
fn best_of(runs: usize, mut f: impl FnMut()) -> Duration {
    (0..runs)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed()
        })
        .min()
        .expect("at least one run")
}

// ---- the conic of revolution with A4 … A16 ---------------------------------

const C: f64 = 1.0 / 22.405;
const K: f64 = -1.2;
/// (j, A_j): the term A_j (r²)^(j/2).
const A: [(i32, f64); 7] = [
    (4, 1.3e-4),
    (6, -2.5e-6),
    (8, 3.1e-8),
    (10, -4.0e-10),
    (12, 2.2e-12),
    (14, -1.7e-14),
    (16, 5.0e-17),
];
const APERTURE: f64 = 5.0;

fn asphere_tape() -> SurfaceTape {
    let mut g = Graph::new();
    let (x, y) = (g.x(), g.y());
    let x2 = g.powi(x, 2);
    let y2 = g.powi(y, 2);
    let r2 = g.add(x2, y2);
    let cc = g.constant_node(C);
    let num = g.mul(cc, r2);
    let kk = g.constant_node((1.0 + K) * C * C);
    let t = g.mul(kk, r2);
    let one = g.constant_node(1.0);
    let u = g.sub(one, t);
    let s = g.sqrt(u);
    let den = g.add(one, s);
    let mut z: Id = g.div(num, den);
    for (j, aj) in A {
        let p = g.powi(r2, j / 2);
        let ca = g.constant_node(aj);
        let term = g.mul(ca, p);
        z = g.add(z, term);
    }
    SurfaceTape::new(g, z)
}

/// z = f(s), s = x² + y²: z_x = 2x f', z_xx = 2f' + 4x² f'', z_xy = 4xy f''.
/// Conic part g(s) = c s/(1 + q), q = sqrt(1 − κ s), κ = (1+k)c²:
/// g' = c/(2q), g'' = cκ/(4q³). Polynomial part by Horner in s.
#[inline(never)]
fn asphere_by_hand(xs: &[f64], ys: &[f64], out: &mut [f64]) {
    let kappa = (1.0 + K) * C * C;
    for ((&x, &y), o) in xs.iter().zip(ys).zip(out.chunks_exact_mut(6)) {
        let s = x * x + y * y;
        let q = (1.0 - kappa * s).sqrt();
        let mut f = C * s / (1.0 + q);
        let mut f1 = C / (2.0 * q);
        let mut f2 = C * kappa / (4.0 * q * q * q);
        // Σ A_j s^m, m = j/2 = 2..8, and its first two derivatives in s
        let (mut p, mut p1, mut p2) = (0.0, 0.0, 0.0);
        for &(j, aj) in A.iter().rev() {
            let m = f64::from(j / 2);
            p = p * s + aj;
            p1 = p1 * s + m * aj;
            p2 = p2 * s + m * (m - 1.0) * aj;
        }
        let s2 = s * s;
        f += p * s2; // lowest power is s²
        f1 += p1 * s;
        f2 += p2;
        o[0] = f;
        o[1] = 2.0 * x * f1;
        o[2] = 2.0 * y * f1;
        o[3] = 2.0 * f1 + 4.0 * x * x * f2;
        o[4] = 4.0 * x * y * f2;
        o[5] = 2.0 * f1 + 4.0 * y * y * f2;
    }
}

fn asphere_points() -> (Vec<f64>, Vec<f64>) {
    (0..POINTS)
        .map(|i| {
            let r = APERTURE * ((i as f64 + 0.5) / POINTS as f64).sqrt();
            let th = i as f64 * 2.399_963_229_728_653; // golden angle
            (r * th.cos(), r * th.sin())
        })
        .unzip()
}

// ---- the sinusoidal freeform -----------------------------------------------

fn freeform_tape() -> SurfaceTape {
    let mut g = Graph::new();
    let (x, y) = (g.x(), g.y());
    let five = g.constant_node(5.0);
    let fx = g.mul(five, x);
    let s = g.unary(Unary::Sin, fx);
    let ky = g.constant_node(10.0 / 3.0);
    let fy = g.mul(ky, y);
    let c = g.unary(Unary::Cos, fy);
    let sum = g.add(s, c);
    let amp = g.constant_node(0.02);
    let a = g.mul(amp, sum);
    let off = g.constant_node(0.04);
    let z = g.sub(a, off);
    SurfaceTape::new(g, z)
}

/// z = 0.02 (sin 5x + cos(10y/3)) − 0.04 and its exact derivatives.
#[inline(never)]
fn freeform_by_hand(xs: &[f64], ys: &[f64], out: &mut [f64]) {
    let w = 10.0 / 3.0;
    for ((&x, &y), o) in xs.iter().zip(ys).zip(out.chunks_exact_mut(6)) {
        let (sx, cx) = (5.0 * x).sin_cos();
        let (sy, cy) = (w * y).sin_cos();
        o[0] = 0.02 * (sx + cy) - 0.04;
        o[1] = 0.1 * cx;
        o[2] = -0.02 * w * sy;
        o[3] = -0.5 * sx;
        o[4] = 0.0;
        o[5] = -0.02 * w * w * cy;
    }
}

fn freeform_points() -> (Vec<f64>, Vec<f64>) {
    let side = (POINTS as f64).sqrt() as usize;
    (0..POINTS)
        .map(|i| {
            let (u, v) = ((i % side) as f64, (i / side) as f64);
            (
                std::f64::consts::TAU * u / side as f64,
                18.85 * v / side as f64,
            )
        })
        .unzip()
}

// ---- measurement -----------------------------------------------------------

struct Row {
    name: &'static str,
    interp: f64,
    scalar: f64,
    batch: f64,
    hand: f64,
    compile_us: f64,
    max_rel_dev: f64,
}

type HandFn = fn(&[f64], &[f64], &mut [f64]);

fn measure(name: &'static str, tape: &SurfaceTape, pts: (Vec<f64>, Vec<f64>), hand: HandFn) -> Row {
    let (xs, ys) = pts;
    let n = xs.len();
    let ns = |d: Duration| d.as_secs_f64() * 1e9 / n as f64;

    let compile = best_of(COMPILES, || {
        black_box(JitSurface::compile(black_box(tape)).expect("compiles"));
    });
    let jit = JitSurface::compile(tape).expect("compiles");
    let interp = Interpreter::new(tape);
    let mut out = vec![0.0; 6 * n];

    // The hand-written function must compute the same numbers, or the
    // comparison means nothing.
    let mut want = vec![0.0; 6 * n];
    hand(&xs, &ys, &mut want);
    jit.eval_batch(&xs, &ys, &mut out);
    let max_rel_dev = want
        .iter()
        .zip(&out)
        .map(|(a, b)| (a - b).abs() / a.abs().max(b.abs()).max(1e-3))
        .fold(0.0, f64::max);
    assert!(
        max_rel_dev < 1e-9,
        "{name}: hand-written differs by {max_rel_dev:e}"
    );

    let interp_t = best_of(RUNS, || {
        interp.eval_batch(black_box(&xs), black_box(&ys), black_box(&mut out));
    });
    let scalar_t = best_of(RUNS, || {
        for (i, (&x, &y)) in xs.iter().zip(&ys).enumerate() {
            let o = jit.eval(black_box(x), black_box(y));
            out[6 * i..6 * i + 6].copy_from_slice(&o);
        }
        black_box(&mut out);
    });
    let batch_t = best_of(RUNS, || {
        jit.eval_batch(black_box(&xs), black_box(&ys), black_box(&mut out));
    });
    let hand_t = best_of(RUNS, || {
        hand(black_box(&xs), black_box(&ys), black_box(&mut out));
    });
    Row {
        name,
        interp: ns(interp_t),
        scalar: ns(scalar_t),
        batch: ns(batch_t),
        hand: ns(hand_t),
        compile_us: compile.as_secs_f64() * 1e6,
        max_rel_dev,
    }
}

fn main() {
    let asphere = asphere_tape();
    let freeform = freeform_tape();
    println!(
        "surface_eval: {POINTS} points, six outputs each, best of {RUNS} runs (compile: best of {COMPILES})"
    );
    println!(
        "live tape nodes: asphere {}, freeform {}",
        asphere.live_nodes().len(),
        freeform.live_nodes().len()
    );
    let rows = [
        measure("conic+A4..A16", &asphere, asphere_points(), asphere_by_hand),
        measure(
            "sin freeform",
            &freeform,
            freeform_points(),
            freeform_by_hand,
        ),
    ];
    println!();
    println!(
        "{:<15} {:>12} {:>12} {:>12} {:>12} | {:>10} {:>12} | {:>11}",
        "ns/point",
        "interpreter",
        "JIT scalar",
        "JIT batch",
        "hand-written",
        "JIT/hand",
        "interp/JIT",
        "compile µs"
    );
    for r in &rows {
        println!(
            "{:<15} {:>12.2} {:>12.2} {:>12.2} {:>12.2} | {:>9.2}× {:>11.2}× | {:>11.1}",
            r.name,
            r.interp,
            r.scalar,
            r.batch,
            r.hand,
            r.batch / r.hand,
            r.interp / r.batch,
            r.compile_us
        );
    }
    println!();
    for r in &rows {
        println!(
            "{}: hand-written vs JIT max relative deviation {:.1e}",
            r.name, r.max_rel_dev
        );
    }
    // What every compile costs whatever the tape: module, ISA, mapping.
    let trivial = {
        let mut g = Graph::new();
        let x = g.x();
        SurfaceTape::new(g, x)
    };
    let fixed = best_of(COMPILES, || {
        black_box(JitSurface::compile(black_box(&trivial)).expect("compiles"));
    });
    println!(
        "compile of z = x (fixed cost): {:.1} µs",
        fixed.as_secs_f64() * 1e6
    );
}
