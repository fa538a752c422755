//! The conformance suite every surface evaluator (a `SurfaceFn` backend)
//! must pass, written once and instantiated once per backend with
//! `surface_fn_tests!` (as fidget's `float_slice_tests!` is): the
//! interpreter in `ir`, the cranelift JIT in `jit`.
//!
//! Each check builds a tape directly from the IR `Graph` and compares the
//! backend's six outputs with closed forms worked out by hand (value, both
//! slopes and the three second derivatives), or with central finite
//! differences of the backend's own values. Backends are also compared
//! with themselves: a batch gives what single points give, whatever `out`
//! held before.

use std::marker::PhantomData;

use super::ir::{Binary, Graph, Id, SurfaceFn, SurfaceTape, Unary};

/// An evaluator under test: how it is made from a tape. Each backend's
/// own tests implement it and call `surface_fn_tests!`.
pub trait Backend: SurfaceFn + Sized {
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

fn tape(build: impl FnOnce(&mut Graph) -> Id) -> SurfaceTape {
    let mut g = Graph::new();
    let z = build(&mut g);
    SurfaceTape::new(g, z)
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    a == b || (a - b).abs() <= tol * 1f64.max(a.abs()).max(b.abs())
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

/// The suite, one associated function a test (see `surface_fn_tests!`).
pub struct Conformance<B>(PhantomData<B>);

impl<B: Backend> Conformance<B> {
    /// z = f(u)·y, u = 0.4x + 0.25y + 0.1 spanning [−1.3, 1.3]: inside and
    /// outside the domains of sqrt, ln, asin and acos.
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
            let n = compare::<B>(&format!("{op:?}"), &t, &pts, |x, y| {
                // F(u, v) = f(u)·v with v = y
                let [f, d1, d2] = unary_closed_form(op, u.at(x, y));
                chain([f * y, d1 * y, f, d2 * y, d1, 0.0], u, Y)
            });
            assert!(n > pts.len() / 3, "{op:?}: only {n} points compared");
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
                let n = compare::<B>(&format!("{op:?}"), &t, &pts, |x, y| {
                    chain(binary_closed_form(op, p.at(x, y), q.at(x, y)), p, q)
                });
                assert!(n > pts.len() / 3, "{op:?}: only {n} points compared");
            }
        }
    }

    /// z = uⁿ for whole n of both signs (the JIT expands them by squaring).
    pub fn whole_powers_have_their_closed_form() {
        let u = Lin(0.5, -0.75, 1.25);
        let pts = points(200);
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
        let n = compare::<B>("hemisphere", &t, &pts, |x, y| {
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
        let pts = points(300);
        let n = compare::<B>("cell", &t, &pts, |x, y| {
            let u = x - p * (x * (1.0 / p)).floor();
            [u * y, y, u, 0.0, 1.0, 0.0]
        });
        assert_eq!(n, pts.len());
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

    /// Outputs that are a constant or a bare coordinate (no operation).
    pub fn constant_and_coordinate_outputs() {
        let pts = points(30);
        let c = tape(|g| g.constant_node(3.5));
        compare::<B>("constant", &c, &pts, |_, _| [3.5, 0.0, 0.0, 0.0, 0.0, 0.0]);
        let x = tape(|g| g.x());
        compare::<B>("x", &x, &pts, |x, _| [x, 1.0, 0.0, 0.0, 0.0, 0.0]);
        let y = tape(|g| g.y());
        compare::<B>("y", &y, &pts, |_, y| [y, 0.0, 1.0, 0.0, 0.0, 0.0]);
    }

    /// Central differences of the backend's own z and first derivatives,
    /// on two formulas that between them use every operation.
    pub fn derivatives_agree_with_finite_differences() {
        let pts = [(0.3, 0.2), (0.7, -0.4), (-0.5, 0.6)];
        check_against_finite_differences::<B>(&tape(trig_and_exp), &pts);
        check_against_finite_differences::<B>(&tape(every_other_operation), &pts);
    }

    /// Batches of 0, 1, 2, 3, 7, 17 and 1000 points give, bit for bit, what
    /// the points give one at a time, whatever `out` held before.
    pub fn batches_of_every_length_agree_with_single_points() {
        let f = B::build(&tape(every_other_operation));
        for n in [0, 1, 2, 3, 7, 17, 1000] {
            let (xs, ys): (Vec<f64>, Vec<f64>) = points(n).into_iter().unzip();
            let mut poisoned = vec![f64::from_bits(0x7ff4_dead_beef_0001); 6 * n];
            let mut filled = vec![-12345.678; 6 * n];
            f.eval_batch(&xs, &ys, &mut poisoned);
            f.eval_batch(&xs, &ys, &mut filled);
            for i in 0..n {
                let one = f.eval(xs[i], ys[i]);
                for k in 0..6 {
                    let same =
                        |a: f64, b: f64| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan());
                    assert!(
                        same(one[k], poisoned[6 * i + k]) && same(one[k], filled[6 * i + k]),
                        "batch of {n}, point {i}, output {k}: {:e} alone, {:e} and {:e} in the batch",
                        one[k],
                        poisoned[6 * i + k],
                        filled[6 * i + k]
                    );
                }
            }
        }
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

macro_rules! surface_fn_test {
    ($name:ident, $backend:ty) => {
        #[test]
        fn $name() {
            $crate::surface::conformance::Conformance::<$backend>::$name()
        }
    };
}

/// The whole suite as `#[test]` functions for one backend type.
macro_rules! surface_fn_tests {
    ($backend:ty) => {
        $crate::surface::conformance::surface_fn_test!(
            every_unary_op_has_its_closed_form,
            $backend
        );
        $crate::surface::conformance::surface_fn_test!(
            every_binary_op_has_its_closed_form,
            $backend
        );
        $crate::surface::conformance::surface_fn_test!(
            whole_powers_have_their_closed_form,
            $backend
        );
        $crate::surface::conformance::surface_fn_test!(
            select_takes_one_branch_and_hides_the_others_nan,
            $backend
        );
        $crate::surface::conformance::surface_fn_test!(floor_makes_cell_coordinates, $backend);
        $crate::surface::conformance::surface_fn_test!(paraboloid_outputs_are_exact, $backend);
        $crate::surface::conformance::surface_fn_test!(tan_plus_sin, $backend);
        $crate::surface::conformance::surface_fn_test!(constant_and_coordinate_outputs, $backend);
        $crate::surface::conformance::surface_fn_test!(
            derivatives_agree_with_finite_differences,
            $backend
        );
        $crate::surface::conformance::surface_fn_test!(
            batches_of_every_length_agree_with_single_points,
            $backend
        );
        $crate::surface::conformance::surface_fn_test!(
            axial_sections_keep_the_x_outputs_bit_for_bit,
            $backend
        );
        $crate::surface::conformance::surface_fn_test!(
            loops_give_the_bits_of_their_steps_written_out,
            $backend
        );
    };
}

pub(crate) use {surface_fn_test, surface_fn_tests};
