//! Surface evaluation speed: ns per point for the six outputs (z and its
//! first and second derivatives) of three surfaces — a conic with A4…A16,
//! seed 002's sinusoidal freeform and seed 003's 10 × 10 lens array, each
//! the tape lensc's own lowering builds — four ways, in the same run:
//!   interpreter — `lensc_runtime::surface::ir::Interpreter` over the batch
//!   JIT scalar  — the cranelift kernel called once per point (`eval`)
//!   JIT batch   — the cranelift kernel called once for 10^5 points
//!   hand-written — a Rust function with the derivatives written out by
//!                  hand, `#[inline(never)]`, over the same batch
//! plus the JIT compile time per surface, and of every surface the
//! examples declare.
//!
//! Run: cargo bench -p lensc-build --bench surface_eval
//! A plain harness: best of N runs, ratios from one process; each time is
//! given as wall time (`Instant`) and as the thread's CPU time
//! (`CLOCK_THREAD_CPUTIME_ID`), each the best of its runs: where the two
//! differ much, other load took the core.

use std::hint::black_box;
use std::time::Instant;

use lensc_runtime::surface::ir::{Graph, Interpreter, SurfaceFn, SurfaceTape};
use lensc_runtime::surface::jit::JitSurface;

/// The CPU time this thread has used (s).
fn thread_cpu_seconds() -> f64 {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `t` is a valid, writable timespec.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut t) };
    if rc != 0 {
        return f64::NAN;
    }
    t.tv_sec as f64 + t.tv_nsec as f64 * 1e-9
}

/// A time measured both ways: the best wall time of the runs and the best
/// CPU time (s).
#[derive(Clone, Copy)]
struct Time {
    wall: f64,
    cpu: f64,
}

impl Time {
    fn per(self, n: usize, unit: f64) -> Time {
        Time {
            wall: self.wall * unit / n as f64,
            cpu: self.cpu * unit / n as f64,
        }
    }
}

/// Best of `runs` runs of `f`, wall and CPU time each.
fn best_of(runs: usize, mut f: impl FnMut()) -> Time {
    let mut best = Time {
        wall: f64::INFINITY,
        cpu: f64::INFINITY,
    };
    for _ in 0..runs {
        let (t, c) = (Instant::now(), thread_cpu_seconds());
        f();
        let (w, c) = (t.elapsed().as_secs_f64(), thread_cpu_seconds() - c);
        best.wall = best.wall.min(w);
        best.cpu = best.cpu.min(c);
    }
    best
}

const POINTS: usize = 100_000;
const RUNS: usize = 15;
const COMPILES: usize = 20;

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

/// The tape lensc itself builds for `surface NAME` of `src`.
fn lowered(src: &str, name: &str) -> SurfaceTape {
    let c =
        lensc_build::driver::check_text(&lensc_lang::loader::RealFs, "bench.lens", src.as_bytes());
    assert!(!c.has_errors(), "bench source has errors");
    lensc_build::driver::declared_surface(&c, name)
        .expect("lowers")
        .tape
}

fn asphere_tape() -> SurfaceTape {
    let mut src = format!(
        "surface s = asphere {{ radius: {} mm, conic: {K}, sense: concave, aperture: circle(radius: {APERTURE} mm)",
        1.0 / C
    );
    for (j, aj) in A {
        src += &format!(", A{j}: {aj:e} mm^-{}", j - 1);
    }
    lowered(&(src + " }"), "s")
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
    lowered(
        "surface f = freeform { z(x, y) = 0.02 mm * (sin(5 rad/mm * x) + cos(10 rad/(3 mm) * y)) - 0.04 mm, domain: rect(x: 0 mm .. 6.283185307179586 mm, y: 0 mm .. 18.84955592153876 mm) }",
        "f",
    )
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

// ---- seed 003's 10 × 10 lens array ------------------------------------------

const PITCH: f64 = 3.5;
const LENS_R: f64 = 20.0;
const LENS_A: f64 = 0.85;

fn array_tape() -> SurfaceTape {
    lowered(
        "surface l = sphere { radius: 20 mm, sense: concave, aperture: circle(diameter: 1.7 mm) }
surface a = grid(l, pitch_x: 3.5 mm, pitch_y: 3.5 mm, count_x: 10, count_y: 10)",
        "a",
    )
}

/// The same array by hand: the point's cell, then the concave sphere
/// (its rim on the land at z = 0) inside the lenslet, the land outside.
#[inline(never)]
fn array_by_hand(xs: &[f64], ys: &[f64], out: &mut [f64]) {
    let rim = LENS_A * LENS_A / (LENS_R + (LENS_R * LENS_R - LENS_A * LENS_A).sqrt());
    let centre = |t: f64| (t / PITCH + 5.0).floor().clamp(0.0, 9.0) * PITCH - 4.5 * PITCH;
    for ((&x, &y), o) in xs.iter().zip(ys).zip(out.chunks_exact_mut(6)) {
        let (u, v) = (x - centre(x), y - centre(y));
        let s = u * u + v * v;
        if s < LENS_A * LENS_A {
            // z = R − sqrt(R² − s) − rim, as the sag of a sphere.
            let q = (LENS_R * LENS_R - s).sqrt();
            let f1 = 1.0 / (2.0 * q);
            let f2 = 1.0 / (4.0 * q * q * q);
            o[0] = s / (LENS_R + q) - rim;
            o[1] = 2.0 * u * f1;
            o[2] = 2.0 * v * f1;
            o[3] = 2.0 * f1 + 4.0 * u * u * f2;
            o[4] = 4.0 * u * v * f2;
            o[5] = 2.0 * f1 + 4.0 * v * v * f2;
        } else {
            o.fill(0.0);
        }
    }
}

fn array_points() -> (Vec<f64>, Vec<f64>) {
    let side = (POINTS as f64).sqrt() as usize;
    (0..POINTS)
        .map(|i| {
            let (u, v) = ((i % side) as f64 + 0.31, (i / side) as f64 + 0.47);
            (35.0 * u / side as f64 - 17.5, 35.0 * v / side as f64 - 17.5)
        })
        .unzip()
}

// ---- measurement -----------------------------------------------------------

struct Row {
    name: &'static str,
    interp: Time,
    scalar: Time,
    batch: Time,
    hand: Time,
    compile_us: Time,
    max_rel_dev: f64,
}

type HandFn = fn(&[f64], &[f64], &mut [f64]);

fn measure(name: &'static str, tape: &SurfaceTape, pts: (Vec<f64>, Vec<f64>), hand: HandFn) -> Row {
    let (xs, ys) = pts;
    let n = xs.len();
    let ns = |t: Time| t.per(n, 1e9);

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
        compile_us: compile.per(1, 1e6),
        max_rel_dev,
    }
}

fn main() {
    let asphere = asphere_tape();
    let freeform = freeform_tape();
    let array = array_tape();
    println!(
        "surface_eval: {POINTS} points, six outputs each, best of {RUNS} runs (compile: best of {COMPILES})"
    );
    println!(
        "live tape nodes: asphere {}, freeform {}, lens array {}",
        asphere.live_nodes().len(),
        freeform.live_nodes().len(),
        array.live_nodes().len()
    );
    let rows = [
        measure("conic+A4..A16", &asphere, asphere_points(), asphere_by_hand),
        measure(
            "sin freeform",
            &freeform,
            freeform_points(),
            freeform_by_hand,
        ),
        measure("10x10 array", &array, array_points(), array_by_hand),
    ];
    for (what, get) in [
        ("wall", (|t: Time| t.wall) as fn(Time) -> f64),
        ("CPU", |t: Time| t.cpu),
    ] {
        println!();
        println!(
            "{:<15} {:>12} {:>12} {:>12} {:>12} | {:>10} {:>12} | {:>11}",
            format!("ns/point {what}"),
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
                get(r.interp),
                get(r.scalar),
                get(r.batch),
                get(r.hand),
                get(r.batch) / get(r.hand),
                get(r.interp) / get(r.batch),
                get(r.compile_us)
            );
        }
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
    })
    .per(1, 1e6);
    println!(
        "compile of z = x (fixed cost): {:.1} µs wall, {:.1} µs CPU",
        fixed.wall, fixed.cpu
    );
    every_example_surface();
}

/// The compile time of every surface the examples declare (best of
/// `COMPILES` each), slowest first, and the JIT batch's time per point
/// over a 100 × 100 grid of the surface's domain (points inside it only;
/// best of `RUNS`).
fn every_example_surface() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .expect("examples/ is readable")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "lens"))
        .collect();
    files.sort();
    let mut rows: Vec<(String, usize, Time, Time)> = Vec::new();
    for path in files {
        let Ok(c) = lensc_build::driver::check_path(&lensc_lang::loader::RealFs, &path) else {
            continue;
        };
        let mut names: Vec<&String> = c
            .checked
            .declarations
            .iter()
            .filter(|(_, o)| o.kind.category == lensc_lang::schema::Category::Surface)
            .map(|(n, _)| n)
            .collect();
        names.sort();
        let file = path
            .file_stem()
            .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
        for name in names {
            let Ok(lowered) = lensc_build::driver::declared_surface(&c, name) else {
                continue;
            };
            let tape = lowered.tape;
            let t = best_of(COMPILES, || {
                black_box(JitSurface::compile(black_box(&tape)).expect("compiles"));
            })
            .per(1, 1e6);
            let kernel = JitSurface::compile(&tape).expect("compiles");
            let ((x0, x1), (y0, y1)) = lowered.domain.bounds();
            let (mut xs, mut ys) = (Vec::new(), Vec::new());
            for i in 0..100 {
                for j in 0..100 {
                    let x = x0 + (x1 - x0) * (f64::from(i) + 0.5) / 100.0;
                    let y = y0 + (y1 - y0) * (f64::from(j) + 0.5) / 100.0;
                    if lowered.domain.contains(x, y) {
                        xs.push(x);
                        ys.push(y);
                    }
                }
            }
            let mut out = vec![0.0; 6 * xs.len()];
            let run = best_of(RUNS, || {
                kernel.eval_batch(black_box(&xs), black_box(&ys), &mut out);
                black_box(&out);
            })
            .per(xs.len().max(1), 1e9);
            rows.push((format!("{file}: {name}"), tape.live_nodes().len(), t, run));
        }
    }
    rows.sort_by(|a, b| b.2.cpu.total_cmp(&a.2.cpu));
    println!();
    println!(
        "JIT compile of every surface the examples declare ({} surfaces, best of {COMPILES} each)",
        rows.len()
    );
    println!(
        "{:<50} {:>10} {:>12} {:>12} | {:>12}",
        "surface", "live nodes", "µs wall", "µs CPU", "ns/point CPU"
    );
    for (name, nodes, t, run) in &rows {
        println!(
            "{name:<50} {nodes:>10} {:>12.1} {:>12.1} | {:>12.2}",
            t.wall, t.cpu, run.cpu
        );
    }
}
