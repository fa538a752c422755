//! Conformance of the cranelift surface JIT (`lensc_runtime::surface::jit`) to the reference
//! interpreter (`lensc_runtime::surface::ir::Interpreter`): every operation, whole
//! powers, steps, deep and wide tapes, realistic surfaces and random tapes
//! must give the same six outputs (to 1e-13 relative, NaN equal to NaN) on
//! batches of every length.

use lensc_runtime::surface::ir::{Binary, Graph, Id, Interpreter, SurfaceFn, SurfaceTape, Unary};
use lensc_runtime::surface::jit::JitSurface;
use proptest::prelude::*;

const TOL: f64 = 1e-13;

const UNARY: [Unary; 12] = Unary::ALL;

const BINARY: [Binary; 8] = Binary::ALL;

/// Agreement: equal (also ±∞ and ±0), both NaN, or within TOL relative.
fn agree(a: f64, b: f64) -> bool {
    a == b || (a.is_nan() && b.is_nan()) || (a - b).abs() <= TOL * 1f64.max(a.abs()).max(b.abs())
}

/// A deterministic spread of points: a grid plus scattered ones, covering
/// both signs, zero, and values outside every inverse trig domain.
fn points(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut xs = Vec::with_capacity(n);
    let mut ys = Vec::with_capacity(n);
    let mut s: u64 = 0x9e37_79b9_7f4a_7c15;
    for i in 0..n {
        // xorshift for the scattered part, a fixed grid for the rest
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        let u = (s >> 11) as f64 / (1u64 << 53) as f64;
        let v = ((s.rotate_left(29)) >> 11) as f64 / (1u64 << 53) as f64;
        if i % 3 == 0 {
            let g = (i / 3) as f64;
            xs.push(-2.0 + (g % 9.0) * 0.5);
            ys.push(-2.0 + ((g / 9.0).floor() % 9.0) * 0.5);
        } else {
            xs.push(4.0 * u - 2.0);
            ys.push(4.0 * v - 2.0);
        }
    }
    (xs, ys)
}

/// Compiles `tape`, runs both backends on the points as one batch, and
/// panics naming the first disagreement. Returns the interpreter's outputs.
fn check_batch(tape: &SurfaceTape, xs: &[f64], ys: &[f64]) -> Vec<f64> {
    let interp = Interpreter::new(tape);
    let jit = JitSurface::compile(tape).expect("tape compiles");
    let n = xs.len();
    let mut want = vec![0.0; 6 * n];
    interp.eval_batch(xs, ys, &mut want);
    // Start from a poison value, so an output the JIT forgets to write fails.
    let mut got = vec![f64::from_bits(0x7ff4_dead_beef_0001); 6 * n];
    let mut poison_check = vec![-12345.678; 6 * n];
    jit.eval_batch(xs, ys, &mut got);
    jit.eval_batch(xs, ys, &mut poison_check);
    for i in 0..n {
        for k in 0..6 {
            let (a, b) = (want[6 * i + k], got[6 * i + k]);
            assert!(
                agree(a, b),
                "output {k} at point {i} ({}, {}): interpreter {a:e} vs JIT {b:e}",
                xs[i],
                ys[i]
            );
            assert!(
                agree(a, poison_check[6 * i + k]),
                "output {k} at point {i} depends on what `out` held before"
            );
        }
    }
    want
}

fn check(tape: &SurfaceTape, n: usize) -> Vec<f64> {
    let (xs, ys) = points(n);
    check_batch(tape, &xs, &ys)
}

fn tape(build: impl FnOnce(&mut Graph) -> Id) -> SurfaceTape {
    let mut g = Graph::new();
    let z = build(&mut g);
    SurfaceTape::new(g, z)
}

/// a·x + b·y + c
fn lin(g: &mut Graph, a: f64, b: f64, c: f64) -> Id {
    let (x, y) = (g.x(), g.y());
    let (a, b, c) = (g.constant_node(a), g.constant_node(b), g.constant_node(c));
    let ax = g.mul(a, x);
    let by = g.mul(b, y);
    let s = g.add(ax, by);
    g.add(s, c)
}

fn finite_count(v: &[f64]) -> usize {
    v.iter().filter(|a| a.is_finite()).count()
}

#[test]
fn every_unary_op_matches() {
    for op in UNARY {
        // The argument spans [-1.3, 1.3] over the points: inside and outside
        // the domains of sqrt, ln, asin and acos.
        let t = tape(|g| {
            let a = lin(g, 0.4, 0.25, 0.1);
            let u = g.unary(op, a);
            // times y so that the mixed derivative is not trivially zero
            let y = g.y();
            g.mul(u, y)
        });
        let want = check(&t, 300);
        assert!(
            finite_count(&want) > want.len() / 3,
            "{op:?}: too few finite values for the comparison to mean much"
        );
    }
}

#[test]
fn every_binary_op_matches() {
    for op in BINARY {
        let t = tape(|g| {
            let a = lin(g, 0.7, -0.3, 0.2);
            let b = lin(g, -0.2, 0.6, 0.9);
            g.binary(op, a, b)
        });
        let want = check(&t, 300);
        assert!(finite_count(&want) > want.len() / 3, "{op:?}");
        // and with the operands swapped (a < b and a > b both happen)
        let t = tape(|g| {
            let a = lin(g, 0.7, -0.3, 0.2);
            let b = lin(g, -0.2, 0.6, 0.9);
            g.binary(op, b, a)
        });
        check(&t, 300);
    }
}

#[test]
fn pow_with_positive_base_and_real_exponent() {
    // a^b with a > 0 everywhere and a non-integer, varying exponent.
    let t = tape(|g| {
        let (x, y) = (g.x(), g.y());
        let x2 = g.powi(x, 2);
        let one = g.constant_node(1.0);
        let a = g.add(x2, one);
        let b = lin(g, 0.3, 0.7, 0.5);
        let c = g.binary(Binary::Pow, a, b);
        let yc = g.constant_node(1.5);
        let q = g.binary(Binary::Pow, a, yc);
        let s = g.add(c, q);
        g.mul(s, y)
    });
    let want = check(&t, 500);
    assert_eq!(finite_count(&want), want.len());
}

/// Whole powers are expanded by repeated squaring in the JIT; that is only
/// allowed because the bits equal Rust's `f64::powi`, so check the bits.
#[test]
fn powi_positive_and_negative_exponents_bit_identical() {
    let mut exps: Vec<i32> = (-70..=70).collect();
    exps.extend([
        127,
        -127,
        255,
        1000,
        -1000,
        65_537,
        i32::MAX,
        // not MIN or MIN + 1: the second derivative would need n − 2
        i32::MIN + 2,
    ]);
    let bases = [
        0.0,
        -0.0,
        1.0,
        -1.0,
        1.000_000_1,
        0.999_999_9,
        -1.1,
        2.5,
        -0.3,
        1e-3,
        1e10,
        -7.25,
        std::f64::consts::PI,
        f64::MIN_POSITIVE,
        5e-324,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ];
    let xs: Vec<f64> = bases.to_vec();
    let ys = vec![0.5; xs.len()];
    for n in exps {
        let t = tape(|g| {
            let x = g.x();
            g.powi(x, n)
        });
        let interp = Interpreter::new(&t);
        let jit = JitSurface::compile(&t).expect("compiles");
        let mut want = vec![0.0; 6 * xs.len()];
        let mut got = vec![0.0; 6 * xs.len()];
        interp.eval_batch(&xs, &ys, &mut want);
        jit.eval_batch(&xs, &ys, &mut got);
        for (i, &b) in xs.iter().enumerate() {
            let direct = b.powi(n);
            for k in 0..6 {
                let (w, j) = (want[6 * i + k], got[6 * i + k]);
                let same_bits = w.to_bits() == j.to_bits() || (w.is_nan() && j.is_nan());
                assert!(
                    same_bits,
                    "x^{n} output {k} at x = {b:e}: {w:e} vs JIT {j:e}"
                );
            }
            let z = got[6 * i];
            assert!(
                z.to_bits() == direct.to_bits() || (z.is_nan() && direct.is_nan()),
                "{b:e}^{n}: JIT {z:e} vs f64::powi {direct:e}"
            );
        }
    }
}

#[test]
fn powi_of_expressions_in_a_surface() {
    for n in [-9, -4, -3, -2, -1, 2, 3, 4, 5, 8, 13, 16] {
        let t = tape(|g| {
            let a = lin(g, 0.5, -0.75, 1.25);
            let p = g.powi(a, n);
            let b = lin(g, 0.1, 0.2, 0.3);
            let q = g.powi(b, -n);
            g.add(p, q)
        });
        let want = check(&t, 200);
        assert!(finite_count(&want) > want.len() / 2, "n = {n}");
    }
}

/// Steps come from the derivatives of abs, min and max; exact ties (x = y,
/// arguments exactly zero) are where step(0) = 0 matters.
#[test]
fn step_through_abs_min_max_derivatives() {
    let t = tape(|g| {
        let (x, y) = (g.x(), g.y());
        let d = g.sub(x, y);
        let ad = g.unary(Unary::Abs, d);
        let a = g.mul(ad, x);
        let x2 = g.powi(x, 2);
        let m = g.binary(Binary::Min, x2, y);
        let sy = g.unary(Unary::Sin, y);
        let xy = g.mul(x, y);
        let mx = g.binary(Binary::Max, xy, sy);
        let s = g.add(a, m);
        let s = g.add(s, mx);
        let mxy = g.mul(s, y);
        g.add(s, mxy)
    });
    let mut xs = vec![];
    let mut ys = vec![];
    for i in -6..=6 {
        for j in -6..=6 {
            xs.push(f64::from(i) * 0.25);
            ys.push(f64::from(j) * 0.25);
        }
    }
    let want = check_batch(&t, &xs, &ys);
    assert_eq!(finite_count(&want), want.len());
    // The step must switch somewhere, or this test would not test it:
    // d/dx of |x − y|·x differs in sign across the diagonal.
    let dzdx: Vec<f64> = want.chunks(6).map(|o| o[1]).collect();
    assert!(dzdx.iter().any(|&v| v > 0.0) && dzdx.iter().any(|&v| v < 0.0));
}

/// min/max: the non-NaN operand wins and ties give the first operand; the
/// sign of a zero result shows through a division.
#[test]
fn min_max_signed_zero_and_nan_bit_identical() {
    for op in [Binary::Min, Binary::Max] {
        for swap in [false, true] {
            let t = tape(|g| {
                let (x, y) = (g.x(), g.y());
                let nx = g.neg(x);
                let sy = g.sqrt(y); // NaN for y < 0
                let (a, b) = if swap { (x, nx) } else { (nx, x) };
                let m = g.binary(op, a, b);
                let one = g.constant_node(1.0);
                let inv = g.div(one, m); // ±∞ at x = ±0
                let (c, d) = if swap { (sy, x) } else { (x, sy) };
                let n = g.binary(op, c, d);
                g.add(inv, n)
            });
            let xs = [0.0, -0.0, 1.0, -1.0, 0.0, -0.0, 2.0, f64::NAN, 0.5];
            let ys = [0.0, 0.0, -1.0, 4.0, -0.0, -3.0, f64::NAN, 1.0, 0.25];
            let interp = Interpreter::new(&t);
            let jit = JitSurface::compile(&t).expect("compiles");
            let mut want = vec![0.0; 6 * xs.len()];
            let mut got = vec![0.0; 6 * xs.len()];
            interp.eval_batch(&xs, &ys, &mut want);
            jit.eval_batch(&xs, &ys, &mut got);
            for (k, (w, j)) in want.iter().zip(&got).enumerate() {
                assert!(
                    w.to_bits() == j.to_bits() || (w.is_nan() && j.is_nan()),
                    "{op:?} swap={swap} value {k}: {w:e} vs JIT {j:e}"
                );
            }
            assert!(want.iter().any(|v| v.is_infinite()), "±0 reached 1/m");
        }
    }
}

/// Interpreter and JIT outputs at the points, bit for bit (NaN equal to
/// NaN), for the one-pass and the two-lane pass alike (odd and even
/// batches).
fn bit_identical(t: &SurfaceTape, xs: &[f64], ys: &[f64], what: &str) {
    let interp = Interpreter::new(t);
    let jit = JitSurface::compile(t).expect("compiles");
    for n in [xs.len(), xs.len() - 1] {
        let mut want = vec![0.0; 6 * n];
        let mut got = vec![0.0; 6 * n];
        interp.eval_batch(&xs[..n], &ys[..n], &mut want);
        jit.eval_batch(&xs[..n], &ys[..n], &mut got);
        for (k, (w, j)) in want.iter().zip(&got).enumerate() {
            assert!(
                w.to_bits() == j.to_bits() || (w.is_nan() && j.is_nan()),
                "{what}, output {} at ({}, {}): {w:e} vs JIT {j:e}",
                k % 6,
                xs[k / 6],
                ys[k / 6]
            );
        }
    }
}

/// min/max with a constant operand on either side (the JIT's shorter
/// forms): zeros of both signs, NaN, ties with the constant and infinities
/// give the interpreter's bits.
#[test]
fn min_max_with_a_constant_bit_identical() {
    let constants = [
        0.0,
        -0.0,
        1.5,
        -2.0,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NAN,
    ];
    for op in [Binary::Min, Binary::Max] {
        for c in constants {
            for constant_first in [false, true] {
                let t = tape(|g| {
                    // Operands are ordered by node: the constant made first
                    // is the left one.
                    let k = constant_first.then(|| g.constant_node(c));
                    let (x, y) = (g.x(), g.y());
                    let k = k.unwrap_or_else(|| g.constant_node(c));
                    let m = g.binary(op, x, k);
                    // The sign of a zero shows in 1/m; y keeps a second lane
                    // busy with something else.
                    let one = g.constant_node(1.0);
                    let inv = g.div(one, m);
                    let my = g.mul(m, y);
                    g.add(inv, my)
                });
                let mut xs = vec![0.0, -0.0, 1.5, -1.5, -2.0, 2.0, 3.0, -3.0];
                xs.extend([f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e-300, -1e-300]);
                xs.extend([1.5f64.next_up(), 1.5f64.next_down(), (-2f64).next_up()]);
                let ys: Vec<f64> = (0..xs.len()).map(|i| 0.25 * i as f64 - 1.0).collect();
                bit_identical(
                    &t,
                    &xs,
                    &ys,
                    &format!("{op:?}(x, {c}) constant first: {constant_first}"),
                );
            }
        }
    }
}

/// Selects and steps against constant branches (+0, −0, others) and one
/// condition shared by several selects, bit for bit.
#[test]
fn selects_with_constant_branches_bit_identical() {
    for (t_const, f_const) in [
        (None, Some(0.0)),
        (Some(0.0), None),
        (None, Some(-0.0)),
        (Some(-0.0), None),
        (Some(2.5), Some(0.0)),
        (None, None),
    ] {
        let t = tape(|g| {
            let (x, y) = (g.x(), g.y());
            let c = g.sub(x, y);
            let sy = g.sqrt(y); // NaN for y < 0, hidden where not selected
            let branch = |g: &mut Graph, k: Option<f64>, v: Id| k.map_or(v, |k| g.constant_node(k));
            let tv = branch(g, t_const, sy);
            let fv = branch(g, f_const, x);
            let a = g.select(c, tv, fv);
            let x2 = g.powi(x, 2);
            let b = g.select(c, x2, fv);
            let s = g.binary(Binary::Max, c, x); // its derivative steps on c
            let ab = g.add(a, b);
            let z = g.add(ab, s);
            let one = g.constant_node(1.0);
            let inv = g.div(one, a); // the sign of a zero selected
            g.add(z, inv)
        });
        let mut xs = vec![0.0, -0.0, 1.0, -1.0, 2.0, 0.5, f64::NAN, 3.0, -3.0];
        let mut ys = vec![0.0, 0.0, 2.0, -4.0, 1.0, 0.5, 1.0, f64::NAN, -1.0];
        xs.extend([0.25, f64::INFINITY, -0.0]);
        ys.extend([0.0, 1.0, -0.0]);
        bit_identical(
            &t,
            &xs,
            &ys,
            &format!("select(c, {t_const:?}, {f_const:?})"),
        );
    }
}

/// A chain 400 operations deep (each step depends on the previous one),
/// with its first and second derivatives.
#[test]
fn deep_graph() {
    let t = tape(|g| {
        let (x, y) = (g.x(), g.y());
        let mut v = g.add(x, y);
        for i in 0..400 {
            let c = g.constant_node(0.5 + f64::from(i % 7) * 0.01);
            v = match i % 5 {
                0 => {
                    let s = g.unary(Unary::Sin, v);
                    g.add(s, x)
                }
                1 => {
                    let m = g.mul(v, c);
                    g.sub(m, y)
                }
                2 => {
                    let a = g.unary(Unary::Atan, v);
                    g.mul(a, y)
                }
                3 => {
                    let p = g.powi(v, 2);
                    let one = g.constant_node(1.0);
                    let d = g.add(p, one);
                    g.div(v, d)
                }
                _ => {
                    let cv = g.unary(Unary::Cos, v);
                    g.add(cv, c)
                }
            };
        }
        v
    });
    assert!(t.live_nodes().len() > 2000, "{}", t.live_nodes().len());
    let want = check(&t, 200);
    assert_eq!(finite_count(&want), want.len());
}

/// 300 independent terms summed: hundreds of values live at once, far more
/// than registers, so the kernel spills; libm calls clobber every register.
#[test]
fn wide_graph() {
    let t = tape(|g| {
        let (x, y) = (g.x(), g.y());
        let mut terms = vec![];
        for i in 0..300 {
            let fi = f64::from(i);
            let a = lin(g, 0.01 * (fi + 1.0), 0.02 * (fi % 11.0 - 5.0), 0.001 * fi);
            let t = match i % 6 {
                0 => g.unary(Unary::Sin, a),
                1 => g.unary(Unary::Exp, a),
                2 => g.powi(a, 3 + (i % 4)),
                3 => {
                    let xy = g.mul(x, y);
                    g.mul(a, xy)
                }
                4 => g.binary(Binary::Atan2, a, y),
                _ => g.unary(Unary::Atan, a),
            };
            terms.push(t);
        }
        // a balanced sum and a product of a few, so everything is live at once
        while terms.len() > 1 {
            let mut next = vec![];
            for pair in terms.chunks(2) {
                next.push(if pair.len() == 2 {
                    g.add(pair[0], pair[1])
                } else {
                    pair[0]
                });
            }
            terms = next;
        }
        terms[0]
    });
    assert!(t.live_nodes().len() > 3000, "{}", t.live_nodes().len());
    let want = check(&t, 100);
    assert_eq!(finite_count(&want), want.len());
}

/// sag = c r²/(1 + sqrt(1 − (1+k) c² r²)) + Σ_{j=4,6..16} A_j (r²)^(j/2),
/// r² = x² + y²: the conic of revolution with even asphere terms.
fn conic_asphere(g: &mut Graph) -> Id {
    let (x, y) = (g.x(), g.y());
    let (c, k) = (1.0 / 22.405, -1.2);
    let a = [
        (4, 1.3e-4),
        (6, -2.5e-6),
        (8, 3.1e-8),
        (10, -4.0e-10),
        (12, 2.2e-12),
        (14, -1.7e-14),
        (16, 5.0e-17),
    ];
    let x2 = g.powi(x, 2);
    let y2 = g.powi(y, 2);
    let r2 = g.add(x2, y2);
    let cc = g.constant_node(c);
    let num = g.mul(cc, r2);
    let kk = g.constant_node((1.0 + k) * c * c);
    let t = g.mul(kk, r2);
    let one = g.constant_node(1.0);
    let u = g.sub(one, t);
    let s = g.sqrt(u);
    let den = g.add(one, s);
    let mut z = g.div(num, den);
    for (j, aj) in a {
        let p = g.powi(r2, j / 2);
        let ca = g.constant_node(aj);
        let term = g.mul(ca, p);
        z = g.add(z, term);
    }
    z
}

#[test]
fn conic_asphere_a4_to_a16() {
    let t = tape(conic_asphere);
    // points across a 5 mm radius aperture, vertex included
    let mut xs = vec![0.0];
    let mut ys = vec![0.0];
    for i in 0..2000 {
        let r = 5.0 * f64::from(i) / 2000.0;
        let th = f64::from(i) * 2.399_963; // golden angle
        xs.push(r * th.cos());
        ys.push(r * th.sin());
    }
    let want = check_batch(&t, &xs, &ys);
    assert_eq!(finite_count(&want), want.len());
    // at the vertex: z = 0, slope 0, curvature c in both directions
    assert_eq!(&want[0..3], &[0.0, 0.0, 0.0]);
    assert!((want[3] - 1.0 / 22.405).abs() < 1e-15 && want[4] == 0.0);
}

/// z = 0.02 (sin 5x + cos(10y/3)) − 0.04 over one period in x and y.
fn sinusoidal_freeform(g: &mut Graph) -> Id {
    let (x, y) = (g.x(), g.y());
    let five = g.constant_node(5.0);
    let fx = g.mul(five, x);
    let s = g.unary(Unary::Sin, fx);
    let ten_thirds = g.constant_node(10.0 / 3.0);
    let fy = g.mul(ten_thirds, y);
    let c = g.unary(Unary::Cos, fy);
    let sum = g.add(s, c);
    let amp = g.constant_node(0.02);
    let a = g.mul(amp, sum);
    let off = g.constant_node(0.04);
    g.sub(a, off)
}

#[test]
fn sinusoidal_freeform_matches() {
    let t = tape(sinusoidal_freeform);
    let mut xs = vec![];
    let mut ys = vec![];
    for i in 0..50 {
        for j in 0..50 {
            xs.push(std::f64::consts::TAU * f64::from(i) / 49.0);
            ys.push(18.85 * f64::from(j) / 49.0);
        }
    }
    let want = check_batch(&t, &xs, &ys);
    assert_eq!(finite_count(&want), want.len());
    // against the closed form, so neither backend is trusted alone
    for (o, (&x, &y)) in want.chunks(6).zip(xs.iter().zip(&ys)) {
        let z = 0.02 * ((5.0 * x).sin() + (10.0 / 3.0 * y).cos()) - 0.04;
        assert!((o[0] - z).abs() < 1e-15);
        assert!((o[1] - 0.1 * (5.0 * x).cos()).abs() < 1e-15);
        assert!((o[3] + 0.5 * (5.0 * x).sin()).abs() < 1e-15);
        assert_eq!(o[4], 0.0);
    }
}

#[test]
fn batch_lengths_0_1_2_3_1000() {
    for build in [conic_asphere as fn(&mut Graph) -> Id, sinusoidal_freeform] {
        let t = tape(build);
        let jit = JitSurface::compile(&t).expect("compiles");
        let interp = Interpreter::new(&t);
        for n in [0, 1, 2, 3, 1000] {
            let (xs, ys) = points(n);
            // the batch is a window of a longer buffer: the kernel must
            // write exactly 6n values and nothing past them
            let mut buf = vec![7.5; 6 * n + 12];
            jit.eval_batch(&xs, &ys, &mut buf[6..6 + 6 * n]);
            assert!(buf[..6].iter().chain(&buf[6 + 6 * n..]).all(|&v| v == 7.5));
            let mut want = vec![0.0; 6 * n];
            interp.eval_batch(&xs, &ys, &mut want);
            for (i, (a, b)) in want.iter().zip(&buf[6..6 + 6 * n]).enumerate() {
                assert!(agree(*a, *b), "n = {n}, value {i}: {a:e} vs {b:e}");
            }
            // one point at a time gives the same as the batch
            for i in 0..n {
                let one = jit.eval(xs[i], ys[i]);
                assert_eq!(&one[..], &buf[6 + 6 * i..12 + 6 * i], "point {i} of {n}");
            }
        }
        check(&t, 1000);
    }
}

/// Outputs that are constants or a bare coordinate (no operation at all).
#[test]
fn constant_and_coordinate_outputs() {
    let cases: [fn(&mut Graph) -> Id; 4] = [
        |g| g.constant_node(3.25),
        |g| g.x(),
        |g| g.y(),
        |g| {
            let (x, y) = (g.x(), g.y());
            g.mul(x, y)
        },
    ];
    for build in cases {
        let t = tape(build);
        let want = check(&t, 50);
        assert_eq!(finite_count(&want), want.len());
    }
}

#[test]
fn nan_and_infinite_inputs_propagate_alike() {
    let t = tape(conic_asphere);
    let xs = [f64::NAN, f64::INFINITY, 0.0, -f64::INFINITY, 1e200, 30.0];
    let ys = [0.0, 0.0, f64::NAN, 1.0, 1e200, 0.0];
    let want = check_batch(&t, &xs, &ys);
    assert!(want.iter().any(|v| v.is_nan()));
}

/// One compiled kernel shared by threads (`JitSurface: Sync`), and many
/// kernels compiled and dropped (their memory freed) along the way.
#[test]
fn shared_across_threads_and_recompiled() {
    let t = tape(conic_asphere);
    let jit = JitSurface::compile(&t).expect("compiles");
    let interp = Interpreter::new(&t);
    let (xs, ys) = points(4000);
    let mut want = vec![0.0; 6 * xs.len()];
    interp.eval_batch(&xs, &ys, &mut want);
    std::thread::scope(|s| {
        for part in 0..4 {
            let (jit, xs, ys, want) = (&jit, &xs, &ys, &want);
            s.spawn(move || {
                let r = part * 1000..(part + 1) * 1000;
                let mut got = vec![0.0; 6000];
                jit.eval_batch(&xs[r.clone()], &ys[r.clone()], &mut got);
                let w = &want[6 * r.start..6 * r.end];
                assert!(w.iter().zip(&got).all(|(a, b)| agree(*a, *b)));
            });
        }
    });
    for _ in 0..50 {
        let f = JitSurface::compile(&tape(sinusoidal_freeform)).expect("compiles");
        let o = f.eval(0.3, 0.4);
        let i = Interpreter::new(&tape(sinusoidal_freeform)).eval(0.3, 0.4);
        assert!(o.iter().zip(&i).all(|(a, b)| agree(*a, *b)));
    }
}

#[test]
#[should_panic(expected = "six values per point")]
fn wrong_output_length_is_refused() {
    let f = JitSurface::compile(&tape(sinusoidal_freeform)).expect("compiles");
    let mut out = vec![0.0; 5];
    f.eval_batch(&[0.0], &[0.0], &mut out);
}

/// One step of a random tape: an operation on earlier values, by index.
#[derive(Clone, Debug)]
enum Step {
    Const(f64),
    Unary(usize, usize),
    Binary(usize, usize, usize),
    PowI(usize, i32),
    Select(usize, usize, usize),
}

fn step_strategy() -> impl Strategy<Value = Step> {
    prop_oneof![
        (-3.0f64..3.0).prop_map(Step::Const),
        (0..UNARY.len(), any::<usize>()).prop_map(|(o, a)| Step::Unary(o, a)),
        (0..BINARY.len(), any::<usize>(), any::<usize>())
            .prop_map(|(o, a, b)| Step::Binary(o, a, b)),
        (any::<usize>(), -6i32..=6).prop_map(|(a, n)| Step::PowI(a, n)),
        (any::<usize>(), any::<usize>(), any::<usize>())
            .prop_map(|(c, a, b)| Step::Select(c, a, b)),
    ]
}

fn build_random(g: &mut Graph, steps: &[Step]) -> Id {
    let mut vals = vec![g.x(), g.y()];
    for s in steps {
        let pick = |i: usize| vals[i % vals.len()];
        let v = match *s {
            Step::Const(c) => g.constant_node(c),
            Step::Unary(o, a) => g.unary(UNARY[o], pick(a)),
            Step::Binary(o, a, b) => g.binary(BINARY[o], pick(a), pick(b)),
            Step::PowI(a, n) => g.powi(pick(a), n),
            Step::Select(c, a, b) => g.select(pick(c), pick(a), pick(b)),
        };
        vals.push(v);
    }
    // the last value plus a few earlier ones, so most steps are live
    let mut z = vals[vals.len() - 1];
    for &v in vals.iter().rev().skip(1).step_by(3).take(4) {
        z = g.add(z, v);
    }
    z
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    #[test]
    fn random_tapes_match_interpreter(
        steps in prop::collection::vec(step_strategy(), 1..25),
        pts in prop::collection::vec((-3.0f64..3.0, -3.0f64..3.0), 0..40),
    ) {
        let t = tape(|g| build_random(g, &steps));
        let xs: Vec<f64> = pts.iter().map(|p| p.0).collect();
        let ys: Vec<f64> = pts.iter().map(|p| p.1).collect();
        let interp = Interpreter::new(&t);
        let jit = JitSurface::compile(&t).expect("compiles");
        let mut want = vec![0.0; 6 * xs.len()];
        let mut got = vec![0.0; 6 * xs.len()];
        interp.eval_batch(&xs, &ys, &mut want);
        jit.eval_batch(&xs, &ys, &mut got);
        for (k, (a, b)) in want.iter().zip(&got).enumerate() {
            prop_assert!(agree(*a, *b), "value {} (output {} of point {}): {:e} vs JIT {:e}", k, k % 6, k / 6, a, b);
        }
    }
}

#[test]
fn select_takes_one_branch_and_hides_the_others_nan() {
    // z = sqrt(1 − x² − y²) inside the unit disc, 0 outside: the sqrt is NaN
    // outside, and neither the value nor a derivative may show it.
    let t = tape(|g| {
        let (x, y) = (g.x(), g.y());
        let x2 = g.powi(x, 2);
        let y2 = g.powi(y, 2);
        let r2 = g.add(x2, y2);
        let one = g.constant_node(1.0);
        let u = g.sub(one, r2);
        let cap = g.sqrt(u);
        let zero = g.constant_node(0.0);
        let c = g.sub(r2, one);
        g.select(c, cap, zero)
    });
    let xs: Vec<f64> = (0..101).map(|i| -2.0 + 0.04 * i as f64).collect();
    let ys: Vec<f64> = xs.iter().map(|x| 0.3 * x).collect();
    let got = check_batch(&t, &xs, &ys);
    assert!(
        got.iter().all(|v| v.is_finite()),
        "a NaN leaked through select"
    );
    assert!(got.chunks(6).any(|o| o[0] > 0.5) && got.chunks(6).any(|o| o[0] == 0.0));
}

#[test]
fn floor_makes_cell_coordinates() {
    // u = x − p·floor(x/p): the position inside a cell of pitch p = 0.35.
    let t = tape(|g| {
        let x = g.x();
        let inv = g.constant_node(1.0 / 0.35);
        let q = g.mul(x, inv);
        let f = g.floor(q);
        let p = g.constant_node(0.35);
        let c = g.mul(p, f);
        let u = g.sub(x, c);
        let y = g.y();
        g.mul(u, y)
    });
    let got = check(&t, 500);
    assert!(got.chunks(6).all(|o| o[1].is_finite()));
}
