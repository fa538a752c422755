//! Surfaces of revolution: sphere, conic and asphere, and Forbes's Q-bfs
//! and Q-con, lowered through their profile f(s) in s = x² + y².

use lensc_runtime::surface::ir::{Graph, Id, SurfaceTape};

use super::{Side, add_power_terms, conic_sag, radius_squared};
use crate::schema::{Conic, FORBES_TOP, Forbes, Surface};

// The Forbes coefficients a surface may state are the ones the runtime's
// polynomials reach.
const _: () = assert!(FORBES_TOP == lensc_runtime::surface::forbes::MAX_ORDER);

/// A sphere, conic or asphere: the conic sag in r² plus the power terms.
pub(super) fn conic_height(g: &mut Graph, p: &Conic, x: Id, y: Id) -> Id {
    let side = Side::from(p.facing);
    let k = p.base.conic;
    let c = side.curvature(p.base.radius);
    let r2 = radius_squared(g, x, y);
    let sag = conic_sag(g, c, k, r2);
    let sag = add_power_terms(g, sag, r2, &p.terms);
    side.apply(g, sag)
}

/// A Forbes Q-bfs or Q-con surface: its radial profile f(s) at s = r².
pub(super) fn forbes_height(g: &mut Graph, radial: Radial, x: Id, y: Id) -> Id {
    let (h, [f0, _, _]) = radial_profile(radial);
    let s = radius_squared(g, x, y);
    g.import(&h, s, s)[f0.0 as usize]
}

/// A surface of revolution lowered through its profile in s = x² + y².
#[derive(Clone, Copy)]
pub(super) enum Radial<'s> {
    /// A sphere, conic or asphere.
    Conic(&'s Conic),
    Qbfs(&'s Forbes),
    Qcon(&'s Forbes),
}

impl<'s> Radial<'s> {
    fn of(s: &'s Surface) -> Option<Radial<'s>> {
        match s {
            Surface::Sphere(p) | Surface::Conic(p) | Surface::Asphere(p) => Some(Radial::Conic(p)),
            Surface::Qbfs(p) => Some(Radial::Qbfs(p)),
            Surface::Qcon(p) => Some(Radial::Qcon(p)),
            _ => None,
        }
    }
}

/// f(s), f'(s) and f''(s) of a surface of revolution, in a scratch graph
/// whose x stands for s = x² + y².
fn radial_profile(radial: Radial) -> (Graph, [Id; 3]) {
    let (base, facing) = match radial {
        Radial::Conic(c) => (c.base, c.facing),
        Radial::Qbfs(f) | Radial::Qcon(f) => (f.base, f.facing),
    };
    let side = Side::from(facing);
    let c = side.curvature(base.radius);
    let k = base.conic;
    // f(s) in a scratch graph whose x stands for s. The conic's own
    // derivatives in s are written in closed form (g = c s/(1 + q),
    // q = sqrt(1 − κ s), κ = (1+k)c²: g' = c/(2q), g'' = cκ/(4q³)); the
    // polynomial's come from the graph's differentiation of its Horner form.
    let mut h = Graph::new();
    let s = h.x();
    let kappa = (1.0 + k) * c * c;
    let q = {
        let kc = h.constant_node(kappa);
        let ks = h.mul(kc, s);
        let one = h.constant_node(1.0);
        let u = h.sub(one, ks);
        h.sqrt(u)
    };
    let g0 = {
        let cc = h.constant_node(c);
        let num = h.mul(cc, s);
        let one = h.constant_node(1.0);
        let den = h.add(one, q);
        h.div(num, den)
    };
    let g1 = {
        let half_c = h.constant_node(c / 2.0);
        h.div(half_c, q)
    };
    let g2 = {
        let ck = h.constant_node(c * kappa / 4.0);
        let q3 = h.powi(q, 3);
        h.div(ck, q3)
    };
    let zero = h.constant_node(0.0);
    let p0 = match radial {
        Radial::Qbfs(f) => qbfs_departure(&mut h, s, c, f),
        Radial::Qcon(f) => qcon_departure(&mut h, s, f),
        Radial::Conic(conic) => add_power_terms(&mut h, zero, s, &conic.terms),
    };
    let p1 = h.derivative(p0, lensc_runtime::surface::ir::Var::X);
    let p2 = h.derivative(p1, lensc_runtime::surface::ir::Var::X);
    let sigma = h.constant_node(side.sigma);
    let mut sum = |a: Id, b: Id| {
        let t = h.add(a, b);
        h.mul(sigma, t)
    };
    let (f0, f1, f2) = (sum(g0, p0), sum(g1, p1), sum(g2, p2));
    (h, [f0, f1, f2])
}

/// Rotationally symmetric surfaces z = f(s), s = x² + y², differentiated
/// through s: f, f' and f'' are built once in s (exactly, by the graph's
/// own differentiation) and combined by the chain rule,
///   z_x = 2x f',  z_xx = 2f' + 4x² f'',  z_xy = 4xy f''  (and in y),
/// which is the tape a careful hand would write, a third the size of
/// differentiating in x and y directly.
pub(super) fn radial_tape(s: &Surface) -> Option<SurfaceTape> {
    let (h, [f0, f1, f2]) = radial_profile(Radial::of(s)?);
    // Compose with s = x² + y².
    let mut g = Graph::new();
    let (x, y) = (g.x(), g.y());
    let s = radius_squared(&mut g, x, y);
    let map = g.import(&h, s, s);
    let (f0, f1, f2) = (map[f0.0 as usize], map[f1.0 as usize], map[f2.0 as usize]);
    let two = g.constant_node(2.0);
    let four = g.constant_node(4.0);
    let tf1 = g.mul(two, f1);
    let ff2 = g.mul(four, f2);
    let zx = g.mul(tf1, x);
    let zy = g.mul(tf1, y);
    let x2 = g.powi(x, 2);
    let y2 = g.powi(y, 2);
    let xy = g.mul(x, y);
    let zxx = {
        let t = g.mul(ff2, x2);
        g.add(tf1, t)
    };
    let zyy = {
        let t = g.mul(ff2, y2);
        g.add(tf1, t)
    };
    let zxy = g.mul(ff2, xy);
    Some(SurfaceTape::with_outputs(g, [f0, zx, zy, zxx, zxy, zyy]))
}

/// Forbes's Q-bfs departure in s = ρ²: u²(1 − u²)/sqrt(1 − c² s) · Σ a_m Q_m(u²),
/// u² = s/ρ_max², the sum evaluated as one Chebyshev series by Clenshaw's
/// recurrence.
fn qbfs_departure(h: &mut Graph, s: Id, c: f64, p: &Forbes) -> Id {
    let (x, series) = forbes_series(h, s, p, lensc_runtime::surface::forbes::qbfs_chebyshev);
    let one = h.constant_node(1.0);
    // u²(1 − u²) / sqrt(1 − c² s)
    let omx = h.sub(one, x);
    let pre = h.mul(x, omx);
    let cc = h.constant_node(c * c);
    let cs = h.mul(cc, s);
    let under = h.sub(one, cs);
    let root = h.sqrt(under);
    let scaled = h.div(pre, root);
    h.mul(scaled, series)
}

/// Forbes's Q-con departure from the conic in s = ρ²: u⁴ Σ a_m Q_m^con(u²),
/// u² = s/ρ_max², with Q_m^con(x) = P_m^(0,4)(2x − 1); the sum evaluated
/// as one Chebyshev series.
fn qcon_departure(h: &mut Graph, s: Id, p: &Forbes) -> Id {
    let (x, series) = forbes_series(h, s, p, lensc_runtime::surface::forbes::qcon_chebyshev);
    let x2 = h.powi(x, 2);
    h.mul(x2, series)
}

/// u² = s/ρ_max² and Σ a_m Q_m(u²) for the coefficients `Q0` … `Q20` of a
/// Forbes surface, `basis(top)` giving each Q_m in the Chebyshev basis:
/// b_k = Σ_m a_m c_mk, the whole sum one Chebyshev series.
fn forbes_series(h: &mut Graph, s: Id, p: &Forbes, basis: fn(usize) -> Vec<Vec<f64>>) -> (Id, Id) {
    let norm = p.norm_radius;
    let coeffs = &p.terms;
    let top = coeffs.iter().map(|t| t.0).max().unwrap_or(0);
    let q = basis(top);
    let mut b = vec![0.0; top + 1];
    for &(m, a) in coeffs {
        for (bk, ck) in b.iter_mut().zip(&q[m]) {
            *bk += a * ck;
        }
    }
    let inv = h.constant_node(1.0 / (norm * norm));
    let x = h.mul(s, inv);
    let series = chebyshev_series(h, x, &b);
    (x, series)
}

/// Σ_k b_k T_k(2x − 1) by Clenshaw's recurrence:
/// y_k = b_k + 2t y_{k+1} − y_{k+2}; the sum is b_0 + t y_1 − y_2.
fn chebyshev_series(h: &mut Graph, x: Id, b: &[f64]) -> Id {
    let two = h.constant_node(2.0);
    let one = h.constant_node(1.0);
    let tx = h.mul(two, x);
    let t = h.sub(tx, one);
    let zero = h.constant_node(0.0);
    let (mut y1, mut y2) = (zero, zero);
    for &bk in b.iter().skip(1).rev() {
        let bk = h.constant_node(bk);
        let tt = h.mul(two, t);
        let a = h.mul(tt, y1);
        let sum = h.add(bk, a);
        let y = h.sub(sum, y2);
        y2 = y1;
        y1 = y;
    }
    let b0 = h.constant_node(b.first().copied().unwrap_or(0.0));
    let ty = h.mul(t, y1);
    let first = h.add(b0, ty);
    h.sub(first, y2)
}

/// z = s · (c r² / (1 + sqrt(1 − (1+k) c² r²)) + Σ A_j (r²)^(j/2)) with
/// c = 1/radius, written in r² = x² + y² so it is smooth through the axis.
pub fn rotational_sag(g: &mut Graph, radius: f64, k: f64, terms: &[(u32, f64)], sign: f64) -> Id {
    let (x, y) = (g.x(), g.y());
    let r2 = radius_squared(g, x, y);
    let sag = conic_sag(g, 1.0 / radius, k, r2);
    let sag = add_power_terms(g, sag, r2, terms);
    let s = g.constant_node(sign);
    g.mul(s, sag)
}
