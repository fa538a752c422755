//! The conformance suite every surface evaluator (a `SurfaceFn` backend)
//! must pass, written once and instantiated once per backend with
//! `surface_fn_tests!` (as fidget's `float_slice_tests!` is): the
//! interpreter in `ir`, the cranelift JIT in `jit`.
//!
//! Each case builds its tapes directly from the IR `Graph` and holds the
//! backend's six outputs (value, both slopes and the three second
//! derivatives) to what is known of them without it: closed forms worked
//! out by hand, central finite differences of its own values, the bits of
//! `f64::powi`, of steps written out, and of single points (a batch gives
//! what its points give alone, whatever `out` held before) — and, where no
//! closed form is at hand (deep, wide and random tapes, signed zeros, NaN
//! and infinities), to the reference interpreter (`against_reference`, to
//! `TOLERANCE`, or bit for bit). For the interpreter itself those last
//! comparisons are with a second interpreter: they then check only that
//! its outputs do not depend on what `out` held, and the case's other
//! assertions.

use std::marker::PhantomData;

use proptest::prelude::*;

use super::{against_reference, agree};
use crate::surface::ir::{Binary, Graph, Id, Interpreter, SurfaceFn, SurfaceTape, Unary};

/// An evaluator under test: how it is made from a tape. Each backend's
/// own tests implement it and call `surface_fn_tests!`.
pub trait Backend: SurfaceFn + Sync + Sized {
    fn build(tape: &SurfaceTape) -> Self;
}

/// Closed forms and the backend agree to this, relative to the larger of
/// 1 and the values (they sum the same terms in other orders).
const TOL: f64 = 1e-12;

const UNARY: [Unary; 12] = Unary::ALL;

const BINARY: [Binary; 8] = Binary::ALL;

/// A linear form a·x + b·y + c: an argument whose own second derivatives
/// vanish, so the chain rule through it is short.
#[derive(Clone, Copy, Debug)]
struct Lin(f64, f64, f64);

impl Lin {
    fn node(self, g: &mut Graph) -> Id {
        let (x, y) = (g.x(), g.y());
        let (a, b, c) = (
            g.constant_node(self.0),
            g.constant_node(self.1),
            g.constant_node(self.2),
        );
        let ax = g.mul(a, x);
        let by = g.mul(b, y);
        let s = g.add(ax, by);
        g.add(s, c)
    }

    fn at(self, x: f64, y: f64) -> f64 {
        self.0 * x + self.1 * y + self.2
    }
}

/// The coordinate y as a linear form.
const Y: Lin = Lin(0.0, 1.0, 0.0);

/// F(u, v) and its partial derivatives at a point: F, Fu, Fv, Fuu, Fuv, Fvv.
type Partials = [f64; 6];

/// The six outputs of z = F(u(x, y), v(x, y)) for linear u and v.
fn chain(p: Partials, u: Lin, v: Lin) -> [f64; 6] {
    let [f, fu, fv, fuu, fuv, fvv] = p;
    // ∂²z/∂i∂j = Fuu uᵢuⱼ + Fuv (uᵢvⱼ + uⱼvᵢ) + Fvv vᵢvⱼ
    let second = |ui: f64, vi: f64, uj: f64, vj: f64| {
        fuu * ui * uj + fuv * (ui * vj + uj * vi) + fvv * vi * vj
    };
    [
        f,
        fu * u.0 + fv * v.0,
        fu * u.1 + fv * v.1,
        second(u.0, v.0, u.0, v.0),
        second(u.0, v.0, u.1, v.1),
        second(u.1, v.1, u.1, v.1),
    ]
}

/// f(a), f′(a), f″(a) of a function of one argument. The kinks take the
/// IR's side: |a|′ = 1 at a = 0; floor′ = 0.
fn unary_closed_form(op: Unary, a: f64) -> [f64; 3] {
    match op {
        Unary::Neg => [-a, -1.0, 0.0],
        Unary::Sqrt => [a.sqrt(), 0.5 / a.sqrt(), -0.25 / (a * a.sqrt())],
        Unary::Abs => [a.abs(), if a < 0.0 { -1.0 } else { 1.0 }, 0.0],
        Unary::Sin => [a.sin(), a.cos(), -a.sin()],
        Unary::Cos => [a.cos(), -a.sin(), -a.cos()],
        Unary::Tan => {
            let t = a.tan();
            [t, 1.0 + t * t, 2.0 * t * (1.0 + t * t)]
        }
        Unary::Asin | Unary::Acos => {
            let q = 1.0 - a * a;
            let (d1, d2) = (1.0 / q.sqrt(), a / (q * q.sqrt()));
            if op == Unary::Asin {
                [a.asin(), d1, d2]
            } else {
                [a.acos(), -d1, -d2]
            }
        }
        Unary::Atan => {
            let q = 1.0 + a * a;
            [a.atan(), 1.0 / q, -2.0 * a / (q * q)]
        }
        Unary::Exp => [a.exp(), a.exp(), a.exp()],
        Unary::Ln => [a.ln(), 1.0 / a, -1.0 / (a * a)],
        Unary::Floor => [a.floor(), 0.0, 0.0],
    }
}

/// F(a, b) and its partials for each operation of two arguments. Ties of
/// min and max take the IR's side: the derivative of the second operand.
fn binary_closed_form(op: Binary, a: f64, b: f64) -> Partials {
    match op {
        Binary::Add => [a + b, 1.0, 1.0, 0.0, 0.0, 0.0],
        Binary::Sub => [a - b, 1.0, -1.0, 0.0, 0.0, 0.0],
        Binary::Mul => [a * b, b, a, 0.0, 1.0, 0.0],
        Binary::Div => [
            a / b,
            1.0 / b,
            -a / (b * b),
            0.0,
            -1.0 / (b * b),
            2.0 * a / (b * b * b),
        ],
        Binary::Pow => {
            let (p, ln) = (a.powf(b), a.ln());
            [
                p,
                b * a.powf(b - 1.0),
                p * ln,
                b * (b - 1.0) * a.powf(b - 2.0),
                a.powf(b - 1.0) * (1.0 + b * ln),
                p * ln * ln,
            ]
        }
        Binary::Atan2 => {
            let r2 = a * a + b * b;
            let r4 = r2 * r2;
            [
                a.atan2(b),
                b / r2,
                -a / r2,
                -2.0 * a * b / r4,
                (a * a - b * b) / r4,
                2.0 * a * b / r4,
            ]
        }
        Binary::Min if a < b => [a, 1.0, 0.0, 0.0, 0.0, 0.0],
        Binary::Min => [b, 0.0, 1.0, 0.0, 0.0, 0.0],
        Binary::Max if a < b => [b, 0.0, 1.0, 0.0, 0.0, 0.0],
        Binary::Max => [a, 1.0, 0.0, 0.0, 0.0, 0.0],
    }
}

/// A deterministic spread of points over [−2, 2]²: a half-unit grid (zero
/// and exact ties included) and scattered points between.
fn points(n: usize) -> Vec<(f64, f64)> {
    let mut s: u64 = 0x9e37_79b9_7f4a_7c15;
    (0..n)
        .map(|i| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            if i % 3 == 0 {
                let g = (i / 3) as f64;
                (
                    -2.0 + (g % 9.0) * 0.5,
                    -2.0 + ((g / 9.0).floor() % 9.0) * 0.5,
                )
            } else {
                let u = (s >> 11) as f64 / (1u64 << 53) as f64;
                let v = (s.rotate_left(29) >> 11) as f64 / (1u64 << 53) as f64;
                (4.0 * u - 2.0, 4.0 * v - 2.0)
            }
        })
        .collect()
}

/// `points(n)` as the two coordinate arrays a batch takes.
fn xy(n: usize) -> (Vec<f64>, Vec<f64>) {
    points(n).into_iter().unzip()
}

fn tape(build: impl FnOnce(&mut Graph) -> Id) -> SurfaceTape {
    let mut g = Graph::new();
    let z = build(&mut g);
    SurfaceTape::new(g, z)
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    a == b || (a - b).abs() <= tol * 1f64.max(a.abs()).max(b.abs())
}

/// NaN equal to NaN, everything else bit for bit.
fn same_bits(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}

fn finite_count(v: &[f64]) -> usize {
    v.iter().filter(|a| a.is_finite()).count()
}

/// Compares the backend with `want` at every point where the closed form
/// is finite (outside a function's domain the two may differ in which
/// output turns NaN first), and returns how many points were compared.
fn compare<B: Backend>(
    what: &str,
    t: &SurfaceTape,
    pts: &[(f64, f64)],
    want: impl Fn(f64, f64) -> [f64; 6],
) -> usize {
    let f = B::build(t);
    let mut compared = 0;
    for &(x, y) in pts {
        let w = want(x, y);
        if !w.iter().all(|v| v.is_finite()) {
            continue;
        }
        let got = f.eval(x, y);
        for k in 0..6 {
            assert!(
                close(got[k], w[k], TOL),
                "{what}: output {k} at ({x}, {y}): {:e}, closed form {:e}",
                got[k],
                w[k]
            );
        }
        compared += 1;
    }
    compared
}

/// The backend of `t` against the reference interpreter at the points, as
/// one batch (`against_reference`); the reference's outputs.
fn reference<B: Backend>(t: &SurfaceTape, xs: &[f64], ys: &[f64]) -> Vec<f64> {
    against_reference(&Interpreter::new(t), &B::build(t), xs, ys).unwrap_or_else(|e| panic!("{e}"))
}

/// `compare` with the closed form at `pts`, then `reference` there: the
/// reference's outputs.
fn closed_and_reference<B: Backend>(
    what: &str,
    t: &SurfaceTape,
    pts: &[(f64, f64)],
    want: impl Fn(f64, f64) -> [f64; 6],
) -> (usize, Vec<f64>) {
    let n = compare::<B>(what, t, pts, want);
    let (xs, ys): (Vec<f64>, Vec<f64>) = pts.iter().copied().unzip();
    (n, reference::<B>(t, &xs, &ys))
}

/// The reference interpreter's and the backend's outputs at the points,
/// bit for bit (NaN equal to NaN), in batches of the points and of all
/// but the last (odd and even lengths: both lanes and the odd point).
fn bit_identical<B: Backend>(t: &SurfaceTape, xs: &[f64], ys: &[f64], what: &str) {
    let (interp, f) = (Interpreter::new(t), B::build(t));
    for n in [xs.len(), xs.len() - 1] {
        let mut want = vec![0.0; 6 * n];
        let mut got = vec![0.0; 6 * n];
        interp.eval_batch(&xs[..n], &ys[..n], &mut want);
        f.eval_batch(&xs[..n], &ys[..n], &mut got);
        for (k, (w, j)) in want.iter().zip(&got).enumerate() {
            assert!(
                same_bits(*w, *j),
                "{what}, output {} at ({}, {}): reference {w:e}, backend {j:e}",
                k % 6,
                xs[k / 6],
                ys[k / 6]
            );
        }
    }
}

/// Builds a tape's graph, returning its output.
type TapeFn = fn(&mut Graph) -> Id;

/// The six outputs in closed form at (x, y).
type ClosedForm = fn(f64, f64) -> [f64; 6];

/// The suite, one associated function a test (see `surface_fn_tests!`).
pub struct Conformance<B>(PhantomData<B>);

impl<B: Backend> Conformance<B> {
    /// z = f(u)·y, u = 0.4x + 0.25y + 0.1 spanning [−1.3, 1.3]: inside and
    /// outside the domains of sqrt, ln, asin and acos (where the reference
    /// has NaN, so must the backend).
    pub fn every_unary_op_has_its_closed_form() {
        let u = Lin(0.4, 0.25, 0.1);
        let pts = points(300);
        for op in UNARY {
            let t = tape(|g| {
                let a = u.node(g);
                let f = g.unary(op, a);
                let y = g.y();
                g.mul(f, y)
            });
            let (n, want) = closed_and_reference::<B>(&format!("{op:?}"), &t, &pts, |x, y| {
                // F(u, v) = f(u)·v with v = y
                let [f, d1, d2] = unary_closed_form(op, u.at(x, y));
                chain([f * y, d1 * y, f, d2 * y, d1, 0.0], u, Y)
            });
            assert!(n > pts.len() / 3, "{op:?}: only {n} points compared");
            assert!(
                finite_count(&want) > want.len() / 3,
                "{op:?}: too few finite values for the comparison to mean much"
            );
        }
    }

    /// z = F(a, b) and F(b, a) for two linear forms that cross inside the
    /// window (a < b and a > b both happen).
    pub fn every_binary_op_has_its_closed_form() {
        let (a, b) = (Lin(0.7, -0.3, 0.2), Lin(-0.2, 0.6, 0.9));
        let pts = points(300);
        for op in BINARY {
            for (p, q) in [(a, b), (b, a)] {
                let t = tape(|g| {
                    let (pn, qn) = (p.node(g), q.node(g));
                    g.binary(op, pn, qn)
                });
                let (n, want) = closed_and_reference::<B>(&format!("{op:?}"), &t, &pts, |x, y| {
                    chain(binary_closed_form(op, p.at(x, y), q.at(x, y)), p, q)
                });
                assert!(n > pts.len() / 3, "{op:?}: only {n} points compared");
                assert!(finite_count(&want) > want.len() / 3, "{op:?}");
            }
        }
    }

    /// z = uⁿ for whole n of both signs (the JIT expands them by squaring),
    /// and uⁿ + v⁻ⁿ against the reference.
    pub fn whole_powers_have_their_closed_form() {
        let (u, v) = (Lin(0.5, -0.75, 1.25), Lin(0.1, 0.2, 0.3));
        let pts = points(200);
        let (xs, ys) = xy(200);
        for n in [-9, -4, -3, -2, -1, 2, 3, 4, 5, 8, 13, 16] {
            let t = tape(|g| {
                let a = u.node(g);
                g.powi(a, n)
            });
            let k = compare::<B>(&format!("u^{n}"), &t, &pts, |x, y| {
                let a = u.at(x, y);
                let nf = f64::from(n);
                let (f, d1, d2) = (
                    a.powi(n),
                    nf * a.powi(n - 1),
                    nf * (nf - 1.0) * a.powi(n - 2),
                );
                chain([f, d1, 0.0, d2, 0.0, 0.0], u, Y)
            });
            assert!(k > pts.len() / 2, "u^{n}: only {k} points compared");
            let t = tape(|g| {
                let a = u.node(g);
                let p = g.powi(a, n);
                let b = v.node(g);
                let q = g.powi(b, -n);
                g.add(p, q)
            });
            let want = reference::<B>(&t, &xs, &ys);
            assert!(finite_count(&want) > want.len() / 2, "n = {n}");
        }
    }

    /// a^b with a = x² + 1 > 0 everywhere and a non-integer exponent, varying
    /// (0.3x + 0.7y + 0.5) and constant (1.5).
    pub fn pow_with_positive_base_and_real_exponent() {
        let t = tape(|g| {
            let (x, y) = (g.x(), g.y());
            let x2 = g.powi(x, 2);
            let one = g.constant_node(1.0);
            let a = g.add(x2, one);
            let b = Lin(0.3, 0.7, 0.5).node(g);
            let c = g.binary(Binary::Pow, a, b);
            let yc = g.constant_node(1.5);
            let q = g.binary(Binary::Pow, a, yc);
            let s = g.add(c, q);
            g.mul(s, y)
        });
        let (xs, ys) = xy(500);
        let want = reference::<B>(&t, &xs, &ys);
        assert_eq!(finite_count(&want), want.len());
    }

    /// Whole powers are expanded by repeated squaring in the JIT; that is
    /// only allowed because the bits equal Rust's `f64::powi`, so the bits
    /// are checked, of every output, for exponents up to ±2³¹ and bases
    /// from subnormal to infinite.
    pub fn powi_positive_and_negative_exponents_bit_identical() {
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
            let (interp, f) = (Interpreter::new(&t), B::build(&t));
            let mut want = vec![0.0; 6 * xs.len()];
            let mut got = vec![0.0; 6 * xs.len()];
            interp.eval_batch(&xs, &ys, &mut want);
            f.eval_batch(&xs, &ys, &mut got);
            for (i, &b) in xs.iter().enumerate() {
                let direct = b.powi(n);
                for k in 0..6 {
                    let (w, j) = (want[6 * i + k], got[6 * i + k]);
                    assert!(
                        same_bits(w, j),
                        "x^{n} output {k} at x = {b:e}: reference {w:e}, backend {j:e}"
                    );
                }
                let z = got[6 * i];
                assert!(
                    same_bits(z, direct),
                    "{b:e}^{n}: backend {z:e} vs f64::powi {direct:e}"
                );
            }
        }
    }

    /// The unit hemisphere z = sqrt(1 − x² − y²) inside the disc, 0
    /// outside, by `select`: the sqrt is NaN outside, and neither the value
    /// nor a derivative may show it.
    pub fn select_takes_one_branch_and_hides_the_others_nan() {
        let t = tape(|g| {
            let (x, y) = (g.x(), g.y());
            let x2 = g.powi(x, 2);
            let y2 = g.powi(y, 2);
            let r2 = g.add(x2, y2);
            let one = g.constant_node(1.0);
            let rest = g.sub(one, r2);
            let cap = g.sqrt(rest);
            let zero = g.constant_node(0.0);
            let outside = g.sub(r2, one);
            g.select(outside, cap, zero)
        });
        let pts: Vec<(f64, f64)> = (0..101)
            .map(|i| -2.0 + 0.04 * f64::from(i))
            .map(|x| (x, 0.3 * x))
            .collect();
        let (n, want) = closed_and_reference::<B>("hemisphere", &t, &pts, |x, y| {
            let q = 1.0 - x * x - y * y;
            if q <= 0.0 {
                return [0.0; 6];
            }
            let s = q.sqrt();
            let s3 = q * s;
            [
                s,
                -x / s,
                -y / s,
                -(1.0 - y * y) / s3,
                -x * y / s3,
                -(1.0 - x * x) / s3,
            ]
        });
        assert_eq!(n, pts.len(), "every closed form here is finite");
        assert!(want.chunks(6).any(|o| o[0] > 0.5) && want.chunks(6).any(|o| o[0] == 0.0));
    }

    /// u = x − p·floor(x/p), the position inside a cell of pitch p, times
    /// y: floor's derivative is zero, so ∂u/∂x = 1 in every cell.
    pub fn floor_makes_cell_coordinates() {
        let p = 0.35;
        let t = tape(|g| {
            let x = g.x();
            let inv = g.constant_node(1.0 / p);
            let q = g.mul(x, inv);
            let f = g.floor(q);
            let pn = g.constant_node(p);
            let c = g.mul(pn, f);
            let u = g.sub(x, c);
            let y = g.y();
            g.mul(u, y)
        });
        let pts = points(500);
        let (n, _) = closed_and_reference::<B>("cell", &t, &pts, |x, y| {
            let u = x - p * (x * (1.0 / p)).floor();
            [u * y, y, u, 0.0, 1.0, 0.0]
        });
        assert_eq!(n, pts.len());
    }

    /// Outputs that are a constant, a bare coordinate (no operation) or
    /// one product.
    pub fn constant_and_coordinate_outputs() {
        let pts = points(50);
        let cases: [(&str, TapeFn, ClosedForm); 4] = [
            (
                "constant",
                |g| g.constant_node(3.5),
                |_, _| [3.5, 0.0, 0.0, 0.0, 0.0, 0.0],
            ),
            ("x", |g| g.x(), |x, _| [x, 1.0, 0.0, 0.0, 0.0, 0.0]),
            ("y", |g| g.y(), |_, y| [y, 0.0, 1.0, 0.0, 0.0, 0.0]),
            (
                "xy",
                |g| {
                    let (x, y) = (g.x(), g.y());
                    g.mul(x, y)
                },
                |x, y| [x * y, y, x, 0.0, 1.0, 0.0],
            ),
        ];
        for (what, build, want) in cases {
            let (n, _) = closed_and_reference::<B>(what, &tape(build), &pts, want);
            assert_eq!(n, pts.len(), "{what}");
        }
    }

    /// Batches of 0, 1, 2, 3, 7, 17 and 1000 points, each a window of a
    /// longer buffer, give bit for bit what the points give one at a time,
    /// whatever the window held before, write nothing outside it, and agree
    /// with the reference: for a sum of every other operation, the conic
    /// asphere and the sinusoidal freeform.
    pub fn batches_of_every_length_agree_with_single_points() {
        let tapes: [TapeFn; 3] = [every_other_operation, conic_asphere, sinusoidal_freeform];
        for build in tapes {
            let t = tape(build);
            let f = B::build(&t);
            for n in [0, 1, 2, 3, 7, 17, 1000] {
                let (xs, ys) = xy(n);
                for before in [f64::from_bits(0x7ff4_dead_beef_0001), -12345.678] {
                    let mut buf = vec![7.5; 6 * n + 12];
                    buf[6..6 + 6 * n].fill(before);
                    f.eval_batch(&xs, &ys, &mut buf[6..6 + 6 * n]);
                    assert!(
                        buf[..6].iter().chain(&buf[6 + 6 * n..]).all(|&v| v == 7.5),
                        "a batch of {n} wrote outside its window"
                    );
                    for i in 0..n {
                        let one = f.eval(xs[i], ys[i]);
                        for k in 0..6 {
                            let in_batch = buf[6 + 6 * i + k];
                            assert!(
                                same_bits(one[k], in_batch),
                                "batch of {n}, point {i}, output {k}: {:e} alone, {in_batch:e} in the batch over {before:e}",
                                one[k],
                            );
                        }
                    }
                }
                reference::<B>(&t, &xs, &ys);
            }
        }
    }

    /// Steps come from the derivatives of abs, min and max; exact ties
    /// (x = y, arguments exactly zero) are where step(0) = 0 matters.
    pub fn step_through_abs_min_max_derivatives() {
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
        let want = reference::<B>(&t, &xs, &ys);
        assert_eq!(finite_count(&want), want.len());
        // The step must switch somewhere, or this case would not test it:
        // d/dx of |x − y|·x differs in sign across the diagonal.
        let dzdx: Vec<f64> = want.chunks(6).map(|o| o[1]).collect();
        assert!(dzdx.iter().any(|&v| v > 0.0) && dzdx.iter().any(|&v| v < 0.0));
    }

    /// min/max: the non-NaN operand wins and ties give the first operand;
    /// the sign of a zero result shows through a division.
    pub fn min_max_signed_zero_and_nan_bit_identical() {
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
                let (interp, f) = (Interpreter::new(&t), B::build(&t));
                let mut want = vec![0.0; 6 * xs.len()];
                let mut got = vec![0.0; 6 * xs.len()];
                interp.eval_batch(&xs, &ys, &mut want);
                f.eval_batch(&xs, &ys, &mut got);
                for (k, (w, j)) in want.iter().zip(&got).enumerate() {
                    assert!(
                        same_bits(*w, *j),
                        "{op:?} swap={swap} value {k}: reference {w:e}, backend {j:e}"
                    );
                }
                assert!(want.iter().any(|v| v.is_infinite()), "±0 reached 1/m");
            }
        }
    }

    /// min/max with a constant operand on either side (the JIT's shorter
    /// forms): zeros of both signs, NaN, ties with the constant and
    /// infinities give the reference's bits.
    pub fn min_max_with_a_constant_bit_identical() {
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
                        // Operands are ordered by node: the constant made
                        // first is the left one.
                        let k = constant_first.then(|| g.constant_node(c));
                        let (x, y) = (g.x(), g.y());
                        let k = k.unwrap_or_else(|| g.constant_node(c));
                        let m = g.binary(op, x, k);
                        // The sign of a zero shows in 1/m; y keeps a second
                        // lane busy with something else.
                        let one = g.constant_node(1.0);
                        let inv = g.div(one, m);
                        let my = g.mul(m, y);
                        g.add(inv, my)
                    });
                    let mut xs = vec![0.0, -0.0, 1.5, -1.5, -2.0, 2.0, 3.0, -3.0];
                    xs.extend([f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e-300, -1e-300]);
                    xs.extend([1.5f64.next_up(), 1.5f64.next_down(), (-2f64).next_up()]);
                    let ys: Vec<f64> = (0..xs.len()).map(|i| 0.25 * i as f64 - 1.0).collect();
                    bit_identical::<B>(
                        &t,
                        &xs,
                        &ys,
                        &format!("{op:?}(x, {c}) constant first: {constant_first}"),
                    );
                }
            }
        }
    }

    /// Selects and steps against constant branches (+0, −0, others) and
    /// one condition shared by several selects, bit for bit.
    pub fn selects_with_constant_branches_bit_identical() {
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
                let branch =
                    |g: &mut Graph, k: Option<f64>, v: Id| k.map_or(v, |k| g.constant_node(k));
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
            bit_identical::<B>(
                &t,
                &xs,
                &ys,
                &format!("select(c, {t_const:?}, {f_const:?})"),
            );
        }
    }

    /// A chain 400 operations deep (each step depends on the previous one),
    /// with its first and second derivatives.
    pub fn deep_graph() {
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
        let (xs, ys) = xy(200);
        let want = reference::<B>(&t, &xs, &ys);
        assert_eq!(finite_count(&want), want.len());
    }

    /// 300 independent terms summed: hundreds of values live at once, far
    /// more than registers, so the kernel spills; libm calls clobber every
    /// register.
    pub fn wide_graph() {
        let t = tape(|g| {
            let (x, y) = (g.x(), g.y());
            let mut terms = vec![];
            for i in 0..300 {
                let fi = f64::from(i);
                let a = Lin(0.01 * (fi + 1.0), 0.02 * (fi % 11.0 - 5.0), 0.001 * fi).node(g);
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
            // a balanced sum, so everything is live at once
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
        let (xs, ys) = xy(100);
        let want = reference::<B>(&t, &xs, &ys);
        assert_eq!(finite_count(&want), want.len());
    }

    /// The conic asphere with A4..A16 across a 5 mm radius aperture, vertex
    /// included: z = 0, slope 0 and curvature c at the vertex.
    pub fn conic_asphere_a4_to_a16() {
        let t = tape(conic_asphere);
        let mut xs = vec![0.0];
        let mut ys = vec![0.0];
        for i in 0..2000 {
            let r = 5.0 * f64::from(i) / 2000.0;
            let th = f64::from(i) * 2.399_963; // golden angle
            xs.push(r * th.cos());
            ys.push(r * th.sin());
        }
        let want = reference::<B>(&t, &xs, &ys);
        assert_eq!(finite_count(&want), want.len());
        let vertex = B::build(&t).eval(0.0, 0.0);
        for o in [&want[0..6], &vertex[..]] {
            assert_eq!(&o[0..3], &[0.0, 0.0, 0.0]);
            assert!((o[3] - 1.0 / 22.405).abs() < 1e-15 && o[4] == 0.0);
        }
    }

    /// The sinusoidal freeform over one period in x and y, against the
    /// reference and its closed form.
    pub fn sinusoidal_freeform_matches() {
        let t = tape(sinusoidal_freeform);
        let mut xs = vec![];
        let mut ys = vec![];
        for i in 0..50 {
            for j in 0..50 {
                xs.push(std::f64::consts::TAU * f64::from(i) / 49.0);
                ys.push(18.85 * f64::from(j) / 49.0);
            }
        }
        let want = reference::<B>(&t, &xs, &ys);
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

    /// NaN and infinite coordinates give the reference's outputs.
    pub fn nan_and_infinite_inputs_propagate_alike() {
        let t = tape(conic_asphere);
        let xs = [f64::NAN, f64::INFINITY, 0.0, -f64::INFINITY, 1e200, 30.0];
        let ys = [0.0, 0.0, f64::NAN, 1.0, 1e200, 0.0];
        let want = reference::<B>(&t, &xs, &ys);
        assert!(want.iter().any(|v| v.is_nan()));
    }

    /// One evaluator shared by threads (`Sync`), and many built and dropped
    /// (a JIT kernel's memory freed) along the way.
    pub fn shared_across_threads_and_rebuilt() {
        let t = tape(conic_asphere);
        let f = B::build(&t);
        let (xs, ys) = xy(4000);
        let mut want = vec![0.0; 6 * xs.len()];
        Interpreter::new(&t).eval_batch(&xs, &ys, &mut want);
        std::thread::scope(|s| {
            for part in 0..4 {
                let (f, xs, ys, want) = (&f, &xs, &ys, &want);
                s.spawn(move || {
                    let r = part * 1000..(part + 1) * 1000;
                    let mut got = vec![0.0; 6000];
                    f.eval_batch(&xs[r.clone()], &ys[r.clone()], &mut got);
                    let w = &want[6 * r.start..6 * r.end];
                    assert!(w.iter().zip(&got).all(|(a, b)| agree(*a, *b)));
                });
            }
        });
        for _ in 0..50 {
            let o = B::build(&tape(sinusoidal_freeform)).eval(0.3, 0.4);
            let i = Interpreter::new(&tape(sinusoidal_freeform)).eval(0.3, 0.4);
            assert!(o.iter().zip(&i).all(|(a, b)| agree(*a, *b)));
        }
    }

    /// An `out` that is not six values a point is refused, not written past
    /// (`surface_fn_tests!` expects the panic).
    pub fn wrong_output_length_is_refused() {
        let f = B::build(&tape(sinusoidal_freeform));
        let mut out = vec![0.0; 5];
        f.eval_batch(&[0.0], &[0.0], &mut out);
    }

    /// Random tapes of up to 24 operations of every kind, at up to 39
    /// points, against the reference (its regressions in
    /// `runtime/proptest-regressions/surface/conformance/suite.txt`).
    pub fn random_tapes_match_the_reference() {
        proptest!(
            ProptestConfig { cases: 300, ..ProptestConfig::default() },
            |(
                steps in prop::collection::vec(step_strategy(), 1..25),
                pts in prop::collection::vec((-3.0f64..3.0, -3.0f64..3.0), 0..40),
            )| {
                let t = tape(|g| build_random(g, &steps));
                let (xs, ys): (Vec<f64>, Vec<f64>) = pts.into_iter().unzip();
                let (interp, f) = (Interpreter::new(&t), B::build(&t));
                let mut want = vec![0.0; 6 * xs.len()];
                let mut got = vec![0.0; 6 * xs.len()];
                interp.eval_batch(&xs, &ys, &mut want);
                f.eval_batch(&xs, &ys, &mut got);
                for (k, (a, b)) in want.iter().zip(&got).enumerate() {
                    prop_assert!(
                        agree(*a, *b),
                        "value {} (output {} of point {}): reference {:e}, backend {:e}",
                        k, k % 6, k / 6, a, b
                    );
                }
            }
        );
    }

    /// z = (x² + y²)/8: every output exact to the last bit's neighbour.
    pub fn paraboloid_outputs_are_exact() {
        let t = tape(|g| {
            let (x, y) = (g.x(), g.y());
            let a = g.powi(x, 2);
            let b = g.powi(y, 2);
            let r2 = g.add(a, b);
            let two_r = g.constant_node(8.0);
            g.div(r2, two_r)
        });
        let o = B::build(&t).eval(1.2, -0.4);
        let want = [
            (1.2f64 * 1.2 + 0.4 * 0.4) / 8.0,
            1.2 / 4.0,
            -0.4 / 4.0,
            0.25,
            0.0,
            0.25,
        ];
        for (a, b) in o.iter().zip(want) {
            assert!((a - b).abs() <= 1e-16, "{o:?} vs {want:?}");
        }
    }

    /// d(sin x + tan x)/dx = cos x + 1/cos² x.
    pub fn tan_plus_sin() {
        let t = tape(|g| {
            let x = g.x();
            let tn = g.unary(Unary::Tan, x);
            let s = g.unary(Unary::Sin, x);
            g.add(s, tn)
        });
        let o = B::build(&t).eval(0.3, 0.0);
        let want = 0.3f64.cos() + 1.0 / 0.3f64.cos().powi(2);
        assert!((o[1] - want).abs() < 1e-14, "{} vs {want}", o[1]);
    }

    /// Central differences of the backend's own z and first derivatives,
    /// on two formulas that between them use every operation.
    pub fn derivatives_agree_with_finite_differences() {
        let pts = [(0.3, 0.2), (0.7, -0.4), (-0.5, 0.6)];
        check_against_finite_differences::<B>(&tape(trig_and_exp), &pts);
        check_against_finite_differences::<B>(&tape(every_other_operation), &pts);
    }

    /// A loop (`Graph::repeat`) gives bit for bit what its steps written
    /// out give, in batches of every length (both lanes, the odd point,
    /// and pairs with a lane outside the inline sin, cos and exp in some
    /// step), its derivatives (through the steps written out) too.
    pub fn loops_give_the_bits_of_their_steps_written_out() {
        let same = |a: f64, b: f64| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan());
        // The values alone (six functions of the loop's result, no
        // derivative: the loop is all the tape has), and z with its
        // derivatives (which go through the steps written out).
        let values = |looped: bool, steps: u32| {
            let mut g = Graph::new();
            let z = newton_like(&mut g, steps, looped);
            let x = g.x();
            let zx = g.mul(z, x);
            let s = g.unary(Unary::Sin, z);
            let zz = g.powi(z, 2);
            // A second loop, q ← q/2 + 10⁻³/(1 + e^(100 q)) from q = 4x:
            // e^(100 q) overflows (outside the inline exp) in the first
            // steps where x > 1.77 and not in the last, and where it does,
            // the term is 0.
            let halving = |g: &mut Graph, q: Id| {
                let half = g.constant_node(0.5);
                let h = g.mul(q, half);
                let k = g.constant_node(100.0);
                let a = g.mul(q, k);
                let e = g.unary(Unary::Exp, a);
                let one = g.constant_node(1.0);
                let d = g.add(one, e);
                let small = g.constant_node(1e-3);
                let t = g.div(small, d);
                g.add(h, t)
            };
            let four = g.constant_node(4.0);
            let start = g.mul(x, four);
            let q = if looped {
                let q = g.carried();
                let next = halving(&mut g, q);
                g.repeat(q, start, next, steps)
            } else {
                (0..steps).fold(start, |q, _| halving(&mut g, q))
            };
            SurfaceTape::with_outputs(g, [z, zx, s, zz, q, x])
        };
        let cases = [1, 2, 6].into_iter().flat_map(|steps| {
            [
                (steps, values(true, steps), values(false, steps)),
                (
                    steps,
                    tape(|g| newton_like(g, steps, true)),
                    tape(|g| newton_like(g, steps, false)),
                ),
            ]
        });
        for (k, (steps, looped, written)) in cases.enumerate() {
            assert!(
                k % 2 == 1 || steps == 1 || looped.live_nodes().len() < written.live_nodes().len(),
                "{steps} steps: the loop's body is written once"
            );
            let (l, w) = (B::build(&looped), B::build(&written));
            for n in [1, 2, 7, 100] {
                let (mut xs, ys): (Vec<f64>, Vec<f64>) = points(n).into_iter().unzip();
                // Estimates the inline code does not cover in a later step
                // (exp's overflow, huge sines), and NaN.
                if n == 100 {
                    for (i, x) in [(3, 1e3), (10, 40.0), (11, 1e7), (50, f64::NAN), (51, 1e20)] {
                        xs[i] = x;
                    }
                }
                let (mut a, mut b) = (vec![0.0; 6 * n], vec![0.0; 6 * n]);
                l.eval_batch(&xs, &ys, &mut a);
                w.eval_batch(&xs, &ys, &mut b);
                for i in 0..6 * n {
                    assert!(
                        same(a[i], b[i]),
                        "{steps} steps, batch of {n}, point {}, output {}: {:e} looped, {:e} written out",
                        i / 6,
                        i % 6,
                        a[i],
                        b[i]
                    );
                }
            }
        }
    }

    /// A tape's axial section (`SurfaceTape::axial_section`) gives z,
    /// ∂z/∂x and ∂²z/∂x² bit for bit as the whole tape does, in batches
    /// of every length (both lanes and the odd point), and NaN for the
    /// three outputs along y.
    pub fn axial_sections_keep_the_x_outputs_bit_for_bit() {
        let same = |a: f64, b: f64| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan());
        for build in [trig_and_exp, every_other_operation] {
            let whole = tape(build);
            let (all, section) = (B::build(&whole), B::build(&whole.axial_section()));
            for n in [1, 2, 7, 100] {
                let (xs, ys): (Vec<f64>, Vec<f64>) = points(n).into_iter().unzip();
                let (mut a, mut s) = (vec![0.0; 6 * n], vec![0.0; 6 * n]);
                all.eval_batch(&xs, &ys, &mut a);
                section.eval_batch(&xs, &ys, &mut s);
                for i in 0..n {
                    for k in [0, 1, 3] {
                        assert!(
                            same(a[6 * i + k], s[6 * i + k]),
                            "batch of {n}, point {i}, output {k}: {:e} whole, {:e} in the section",
                            a[6 * i + k],
                            s[6 * i + k]
                        );
                    }
                    for k in [2, 4, 5] {
                        assert!(s[6 * i + k].is_nan(), "output {k} is not computed");
                    }
                }
            }
        }
    }

    /// A tape's height alone (`SurfaceTape::height_only`) and its height
    /// and slopes alone (`SurfaceTape::slopes_only`) give those outputs
    /// bit for bit as the whole tape does, loops included, in batches of
    /// every length (both lanes and the odd point), and NaN for the rest.
    pub fn heights_and_slopes_alone_keep_their_bits() {
        let same = |a: f64, b: f64| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan());
        let looped = tape(|g| newton_like(g, 6, true));
        let tapes = [tape(trig_and_exp), tape(every_other_operation), looped];
        for whole in tapes {
            let all = B::build(&whole);
            for (part, kept) in [(whole.height_only(), 1), (whole.slopes_only(), 3)] {
                assert!(part.live_nodes().len() < whole.live_nodes().len());
                let part = B::build(&part);
                for n in [1, 2, 7, 100] {
                    let (xs, ys): (Vec<f64>, Vec<f64>) = points(n).into_iter().unzip();
                    let (mut a, mut h) = (vec![0.0; 6 * n], vec![0.0; 6 * n]);
                    all.eval_batch(&xs, &ys, &mut a);
                    part.eval_batch(&xs, &ys, &mut h);
                    for i in 0..n {
                        for k in 0..kept {
                            assert!(
                                same(a[6 * i + k], h[6 * i + k]),
                                "batch of {n}, point {i}, output {k}: {:e} whole, {:e} alone",
                                a[6 * i + k],
                                h[6 * i + k]
                            );
                        }
                        for k in kept..6 {
                            assert!(h[6 * i + k].is_nan(), "output {k} is not computed");
                        }
                    }
                }
            }
        }
    }
}

/// One Newton-like step over the estimate `p`, with every kind of
/// operation a kernel inlines (sin, cos, exp, sqrt, a select, min, max,
/// whole powers) and one it calls (atan), reading x and y and values
/// computed outside the loop.
fn newton_like_step(g: &mut Graph, p: Id) -> Id {
    let (x, y) = (g.x(), g.y());
    let xy = g.mul(x, y);
    let s = g.unary(Unary::Sin, p);
    let c = g.unary(Unary::Cos, p);
    let px = g.mul(p, x);
    let e = {
        let q = g.mul(px, xy);
        let tenth = g.constant_node(0.1);
        let small = g.mul(q, tenth);
        g.unary(Unary::Exp, small)
    };
    // A fast wobble whose argument leaves the inline sine's range
    // (2^20 π/2) where |p| > 1.65, as it may in one step and not the next.
    let wobble = {
        let fast = g.constant_node(1e6);
        let a = g.mul(p, fast);
        let w = g.unary(Unary::Sin, a);
        let small = g.constant_node(1e-3);
        g.mul(w, small)
    };
    let f = {
        let a = g.add(s, e);
        let b = g.add(a, wobble);
        g.sub(b, y)
    };
    let slope = {
        let two = g.constant_node(2.0);
        let c2 = g.add(c, two);
        let p2 = g.powi(p, 2);
        let r = g.add(p2, two);
        let root = g.sqrt(r);
        let m = g.binary(Binary::Min, c2, root);
        let half = g.constant_node(0.5);
        g.binary(Binary::Max, m, half)
    };
    let step = g.div(f, slope);
    let damped = {
        let d = g.sub(p, x);
        let a = g.unary(Unary::Atan, step);
        g.select(d, step, a)
    };
    g.sub(p, damped)
}

/// A loop of `newton_like_step` from p = x y, `steps` steps, as a loop
/// (`looped`) or written out; z = the result plus y.
fn newton_like(g: &mut Graph, steps: u32, looped: bool) -> Id {
    let (x, y) = (g.x(), g.y());
    let start = g.mul(x, y);
    let p = if looped {
        let p = g.carried();
        let next = newton_like_step(g, p);
        g.repeat(p, start, next, steps)
    } else {
        (0..steps).fold(start, |p, _| newton_like_step(g, p))
    };
    g.add(p, y)
}

/// z = sin x + cos y + tan x + exp(xy).
fn trig_and_exp(g: &mut Graph) -> Id {
    let (x, y) = (g.x(), g.y());
    let s = g.unary(Unary::Sin, x);
    let c = g.unary(Unary::Cos, y);
    let t = g.unary(Unary::Tan, x);
    let xy = g.mul(x, y);
    let e = g.unary(Unary::Exp, xy);
    let sum = g.add(s, c);
    let sum = g.add(sum, t);
    g.add(sum, e)
}

/// A sum of sqrt, ln, division, atan2, asin, acos, atan, pow, abs, min and
/// max of functions of x and y.
fn every_other_operation(g: &mut Graph) -> Id {
    let (x, y) = (g.x(), g.y());
    let x2 = g.powi(x, 2);
    let y2 = g.powi(y, 2);
    let r2 = g.add(x2, y2);
    let one = g.constant_node(1.0);
    let u = g.add(one, r2);
    let s = g.sqrt(u);
    let l = g.unary(Unary::Ln, u);
    let q = g.div(s, l);
    let at = g.binary(Binary::Atan2, y, x);
    let h = g.constant_node(0.5);
    let xh = g.mul(x, h);
    let asn = g.unary(Unary::Asin, xh);
    let acs = g.unary(Unary::Acos, xh);
    let atn = g.unary(Unary::Atan, y);
    let p = g.binary(Binary::Pow, u, xh);
    let d = g.sub(x, y);
    let ab = g.unary(Unary::Abs, d);
    let mn = g.binary(Binary::Min, x, y);
    let mx = g.binary(Binary::Max, x2, y);
    let mut acc = q;
    for t in [at, asn, acs, atn, p, ab, mn, mx] {
        acc = g.add(acc, t);
    }
    acc
}

/// Each derivative output against central differences (h = 1e-5) of the
/// output it derives from.
fn check_against_finite_differences<B: Backend>(t: &SurfaceTape, pts: &[(f64, f64)]) {
    let f = B::build(t);
    let h = 1e-5;
    for &(x, y) in pts {
        let o = f.eval(x, y);
        let (px, mx) = (f.eval(x + h, y), f.eval(x - h, y));
        let (py, my) = (f.eval(x, y + h), f.eval(x, y - h));
        // (output, the output it derives, along x?, tolerance)
        for (k, of, along_x, tol) in [
            (1, 0, true, 1e-8),
            (2, 0, false, 1e-8),
            (3, 1, true, 1e-7),
            (4, 1, false, 1e-7),
            (5, 2, false, 1e-7),
        ] {
            let (p, m) = if along_x {
                (px[of], mx[of])
            } else {
                (py[of], my[of])
            };
            let fd = (p - m) / (2.0 * h);
            assert!(
                (o[k] - fd).abs() <= tol * (1.0 + o[k].abs()),
                "output {k} at ({x}, {y}): {} vs finite difference {fd}",
                o[k]
            );
        }
    }
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

/// z = 0.02 (sin 5x + cos(10y/3)) − 0.04.
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

macro_rules! surface_fn_test {
    ($(#[$attr:meta])* $name:ident, $backend:ty) => {
        #[test]
        $(#[$attr])*
        fn $name() {
            $crate::surface::conformance::suite::Conformance::<$backend>::$name()
        }
    };
}

/// The whole suite as `#[test]` functions for one backend type.
macro_rules! surface_fn_tests {
    ($backend:ty) => {
        $crate::surface::conformance::surface_fn_tests!(
            $backend;
            every_unary_op_has_its_closed_form,
            every_binary_op_has_its_closed_form,
            whole_powers_have_their_closed_form,
            pow_with_positive_base_and_real_exponent,
            powi_positive_and_negative_exponents_bit_identical,
            select_takes_one_branch_and_hides_the_others_nan,
            floor_makes_cell_coordinates,
            constant_and_coordinate_outputs,
            batches_of_every_length_agree_with_single_points,
            step_through_abs_min_max_derivatives,
            min_max_signed_zero_and_nan_bit_identical,
            min_max_with_a_constant_bit_identical,
            selects_with_constant_branches_bit_identical,
            deep_graph,
            wide_graph,
            conic_asphere_a4_to_a16,
            sinusoidal_freeform_matches,
            nan_and_infinite_inputs_propagate_alike,
            shared_across_threads_and_rebuilt,
            random_tapes_match_the_reference,
            paraboloid_outputs_are_exact,
            tan_plus_sin,
            derivatives_agree_with_finite_differences,
            loops_give_the_bits_of_their_steps_written_out,
            axial_sections_keep_the_x_outputs_bit_for_bit,
            heights_and_slopes_alone_keep_their_bits,
        );
        $crate::surface::conformance::surface_fn_test!(
            #[should_panic(expected = "six values per point")]
            wrong_output_length_is_refused,
            $backend
        );
    };
    ($backend:ty; $($name:ident),* $(,)?) => {
        $($crate::surface::conformance::surface_fn_test!($name, $backend);)*
    };
}

pub(crate) use {surface_fn_test, surface_fn_tests};
