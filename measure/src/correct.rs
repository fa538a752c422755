//! The correction a measurement asks of the next cut: the form error,
//! smoothed and carried over the whole aperture as a polynomial, and that
//! polynomial as surface IR, so the corrected surface is evaluated (by
//! the interpreter or the JIT) with exact derivatives like any other.
//!
//! The method, stated once:
//!
//! 1. The registered error along z is averaged in cells (`bin`): rings
//!    about the axis for a turned part, whose cut can only follow the
//!    mean of each ring; squares across a map otherwise. A cell is a
//!    tenth (rings) or a quarter (squares) of the smoothing length wide,
//!    so averaging smooths nothing the fit would keep (the caller,
//!    lensc-build's `compensate`, chooses it).
//! 2. The cells' means are fitted by weighted least squares (each cell
//!    weighted by its points) with Legendre polynomials, orthogonal on
//!    the aperture's span, so the fit stays well conditioned to high
//!    order: radially P_k(2ρ² − 1), ρ = r/R, k = 0..n (the rotationally
//!    symmetric Zernike terms R_2k^0 are these); across a map
//!    P_i(u)·P_j(v), i + j ≤ n, u and v the coordinates scaled to −1..1
//!    over the aperture's bounding box. The order n is the aperture's
//!    width over the smoothing length, rounded up: P_n has n roots
//!    across its span, so no ripple shorter than the smoothing length is
//!    followed (at most `MAX_RADIAL_ORDER` and `MAX_MAP_ORDER`).
//! 3. The fit's piston (and, across a map, its tilts) are dropped: the
//!    registration already removed them, and a shift of the datum is not
//!    form. What is left is the correction; it is defined everywhere on
//!    the aperture, so holes in the measurement and its unmeasured rim
//!    are carried by the same polynomial.

use lensc_runtime::surface::ir::{Graph, Id, Var};

/// The highest radial order fitted (P_12(2ρ² − 1) is of degree 24 in ρ).
/// Measured: the README's condenser (6 mm) measured to r = 2.95 mm and
/// fitted at order 20 swung by 100 nm in the last 50 µm it carries the
/// fit over (the second part gouged there); at order 12 it follows the
/// measured error to 1.4 nm RMS.
pub const MAX_RADIAL_ORDER: usize = 12;
/// The highest total degree fitted across a map (91 terms).
pub const MAX_MAP_ORDER: usize = 12;

/// The basis of a correction, with the frame its coordinates are scaled in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Basis {
    /// P_k(2(r/radius)² − 1), k = 0..=order, r from the axis.
    Radial { radius: f64, order: usize },
    /// P_i(u) P_j(v), i + j ≤ order, u = (x − cx)/hx, v = (y − cy)/hy.
    Map {
        centre: (f64, f64),
        half: (f64, f64),
        order: usize,
    },
}

impl Basis {
    /// The radial basis over a disc of `radius` for a smoothing length.
    pub fn radial(radius: f64, smoothing: f64) -> Basis {
        Basis::Radial {
            radius,
            order: order_for(2.0 * radius, smoothing, MAX_RADIAL_ORDER),
        }
    }

    /// The map basis over the box `x` × `y` (mm) for a smoothing length.
    pub fn map(x: (f64, f64), y: (f64, f64), smoothing: f64) -> Basis {
        let width = (x.1 - x.0).max(y.1 - y.0);
        Basis::Map {
            centre: ((x.0 + x.1) / 2.0, (y.0 + y.1) / 2.0),
            half: ((x.1 - x.0) / 2.0, (y.1 - y.0) / 2.0),
            order: order_for(width, smoothing, MAX_MAP_ORDER),
        }
    }

    pub fn order(&self) -> usize {
        match *self {
            Basis::Radial { order, .. } | Basis::Map { order, .. } => order,
        }
    }

    /// The (i, j) degrees of each term, in the coefficients' order (a
    /// radial term's j is 0).
    pub fn terms(&self) -> Vec<(usize, usize)> {
        match *self {
            Basis::Radial { order, .. } => (0..=order).map(|k| (k, 0)).collect(),
            Basis::Map { order, .. } => {
                let mut t = Vec::new();
                for total in 0..=order {
                    for i in (0..=total).rev() {
                        t.push((i, total - i));
                    }
                }
                t
            }
        }
    }

    /// Whether a term is piston or tilt (left out of the correction).
    fn is_placement(&self, (i, j): (usize, usize)) -> bool {
        match self {
            Basis::Radial { .. } => i == 0,
            Basis::Map { .. } => i + j <= 1,
        }
    }

    /// The basis's coordinates at (x, y): (t, 0) radially, (u, v) across a
    /// map.
    fn coords(&self, x: f64, y: f64) -> (f64, f64) {
        match *self {
            Basis::Radial { radius, .. } => (2.0 * (x * x + y * y) / (radius * radius) - 1.0, 0.0),
            Basis::Map { centre, half, .. } => ((x - centre.0) / half.0, (y - centre.1) / half.1),
        }
    }

    /// Every term's value at (x, y).
    fn values(&self, x: f64, y: f64, out: &mut Vec<f64>) {
        let (u, v) = self.coords(x, y);
        let n = self.order();
        let pu = legendre(u, n);
        let pv = legendre(v, n);
        out.clear();
        out.extend(self.terms().into_iter().map(|(i, j)| pu[i] * pv[j]));
    }

    /// Words for the report.
    pub fn words(&self) -> String {
        match *self {
            Basis::Radial { radius, order } => format!(
                "radial Legendre polynomials P_k(2(r/R)² − 1), k = 0..{order}, R = {radius} mm (the rotationally symmetric Zernike terms)"
            ),
            Basis::Map {
                centre,
                half,
                order,
            } => format!(
                "Legendre products P_i(u)·P_j(v), i + j ≤ {order}, u = (x − {})/{}, v = (y − {})/{} (mm)",
                centre.0, half.0, centre.1, half.1
            ),
        }
    }
}

/// The order whose shortest ripple (`width` / n) is no shorter than
/// `smoothing`, at least 1 and at most `max`.
fn order_for(width: f64, smoothing: f64, max: usize) -> usize {
    let n = (width / smoothing).ceil();
    if n.is_finite() {
        (n as usize).clamp(1, max)
    } else {
        max
    }
}

/// P_0(t) … P_n(t) by Bonnet's recurrence, written as `legendre_nodes`
/// builds it (the same operations in the same order).
fn legendre(t: f64, n: usize) -> Vec<f64> {
    let mut p = Vec::with_capacity(n + 1);
    p.push(1.0);
    if n >= 1 {
        p.push(t);
    }
    for k in 1..n {
        let a = (2 * k + 1) as f64 / (k + 1) as f64;
        let b = k as f64 / (k + 1) as f64;
        p.push(a * (t * p[k]) - b * p[k - 1]);
    }
    p
}

/// Room for P_0 … P_n at the highest order either basis fits.
const ORDERS: usize = 1 + if MAX_RADIAL_ORDER > MAX_MAP_ORDER {
    MAX_RADIAL_ORDER
} else {
    MAX_MAP_ORDER
};

/// P_0(t) … P_n(t) into `p`, by the operations of `legendre`.
fn legendre_into(t: f64, n: usize, p: &mut [f64; ORDERS]) {
    p[0] = 1.0;
    if n >= 1 {
        p[1] = t;
    }
    for k in 1..n {
        let a = (2 * k + 1) as f64 / (k + 1) as f64;
        let b = k as f64 / (k + 1) as f64;
        p[k + 1] = a * (t * p[k]) - b * p[k - 1];
    }
}

/// A fitted correction: its basis and one coefficient per term (mm),
/// placement terms zero.
#[derive(Clone, Debug, PartialEq)]
pub struct Correction {
    pub basis: Basis,
    pub coefficients: Vec<f64>,
    /// RMS of the cells' means about the full fit (mm): what the
    /// polynomial did not follow (ripple shorter than the smoothing
    /// length, noise).
    pub fit_residual_rms: f64,
    /// How many cells held points.
    pub cells: usize,
}

impl Correction {
    /// The correction's height at (x, y) (mm): each term's value times
    /// its coefficient, summed in the terms' order (the same operations as
    /// `Basis::values` and a dot product, without allocating: a
    /// compensated build asks it at every measured point).
    pub fn at(&self, x: f64, y: f64) -> f64 {
        let (u, v) = self.basis.coords(x, y);
        let n = self.basis.order();
        let (mut pu, mut pv) = ([0.0; ORDERS], [0.0; ORDERS]);
        legendre_into(u, n, &mut pu);
        legendre_into(v, n, &mut pv);
        let mut sum = -0.0;
        let mut k = 0;
        for total in 0..=n {
            for i in (0..=total).rev() {
                let j = total - i;
                if j > 0 && matches!(self.basis, Basis::Radial { .. }) {
                    continue;
                }
                sum += pu[i] * pv[j] * self.coefficients[k];
                k += 1;
            }
        }
        sum
    }

    /// The correction as a node of `g` over its coordinates `x`, `y`,
    /// times `scale`: the same polynomial, built by the same recurrence,
    /// so its derivatives are the graph's exact ones.
    pub fn node(&self, g: &mut Graph, x: Id, y: Id, scale: f64) -> Id {
        let n = self.basis.order();
        let (u, v) = match self.basis {
            Basis::Radial { radius, .. } => {
                let x2 = g.mul(x, x);
                let y2 = g.mul(y, y);
                let r2 = g.add(x2, y2);
                let k = g.constant_node(2.0 / (radius * radius));
                let s = g.mul(k, r2);
                let one = g.constant_node(1.0);
                (g.sub(s, one), None)
            }
            Basis::Map { centre, half, .. } => {
                let scaled = |g: &mut Graph, a: Id, c: f64, h: f64| {
                    let c = g.constant_node(c);
                    let d = g.sub(a, c);
                    let h = g.constant_node(1.0 / h);
                    g.mul(d, h)
                };
                let u = scaled(g, x, centre.0, half.0);
                let v = scaled(g, y, centre.1, half.1);
                (u, Some(v))
            }
        };
        let pu = legendre_nodes(g, u, n);
        let mut sum = g.constant_node(0.0);
        let Some(v) = v else {
            for (k, c) in self.coefficients.iter().enumerate() {
                if *c != 0.0 {
                    let c = g.constant_node(c * scale);
                    let t = g.mul(c, pu[k]);
                    sum = g.add(sum, t);
                }
            }
            return sum;
        };
        // Across a map, Σ_i P_i(u) · Σ_j c_ij P_j(v): a product per i, not
        // per term, so the graph's derivatives (product rule per product)
        // stay a few times smaller.
        let pv = legendre_nodes(g, v, n);
        for (i, &p_i) in pu.iter().enumerate() {
            let mut q: Option<Id> = None;
            for (j, &p_j) in pv.iter().enumerate().take(n - i + 1) {
                let d = i + j;
                let c = self.coefficients[d * (d + 1) / 2 + (d - i)];
                if c == 0.0 {
                    continue;
                }
                let c = g.constant_node(c * scale);
                let t = g.mul(c, p_j);
                q = Some(match q {
                    None => t,
                    Some(q) => g.add(q, t),
                });
            }
            if let Some(q) = q {
                let t = g.mul(p_i, q);
                sum = g.add(sum, t);
            }
        }
        sum
    }
}

impl Correction {
    /// The correction times `scale` over the graph's `x`, `y` with its
    /// derivatives, exact: [c, ∂c/∂x, ∂c/∂y, ∂²c/∂x², ∂²c/∂x∂y, ∂²c/∂y²].
    /// Across a map the polynomial is written once as monomials of the
    /// basis's u and v (`monomials`) and summed by Horner's rule, rows
    /// in v inside one column in u, each sum carrying its own first and
    /// second derivatives: a chain of a few live values, where the graph's
    /// derivatives of `node` keep every P_j(v) and its derivatives live
    /// across the sum (a 10th-order map's corrected tape compiled in
    /// 52 ms against the design's 13 ms, measured with
    /// benches/compensate.rs). A radial correction is `node` with the
    /// graph's derivatives.
    pub fn nodes(&self, g: &mut Graph, x: Id, y: Id, scale: f64) -> [Id; 6] {
        let Basis::Map { centre, half, .. } = self.basis else {
            let c = self.node(g, x, y, scale);
            let cx = g.derivative(c, Var::X);
            let cy = g.derivative(c, Var::Y);
            let cxx = g.derivative(cx, Var::X);
            let cxy = g.derivative(cx, Var::Y);
            let cyy = g.derivative(cy, Var::Y);
            return [c, cx, cy, cxx, cxy, cyy];
        };
        let n = self.basis.order();
        let m = self.monomials(scale);
        let scaled = |g: &mut Graph, a: Id, c: f64, h: f64| {
            let c = g.constant_node(c);
            let d = g.sub(a, c);
            let h = g.constant_node(1.0 / h);
            g.mul(d, h)
        };
        let u = scaled(g, x, centre.0, half.0);
        let v = scaled(g, y, centre.1, half.1);
        // acc · t + add, either missing standing for zero.
        fn step(g: &mut Graph, acc: Option<Id>, t: Id, add: Option<Id>) -> Option<Id> {
            let prod = acc.map(|a| g.mul(a, t));
            match (prod, add) {
                (Some(p), Some(a)) => Some(g.add(p, a)),
                (p, a) => p.or(a),
            }
        }
        let twice = |g: &mut Graph, a: Option<Id>| a.map(|a| g.add(a, a));
        // The column in u: S = Σ_a R_a(v) u^a, with S_u, S_uu, S_v, S_vv, S_uv.
        let mut s: [Option<Id>; 6] = [None; 6];
        for a in (0..=n).rev() {
            // The row R_a(v) = Σ_b m_ab v^b, with R_a' and R_a''.
            let (mut r, mut r1, mut r2): (Option<Id>, Option<Id>, Option<Id>) = (None, None, None);
            for b in (0..=n - a).rev() {
                let c = m[a * (n + 1) + b];
                let c = (c != 0.0).then(|| g.constant_node(c));
                let r1x2 = twice(g, r1);
                r2 = step(g, r2, v, r1x2);
                r1 = step(g, r1, v, r);
                r = step(g, r, v, c);
            }
            let [s0, su, suu, sv, svv, suv] = s;
            let sux2 = twice(g, su);
            s = [
                step(g, s0, u, r),
                step(g, su, u, s0),
                step(g, suu, u, sux2),
                step(g, sv, u, r1),
                step(g, svv, u, r2),
                step(g, suv, u, sv),
            ];
        }
        let zero = g.constant_node(0.0);
        let per = |g: &mut Graph, a: Option<Id>, k: f64| match a {
            Some(a) => {
                let k = g.constant_node(k);
                g.mul(a, k)
            }
            None => zero,
        };
        let (hx, hy) = (1.0 / half.0, 1.0 / half.1);
        [
            s[0].unwrap_or(zero),
            per(g, s[1], hx),
            per(g, s[3], hy),
            per(g, s[2], hx * hx),
            per(g, s[5], hx * hy),
            per(g, s[4], hy * hy),
        ]
    }

    /// A map's correction times `scale` as monomials of the basis's u and
    /// v: m_ab at a·(order + 1) + b, the coefficient of u^a v^b (each
    /// Legendre product expanded by the coefficients of P_k's powers,
    /// from Bonnet's recurrence).
    fn monomials(&self, scale: f64) -> Vec<f64> {
        let n = self.basis.order();
        // L[k][a]: the coefficient of t^a in P_k(t).
        let mut l = vec![vec![0.0; n + 1]; n + 1];
        l[0][0] = 1.0;
        if n >= 1 {
            l[1][1] = 1.0;
        }
        for k in 1..n {
            for a in 0..=k + 1 {
                let up = if a > 0 { l[k][a - 1] } else { 0.0 };
                l[k + 1][a] = ((2 * k + 1) as f64 * up - k as f64 * l[k - 1][a]) / (k + 1) as f64;
            }
        }
        let mut m = vec![0.0; (n + 1) * (n + 1)];
        for d in 0..=n {
            for i in (0..=d).rev() {
                let j = d - i;
                let c = self.coefficients[d * (d + 1) / 2 + (d - i)] * scale;
                if c == 0.0 {
                    continue;
                }
                for a in 0..=i {
                    for b in 0..=j {
                        m[a * (n + 1) + b] += c * l[i][a] * l[j][b];
                    }
                }
            }
        }
        m
    }
}

/// The most coefficients a correction along a line has: a radial term
/// P_k(2ρ² − 1) is of degree 2k in the distance along a line.
pub const ALONG_TERMS: usize = 2 * MAX_RADIAL_ORDER + 1;

/// A correction along one line, (x, y) = origin + t · direction: a
/// polynomial in t, Σ_m a_m (t − t0)^m, t0 the line's point nearest the
/// basis's centre (so that the powers stay near the unit over the
/// aperture, and the sum does not cancel). Where a simulation asks the
/// correction at many points of one line (a column of its grid: a ray of
/// a lathe, a row of a raster), each costs a few operations
/// (`Along::at`) instead of the two Legendre recurrences and the sum of
/// every term that `Correction::at` costs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Along {
    t0: f64,
    a: [f64; ALONG_TERMS],
    terms: usize,
}

impl Along {
    /// The correction at t along the line (Horner's rule).
    pub fn at(&self, t: f64) -> f64 {
        let d = t - self.t0;
        let mut v = 0.0;
        for &a in self.a[..self.terms].iter().rev() {
            v = v * d + a;
        }
        v
    }
}

/// A polynomial in the line's parameter, as coefficients of the powers
/// of (t − t0), lowest first; at most `ALONG_TERMS`.
type Poly = [f64; ALONG_TERMS];

/// p · q, its terms beyond `ALONG_TERMS` dropped (none are: every product
/// taken here is of degree at most 2 × `MAX_RADIAL_ORDER`).
fn poly_mul(p: &Poly, q: &Poly, dp: usize, dq: usize) -> Poly {
    let mut r = [0.0; ALONG_TERMS];
    for i in 0..=dp {
        for j in 0..=dq.min(ALONG_TERMS - 1 - i) {
            r[i + j] += p[i] * q[j];
        }
    }
    r
}

/// P_0(s) … P_n(s) for s = `s` a polynomial of degree `ds` in the line's
/// parameter, by Bonnet's recurrence on polynomials.
fn legendre_along(s: &Poly, ds: usize, n: usize) -> Vec<Poly> {
    let mut p = vec![[0.0; ALONG_TERMS]];
    p[0][0] = 1.0;
    if n >= 1 {
        p.push(*s);
    }
    for k in 1..n {
        let a = (2 * k + 1) as f64 / (k + 1) as f64;
        let b = k as f64 / (k + 1) as f64;
        let sp = poly_mul(s, &p[k], ds, ds * k);
        let mut next = [0.0; ALONG_TERMS];
        for m in 0..ALONG_TERMS {
            next[m] = a * sp[m] - b * p[k - 1][m];
        }
        p.push(next);
    }
    p
}

impl Correction {
    /// The correction along the line origin + t · direction (`Along`):
    /// the same polynomial as `at`, its terms composed with the line
    /// (exact but for rounding: it agrees with `at` to about 1e-13 of the
    /// correction's size, tested).
    pub fn along(&self, origin: (f64, f64), direction: (f64, f64)) -> Along {
        let n = self.basis.order();
        let (dx, dy) = direction;
        let len2 = dx * dx + dy * dy;
        let centre = match self.basis {
            Basis::Radial { .. } => (0.0, 0.0),
            Basis::Map { centre, .. } => centre,
        };
        // The parameter of the line's point nearest the centre.
        let t0 = if len2 > 0.0 {
            ((centre.0 - origin.0) * dx + (centre.1 - origin.1) * dy) / len2
        } else {
            0.0
        };
        let (x0, y0) = (origin.0 + t0 * dx, origin.1 + t0 * dy);
        let linear = |c0: f64, c1: f64| {
            let mut p = [0.0; ALONG_TERMS];
            (p[0], p[1]) = (c0, c1);
            p
        };
        let mut a = [0.0; ALONG_TERMS];
        let terms;
        match self.basis {
            Basis::Radial { radius, .. } => {
                // 2ρ² − 1 along the line, ρ² = ((x0 + dx d)² + (y0 + dy d)²)/R².
                let k = 2.0 / (radius * radius);
                let mut s = [0.0; ALONG_TERMS];
                s[0] = k * (x0 * x0 + y0 * y0) - 1.0;
                s[1] = k * 2.0 * (x0 * dx + y0 * dy);
                s[2] = k * len2;
                let p = legendre_along(&s, 2, n);
                for (c, pk) in self.coefficients.iter().zip(&p) {
                    for m in 0..ALONG_TERMS {
                        a[m] += c * pk[m];
                    }
                }
                terms = 2 * n + 1;
            }
            Basis::Map { centre, half, .. } => {
                let u = linear((x0 - centre.0) / half.0, dx / half.0);
                let v = linear((y0 - centre.1) / half.1, dy / half.1);
                let pu = legendre_along(&u, 1, n);
                let pv = legendre_along(&v, 1, n);
                for (i, p_i) in pu.iter().enumerate() {
                    // Σ_j c_ij P_j(v), then times P_i(u).
                    let mut q = [0.0; ALONG_TERMS];
                    for (j, p_j) in pv.iter().enumerate().take(n - i + 1) {
                        let d = i + j;
                        let c = self.coefficients[d * (d + 1) / 2 + (d - i)];
                        for m in 0..=j {
                            q[m] += c * p_j[m];
                        }
                    }
                    let t = poly_mul(p_i, &q, i, n - i);
                    for m in 0..=n {
                        a[m] += t[m];
                    }
                }
                terms = n + 1;
            }
        }
        Along { t0, a, terms }
    }
}

/// A correction's sections along the rays from the origin (a lathe's
/// spindle axis): each a polynomial in the radius u (`Rays::section`),
/// Σ_k u^k Σ_{a+b=k} m_ab cos^a θ sin^b θ, from the correction written
/// once as monomials x^a y^b about the origin (a radial correction's
/// section is the same along every ray).
#[derive(Clone, Debug, PartialEq)]
pub struct Rays {
    order: usize,
    /// Map: m_ab (of x^a y^b) by degree, m_{a, k−a} at k(k + 1)/2 + a.
    /// Radial: the section itself.
    m: Vec<f64>,
    radial: bool,
}

impl Correction {
    /// The correction's sections along rays from the origin, or `None`
    /// where a map's centre lies beyond its half-widths from the origin
    /// (there its monomials about the origin would cancel to a loss of
    /// digits; such a part is not turned about its axis).
    pub fn rays(&self) -> Option<Rays> {
        let n = self.basis.order();
        match self.basis {
            Basis::Radial { .. } => {
                let along = self.along((0.0, 0.0), (1.0, 0.0));
                Some(Rays {
                    order: n,
                    m: along.a[..along.terms].to_vec(),
                    radial: true,
                })
            }
            Basis::Map { centre, half, .. } => {
                if centre.0.abs() > half.0 || centre.1.abs() > half.1 {
                    return None;
                }
                let linear = |c0: f64, c1: f64| {
                    let mut p = [0.0; ALONG_TERMS];
                    (p[0], p[1]) = (c0, c1);
                    p
                };
                let px = legendre_along(&linear(-centre.0 / half.0, 1.0 / half.0), 1, n);
                let py = legendre_along(&linear(-centre.1 / half.1, 1.0 / half.1), 1, n);
                let mut m = vec![0.0; (n + 1) * (n + 1)];
                for d in 0..=n {
                    for i in (0..=d).rev() {
                        let j = d - i;
                        let c = self.coefficients[d * (d + 1) / 2 + (d - i)];
                        if c == 0.0 {
                            continue;
                        }
                        for a in 0..=i {
                            for b in 0..=j {
                                m[a * (n + 1) + b] += c * px[i][a] * py[j][b];
                            }
                        }
                    }
                }
                // By degree: the terms of u^k, m_{a, k−a} for a = 0..=k,
                // one after another (`section` runs along them).
                let mut by_degree = Vec::with_capacity((n + 1) * (n + 2) / 2);
                for k in 0..=n {
                    for a in 0..=k {
                        by_degree.push(m[a * (n + 1) + (k - a)]);
                    }
                }
                Some(Rays {
                    order: n,
                    m: by_degree,
                    radial: false,
                })
            }
        }
    }
}

impl Rays {
    /// The section along the ray (cos θ, sin θ): coefficients of u^k,
    /// lowest first, times `scale`, and how many there are.
    pub fn section(&self, cos: f64, sin: f64, scale: f64, out: &mut [f64]) -> usize {
        if self.radial {
            for (o, m) in out.iter_mut().zip(&self.m) {
                *o = scale * m;
            }
            return self.m.len();
        }
        let n = self.order;
        let (mut cp, mut sp) = ([1.0; ORDERS], [1.0; ORDERS]);
        for k in 1..=n {
            cp[k] = cp[k - 1] * cos;
            sp[k] = sp[k - 1] * sin;
        }
        let mut terms = self.m.as_slice();
        for (k, o) in out.iter_mut().enumerate().take(n + 1) {
            let (row, rest) = terms.split_at(k + 1);
            terms = rest;
            let mut h = 0.0;
            // m_{a, k−a} cos^a θ sin^(k−a) θ, a = 0..=k.
            for ((m, c), s) in row.iter().zip(&cp[..=k]).zip(sp[..=k].iter().rev()) {
                h += m * c * s;
            }
            *o = scale * h;
        }
        n + 1
    }
}

/// P_0 … P_n of the node `t`, by the recurrence `legendre` uses.
fn legendre_nodes(g: &mut Graph, t: Id, n: usize) -> Vec<Id> {
    let mut p = vec![g.constant_node(1.0)];
    if n >= 1 {
        p.push(t);
    }
    for k in 1..n {
        let a = g.constant_node((2 * k + 1) as f64 / (k + 1) as f64);
        let b = g.constant_node(k as f64 / (k + 1) as f64);
        let tp = g.mul(t, p[k]);
        let first = g.mul(a, tp);
        let second = g.mul(b, p[k - 1]);
        p.push(g.sub(first, second));
    }
    p
}

/// Averages the errors `e` at design-frame points `xy` into cells at most
/// `cell` wide: rings of radius for the radial basis, squares otherwise.
/// Each cell: (mean x, mean y, mean error, points).
pub fn bin(basis: &Basis, xy: &[(f64, f64)], e: &[f64], cell: f64) -> Vec<(f64, f64, f64, f64)> {
    use std::collections::HashMap;
    let mut cells: HashMap<(i64, i64), (f64, f64, f64, f64)> = HashMap::new();
    for (&(x, y), &v) in xy.iter().zip(e) {
        let key = match basis {
            Basis::Radial { .. } => (((x * x + y * y).sqrt() / cell).floor() as i64, 0),
            Basis::Map { .. } => ((x / cell).floor() as i64, (y / cell).floor() as i64),
        };
        let c = cells.entry(key).or_insert((0.0, 0.0, 0.0, 0.0));
        match basis {
            // A ring's mean radius, as a point on +x.
            Basis::Radial { .. } => c.0 += (x * x + y * y).sqrt(),
            Basis::Map { .. } => {
                c.0 += x;
                c.1 += y;
            }
        }
        c.2 += v;
        c.3 += 1.0;
    }
    let mut out: Vec<(f64, f64, f64, f64)> = cells
        .into_values()
        .map(|(x, y, v, n)| (x / n, y / n, v / n, n))
        .collect();
    // The same fit whatever order the map's cells were visited in.
    out.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    out
}

/// Fits `basis` to the cells (`bin`) by weighted least squares; `None`
/// when there are fewer cells than terms or the normal equations are
/// singular (the cells do not span the aperture).
pub fn fit(basis: Basis, cells: &[(f64, f64, f64, f64)]) -> Option<Correction> {
    let terms = basis.terms();
    let m = terms.len();
    if cells.len() < m {
        return None;
    }
    let mut a = vec![0.0; m * m];
    let mut b = vec![0.0; m];
    let mut row = Vec::with_capacity(m);
    for &(x, y, v, w) in cells {
        basis.values(x, y, &mut row);
        for i in 0..m {
            let wi = w * row[i];
            b[i] += wi * v;
            for j in 0..=i {
                a[i * m + j] += wi * row[j];
            }
        }
    }
    for i in 0..m {
        for j in 0..i {
            a[j * m + i] = a[i * m + j];
        }
    }
    let full = cholesky_solve(&mut a, &mut b, m)?;
    let mut sum = 0.0;
    let mut weight = 0.0;
    for &(x, y, v, w) in cells {
        basis.values(x, y, &mut row);
        let f: f64 = row.iter().zip(&full).map(|(p, c)| p * c).sum();
        sum += w * (v - f).powi(2);
        weight += w;
    }
    let coefficients = terms
        .iter()
        .zip(&full)
        .map(|(t, c)| if basis.is_placement(*t) { 0.0 } else { *c })
        .collect();
    Some(Correction {
        basis,
        coefficients,
        fit_residual_rms: (sum / weight).sqrt(),
        cells: cells.len(),
    })
}

/// Solves the symmetric positive definite `a` x = `b` (row-major, m × m)
/// by Cholesky; `None` if `a` is not positive definite to working
/// precision.
fn cholesky_solve(a: &mut [f64], b: &mut [f64], m: usize) -> Option<Vec<f64>> {
    let scale = (0..m).map(|i| a[i * m + i]).fold(0.0, f64::max);
    for j in 0..m {
        let mut d = a[j * m + j];
        for k in 0..j {
            d -= a[j * m + k] * a[j * m + k];
        }
        // (NaN included: a NaN pivot is no pivot)
        if d.is_nan() || d <= 1e-13 * scale {
            return None;
        }
        let d = d.sqrt();
        a[j * m + j] = d;
        for i in j + 1..m {
            let mut s = a[i * m + j];
            for k in 0..j {
                s -= a[i * m + k] * a[j * m + k];
            }
            a[i * m + j] = s / d;
        }
    }
    for i in 0..m {
        let mut s = b[i];
        for k in 0..i {
            s -= a[i * m + k] * b[k];
        }
        b[i] = s / a[i * m + i];
    }
    for i in (0..m).rev() {
        let mut s = b[i];
        for k in i + 1..m {
            s -= a[k * m + i] * b[k];
        }
        b[i] = s / a[i * m + i];
    }
    Some(b.to_vec())
}

#[cfg(test)]
mod tests;
