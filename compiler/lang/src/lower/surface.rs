//! Lowering checked surfaces to the runtime's expression IR: the height
//! z(x, y) in mm as a `SurfaceTape` (with its exact derivatives) and the
//! domain it is defined on.

use lensc_grammar::ast::{BinaryOp, Expr, ExprKind, UnaryOp};
use lensc_runtime::surface::analysis::Domain;
use lensc_runtime::surface::ir::{Binary, Graph, Id, SurfaceTape, Unary};

use crate::check::aperture_radius;
use crate::units;
use crate::value::{self, Formula, Object, Value};

/// A surface ready to evaluate.
pub struct LoweredSurface {
    pub tape: SurfaceTape,
    pub domain: Domain,
}

/// Why a checked surface cannot be lowered (yet).
#[derive(Debug, PartialEq)]
pub enum LowerError {
    /// The kind (or a part of it) has no IR lowering yet.
    Unsupported(&'static str),
    /// The aperture or domain is of a shape the surface cannot use.
    Aperture(&'static str),
}

/// How the material side enters the height: z = σ · sag(c), with c the
/// signed vertex curvature used in the sag formula.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Side {
    /// +1 or −1: multiplies the whole sag (coefficients included).
    pub sigma: f64,
    /// Whether the radius is used with its sign (optical convention).
    pub signed: bool,
}

impl Side {
    /// Reads `sense` / `convention` of a checked surface. With `sense`,
    /// radii are magnitudes and σ = +1 concave, −1 convex (Lin's s). With
    /// `convention: optical` (light along +z into the material), the sag is
    /// the lens designer's, seen from the other side: σ = −1 and radii keep
    /// their sign, so R > 0 is convex to the tool.
    pub fn of(f: &[value::Field]) -> Side {
        if value::word(f, "convention") == Some("optical") {
            Side {
                sigma: -1.0,
                signed: true,
            }
        } else {
            Side {
                sigma: if value::word(f, "sense") == Some("convex") {
                    -1.0
                } else {
                    1.0
                },
                signed: false,
            }
        }
    }
    /// The curvature 1/R the sag formula uses.
    pub fn curvature(self, radius: f64) -> f64 {
        if self.signed {
            1.0 / radius
        } else {
            1.0 / radius.abs()
        }
    }
}

/// Lowers a checked surface object.
pub fn lower_surface(o: &Object) -> Result<LoweredSurface, LowerError> {
    let domain = surface_domain(o).ok_or(LowerError::Aperture("no aperture or domain"))?;
    if let Some(tape) = radial_tape(o) {
        return Ok(LoweredSurface { tape, domain });
    }
    let mut g = Graph::new();
    let (x, y) = (g.x(), g.y());
    let z = height(&mut g, o, x, y)?;
    Ok(LoweredSurface {
        tape: SurfaceTape::new(g, z),
        domain,
    })
}

/// f(s), f'(s) and f''(s) of a surface of revolution, in a scratch graph
/// whose x stands for s = x² + y².
fn radial_profile(o: &Object) -> Option<(Graph, [Id; 3])> {
    if !matches!(
        o.kind.name,
        "sphere" | "conic" | "asphere" | "qbfs" | "qcon"
    ) {
        return None;
    }
    let f = &o.fields;
    let side = Side::of(f);
    let c = side.curvature(value::num(f, "radius")?);
    let k = value::num(f, "conic").unwrap_or(0.0);
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
    let p0 = match o.kind.name {
        "qbfs" => qbfs_departure(&mut h, s, c, f)?,
        "qcon" => qcon_departure(&mut h, s, f)?,
        _ => add_power_terms(&mut h, zero, s, &power_terms(f)),
    };
    let p1 = h.derivative(p0, lensc_runtime::surface::ir::Var::X);
    let p2 = h.derivative(p1, lensc_runtime::surface::ir::Var::X);
    let sigma = h.constant_node(side.sigma);
    let mut sum = |a: Id, b: Id| {
        let t = h.add(a, b);
        h.mul(sigma, t)
    };
    let (f0, f1, f2) = (sum(g0, p0), sum(g1, p1), sum(g2, p2));
    Some((h, [f0, f1, f2]))
}

/// Rotationally symmetric surfaces z = f(s), s = x² + y², differentiated
/// through s: f, f' and f'' are built once in s (exactly, by the graph's
/// own differentiation) and combined by the chain rule,
///   z_x = 2x f',  z_xx = 2f' + 4x² f'',  z_xy = 4xy f''  (and in y),
/// which is the tape a careful hand would write, a third the size of
/// differentiating in x and y directly.
fn radial_tape(o: &Object) -> Option<SurfaceTape> {
    let (h, [f0, f1, f2]) = radial_profile(o)?;
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
fn qbfs_departure(h: &mut Graph, s: Id, c: f64, f: &[value::Field]) -> Option<Id> {
    let (x, series) = forbes_series(h, s, f, lensc_runtime::surface::forbes::qbfs_chebyshev)?;
    let one = h.constant_node(1.0);
    // u²(1 − u²) / sqrt(1 − c² s)
    let omx = h.sub(one, x);
    let pre = h.mul(x, omx);
    let cc = h.constant_node(c * c);
    let cs = h.mul(cc, s);
    let under = h.sub(one, cs);
    let root = h.sqrt(under);
    let scaled = h.div(pre, root);
    Some(h.mul(scaled, series))
}

/// Forbes's Q-con departure from the conic in s = ρ²: u⁴ Σ a_m Q_m^con(u²),
/// u² = s/ρ_max², with Q_m^con(x) = P_m^(0,4)(2x − 1); the sum evaluated
/// as one Chebyshev series.
fn qcon_departure(h: &mut Graph, s: Id, f: &[value::Field]) -> Option<Id> {
    let (x, series) = forbes_series(h, s, f, lensc_runtime::surface::forbes::qcon_chebyshev)?;
    let x2 = h.powi(x, 2);
    Some(h.mul(x2, series))
}

/// u² = s/ρ_max² and Σ a_m Q_m(u²) for the coefficients `Q0` … `Q20` of a
/// Forbes surface, `basis(top)` giving each Q_m in the Chebyshev basis:
/// b_k = Σ_m a_m c_mk, the whole sum one Chebyshev series.
fn forbes_series(
    h: &mut Graph,
    s: Id,
    f: &[value::Field],
    basis: fn(usize) -> Vec<Vec<f64>>,
) -> Option<(Id, Id)> {
    let norm = value::num(f, "norm_radius")?;
    let coeffs: Vec<(usize, f64)> = (0..=lensc_runtime::surface::forbes::MAX_ORDER)
        .filter_map(|m| value::num(f, &format!("Q{m}")).map(|a| (m, a)))
        .collect();
    let top = coeffs.iter().map(|t| t.0).max().unwrap_or(0);
    let q = basis(top);
    let mut b = vec![0.0; top + 1];
    for &(m, a) in &coeffs {
        for (bk, ck) in b.iter_mut().zip(&q[m]) {
            *bk += a * ck;
        }
    }
    let inv = h.constant_node(1.0 / (norm * norm));
    let x = h.mul(s, inv);
    let series = chebyshev_series(h, x, &b);
    Some((x, series))
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

/// The height of surface `o` at the coordinates `x`, `y` (nodes of `g`),
/// built into `g`: sections and wrapped designs build their parent's height
/// at moved coordinates.
pub fn height(g: &mut Graph, o: &Object, x: Id, y: Id) -> Result<Id, LowerError> {
    let f = &o.fields;
    let side = Side::of(f);
    let k = value::num(f, "conic").unwrap_or(0.0);
    let z = match o.kind.name {
        "plane" => g.constant_node(0.0),
        "sphere" | "conic" | "asphere" => {
            let c =
                side.curvature(value::num(f, "radius").ok_or(LowerError::Unsupported("radius"))?);
            let r2 = radius_squared(g, x, y);
            let sag = conic_sag(g, c, k, r2);
            let sag = add_power_terms(g, sag, r2, &power_terms(f));
            let s = g.constant_node(side.sigma);
            g.mul(s, sag)
        }
        "qbfs" | "qcon" => {
            let (h, [f0, _, _]) = radial_profile(o).ok_or(LowerError::Unsupported(o.kind.name))?;
            let s = radius_squared(g, x, y);
            g.import(&h, s, s)[f0.0 as usize]
        }
        "cylinder" | "acylinder" => {
            let c =
                side.curvature(value::num(f, "radius").ok_or(LowerError::Unsupported("radius"))?);
            // Extruded along `axis`: the profile varies across it.
            let u = if value::word(f, "axis") == Some("x") {
                y
            } else {
                x
            };
            let u2 = g.powi(u, 2);
            let sag = conic_sag(g, c, k, u2);
            let sag = add_power_terms(g, sag, u2, &power_terms(f));
            let s = g.constant_node(side.sigma);
            g.mul(s, sag)
        }
        "biconic" => {
            let cx = side
                .curvature(value::num(f, "radius_x").ok_or(LowerError::Unsupported("radius_x"))?);
            let cy = side
                .curvature(value::num(f, "radius_y").ok_or(LowerError::Unsupported("radius_y"))?);
            let (kx, ky) = (
                value::num(f, "conic_x").unwrap_or(0.0),
                value::num(f, "conic_y").unwrap_or(0.0),
            );
            let x2 = g.powi(x, 2);
            let y2 = g.powi(y, 2);
            let num = {
                let a = g.constant_node(cx);
                let b = g.constant_node(cy);
                let ax = g.mul(a, x2);
                let by = g.mul(b, y2);
                g.add(ax, by)
            };
            let root = {
                let qa = g.constant_node((1.0 + kx) * cx * cx);
                let qb = g.constant_node((1.0 + ky) * cy * cy);
                let ta = g.mul(qa, x2);
                let tb = g.mul(qb, y2);
                let t = g.add(ta, tb);
                let one = g.constant_node(1.0);
                let u = g.sub(one, t);
                g.sqrt(u)
            };
            let one = g.constant_node(1.0);
            let den = g.add(one, root);
            let sag = g.div(num, den);
            let s = g.constant_node(side.sigma);
            g.mul(s, sag)
        }
        "toroid" => {
            let c =
                side.curvature(value::num(f, "radius").ok_or(LowerError::Unsupported("radius"))?);
            let rr = value::num(f, "rotation_radius")
                .ok_or(LowerError::Unsupported("rotation_radius"))?;
            // The rotation axis lies on the profile's side of the vertex.
            let rr = if c < 0.0 { -rr } else { rr };
            let y2 = g.powi(y, 2);
            let zy = conic_sag(g, c, k, y2);
            let zy = add_power_terms(g, zy, y2, &power_terms(f));
            let x2 = g.powi(x, 2);
            let r = g.constant_node(rr);
            let d = g.sub(r, zy);
            let d2 = g.powi(d, 2);
            let under = g.sub(d2, x2);
            let root = g.sqrt(under);
            // z = Rr − sign(Rr) sqrt((Rr − z_y)² − x²)
            let signed_root = if rr < 0.0 { g.neg(root) } else { root };
            let sag = g.sub(r, signed_root);
            let s = g.constant_node(side.sigma);
            g.mul(s, sag)
        }
        "ellipsoid" => {
            let (a, b, c) = (
                value::num(f, "a").unwrap_or(1.0),
                value::num(f, "b").unwrap_or(1.0),
                value::num(f, "c").unwrap_or(1.0),
            );
            let x2 = g.powi(x, 2);
            let y2 = g.powi(y, 2);
            let ia = g.constant_node(1.0 / (a * a));
            let ib = g.constant_node(1.0 / (b * b));
            let tx = g.mul(ia, x2);
            let ty = g.mul(ib, y2);
            let t = g.add(tx, ty);
            let one = g.constant_node(1.0);
            let u = g.sub(one, t);
            let root = g.sqrt(u);
            let depth = g.sub(one, root);
            let cc = g.constant_node(c * side.sigma);
            g.mul(cc, depth)
        }
        "xy_polynomial" => {
            let r2 = radius_squared(g, x, y);
            let mut sag = match value::num(f, "radius") {
                Some(radius) => conic_sag(g, side.curvature(radius), k, r2),
                None => g.constant_node(0.0),
            };
            let mut terms: Vec<(u32, u32, f64)> = f
                .iter()
                .filter_map(|fl| {
                    let (i, j) = crate::schema::xy_powers(&fl.name)?;
                    match fl.value {
                        Value::Num(v, _) => Some((i, j, v)),
                        _ => None,
                    }
                })
                .collect();
            terms.sort_by_key(|t| (t.0, t.1));
            for (i, j, cij) in terms {
                let xi = g.powi(x, i as i32);
                let yj = g.powi(y, j as i32);
                let m = g.mul(xi, yj);
                let cc = g.constant_node(cij);
                let t = g.mul(cc, m);
                sag = g.add(sag, t);
            }
            let s = g.constant_node(side.sigma);
            g.mul(s, sag)
        }
        "zernike" => {
            let r2 = radius_squared(g, x, y);
            let mut sag = match value::num(f, "radius") {
                Some(radius) => conic_sag(g, side.curvature(radius), k, r2),
                None => g.constant_node(0.0),
            };
            let norm =
                value::num(f, "norm_radius").ok_or(LowerError::Unsupported("norm_radius"))?;
            let ansi = value::word(f, "ordering") == Some("ansi");
            let mut terms: Vec<(u32, f64)> = f
                .iter()
                .filter_map(|fl| {
                    let j: u32 = fl.name.strip_prefix('Z')?.parse().ok()?;
                    match fl.value {
                        Value::Num(v, _) => Some((j, v)),
                        _ => None,
                    }
                })
                .collect();
            terms.sort_by_key(|t| t.0);
            for (j, coef) in terms {
                let (n, m) = if ansi {
                    zernike_ansi(j)
                } else {
                    zernike_fringe(j).ok_or(LowerError::Unsupported("fringe index above 37"))?
                };
                let norm_factor = if ansi {
                    (2.0 * f64::from(n + 1) / if m == 0 { 2.0 } else { 1.0 }).sqrt()
                } else {
                    1.0
                };
                let zt = zernike_term(g, (x, y), n, m, norm);
                let cc = g.constant_node(coef * norm_factor);
                let t = g.mul(cc, zt);
                sag = g.add(sag, t);
            }
            let s = g.constant_node(side.sigma);
            g.mul(s, sag)
        }
        "freeform" => {
            let Some(Value::Formula(formula)) = value::field(f, "z").map(|fl| &fl.value) else {
                return Err(LowerError::Unsupported("freeform without a formula"));
            };
            lower_formula(g, formula, x, y)
        }
        "wrap" => {
            // The flat design; the roller only maps y to the arc around it.
            let design = value::object(f, "surface")
                .ok_or(LowerError::Unsupported("wrap without a design"))?;
            height(g, design, x, y)?
        }
        "revolve" => {
            let profile = value::object(f, "profile")
                .ok_or(LowerError::Unsupported("revolve without a profile"))?;
            let start = g.constant_node(value::num(f, "start").unwrap_or(0.0));
            let r2 = radius_squared(g, x, y);
            let r = g.sqrt(r2);
            let u = g.add(start, r);
            let zero = g.constant_node(0.0);
            height(g, profile, u, zero)?
        }
        "off_axis" => {
            let parent = value::object(f, "parent")
                .ok_or(LowerError::Unsupported("off_axis without a parent"))?;
            let (x0, y0) = (
                value::num(f, "x").unwrap_or(0.0),
                value::num(f, "y").unwrap_or(0.0),
            );
            let cx = g.constant_node(x0);
            let cy = g.constant_node(y0);
            let px = g.add(x, cx);
            let py = g.add(y, cy);
            let zp = height(g, parent, px, py)?;
            // The parent's height and slope at the centre, as constants.
            let mut h = Graph::new();
            let (hx, hy) = (h.x(), h.y());
            let hz = height(&mut h, parent, hx, hy)?;
            let at = lensc_runtime::surface::ir::Interpreter::new(&SurfaceTape::new(h, hz));
            let o0 = lensc_runtime::surface::ir::SurfaceFn::eval(&at, x0, y0);
            let z0 = g.constant_node(o0[0]);
            let mut z = g.sub(zp, z0);
            if value::word(f, "tilt") == Some("remove") {
                let sx = g.constant_node(o0[1]);
                let sy = g.constant_node(o0[2]);
                let tx = g.mul(sx, x);
                let ty = g.mul(sy, y);
                let plane = g.add(tx, ty);
                z = g.sub(z, plane);
            }
            z
        }
        "grid" | "hex_grid" | "linear_array" => array_height(g, o, x, y)?,
        "tilt" => tilted_height(g, o, x, y)?,
        other => return Err(LowerError::Unsupported(other)),
    };
    Ok(z)
}

/// A parent surface turned by θ about the y (or x) axis through its vertex.
/// A parent point (p, q, z(p, q)) lands at P = p cosθ + z sinθ over the
/// turning direction, Z = −p sinθ + z cosθ. For the machine coordinate P
/// the parent coordinate p solves p cosθ + z(p, q) sinθ = P: Newton's
/// method, unrolled six times in the graph from p = P cosθ, converges
/// quadratically to machine precision for the gentle tilts allowed
/// (|θ| < 45°), and the derivatives flow through the iterations.
fn tilted_height(g: &mut Graph, o: &Object, x: Id, y: Id) -> Result<Id, LowerError> {
    let f = &o.fields;
    let parent =
        value::object(f, "parent").ok_or(LowerError::Unsupported("tilt without a parent"))?;
    let theta = value::num(f, "angle").unwrap_or(0.0);
    let about_x = value::word(f, "about") == Some("x");
    // Turning about y moves x; about x moves y, with the sign of the
    // right-hand rule (a positive turn about x lifts +y).
    let (cos, sin) = (
        theta.cos(),
        if about_x { -theta.sin() } else { theta.sin() },
    );
    // The parent and its slope along the turning direction, in a scratch
    // graph over (p, q) = (turning coordinate, the other one).
    let mut h = Graph::new();
    let (hp, hq) = (h.x(), h.y());
    let (hx, hy) = if about_x { (hq, hp) } else { (hp, hq) };
    let hz = height(&mut h, parent, hx, hy)?;
    let hzp = h.derivative(hz, lensc_runtime::surface::ir::Var::X);
    let (big_p, q) = if about_x { (y, x) } else { (x, y) };
    let c = g.constant_node(cos);
    let sn = g.constant_node(sin);
    let mut p = g.mul(big_p, c);
    for _ in 0..6 {
        let map = g.import(&h, p, q);
        let (z, zp) = (map[hz.0 as usize], map[hzp.0 as usize]);
        // F = p cosθ + z sinθ − P, F′ = cosθ + z_p sinθ
        let pc = g.mul(p, c);
        let zs = g.mul(z, sn);
        let sum = g.add(pc, zs);
        let res = g.sub(sum, big_p);
        let zps = g.mul(zp, sn);
        let der = g.add(c, zps);
        let step = g.div(res, der);
        p = g.sub(p, step);
    }
    let map = g.import(&h, p, q);
    let z = map[hz.0 as usize];
    let ps = g.mul(p, sn);
    let zc = g.mul(z, c);
    Ok(g.sub(zc, ps))
}

/// The region a surface is defined on: its aperture, or its domain.
fn region(o: &Object) -> Option<&Object> {
    value::object(&o.fields, "aperture")
        .or_else(|| value::object(&o.fields, "domain"))
        .map(|r| &**r)
}

/// A node that is negative exactly inside `domain` at (u, v).
fn inside(g: &mut Graph, domain: &Domain, u: Id, v: Id) -> Id {
    match *domain {
        Domain::Circle { radius } => {
            let r2 = radius_squared(g, u, v);
            let a2 = g.constant_node(radius * radius);
            g.sub(r2, a2)
        }
        Domain::Annulus { inner, outer } => {
            // max(r² − outer², inner² − r²)
            let r2 = radius_squared(g, u, v);
            let o2 = g.constant_node(outer * outer);
            let i2 = g.constant_node(inner * inner);
            let a = g.sub(r2, o2);
            let b = g.sub(i2, r2);
            g.binary(Binary::Max, a, b)
        }
        Domain::Rect {
            x: (x0, x1),
            y: (y0, y1),
        } => {
            // max(x0 − u, u − x1, y0 − v, v − y1)
            let c = |g: &mut Graph, k: f64| g.constant_node(k);
            let (cx0, cx1, cy0, cy1) = (c(g, x0), c(g, x1), c(g, y0), c(g, y1));
            let a = g.sub(cx0, u);
            let b = g.sub(u, cx1);
            let d = g.sub(cy0, v);
            let e = g.sub(v, cy1);
            let m1 = g.binary(Binary::Max, a, b);
            let m2 = g.binary(Binary::Max, d, e);
            g.binary(Binary::Max, m1, m2)
        }
    }
}

/// Half the extent of a lenslet's aperture along x and y.
fn half_extent(d: &Domain) -> (f64, f64) {
    match *d {
        Domain::Circle { radius } | Domain::Annulus { outer: radius, .. } => (radius, radius),
        Domain::Rect { x, y } => (x.0.abs().max(x.1.abs()), y.0.abs().max(y.1.abs())),
    }
}

/// clamp(floor(t), 0, n − 1) + offset, as a node: a cell index.
fn cell_index(g: &mut Graph, t: Id, n: f64, offset: f64) -> Id {
    let f = g.floor(t);
    let zero = g.constant_node(0.0);
    let top = g.constant_node(n - 1.0);
    let lo = g.binary(Binary::Max, f, zero);
    let i = g.binary(Binary::Min, lo, top);
    let off = g.constant_node(offset);
    let shifted = g.add(i, off);
    let clamped_lo = g.binary(Binary::Max, shifted, zero);
    g.binary(Binary::Min, clamped_lo, top)
}

/// Arrays: each lenslet clipped to its own aperture with its rim at the
/// land (z = 0); where apertures overlap, the deepest cut (the lowest
/// height) wins; outside every aperture, the land. Each point looks at its
/// own cell and, where apertures reach past half a pitch, the neighbours.
fn array_height(g: &mut Graph, o: &Object, x: Id, y: Id) -> Result<Id, LowerError> {
    array_height_settled(g, o, x, y, None)
}

/// The tool trajectory over an array for fast-tool-servo turning with a
/// settling offset h (Hashimoto & Yan, fig. 16): each lenslet continued
/// past its rim until it rises h above the land, the land itself at h.
pub fn lower_trajectory(o: &Object, settle: f64) -> Result<LoweredSurface, LowerError> {
    if !matches!(o.kind.name, "grid" | "hex_grid" | "linear_array") {
        return Err(LowerError::Unsupported(
            "a settling offset needs an array of lenslets",
        ));
    }
    let domain = surface_domain(o).ok_or(LowerError::Aperture("no aperture or domain"))?;
    let mut g = Graph::new();
    let (x, y) = (g.x(), g.y());
    let z = array_height_settled(&mut g, o, x, y, Some(settle))?;
    Ok(LoweredSurface {
        tape: SurfaceTape::new(g, z),
        domain,
    })
}

/// The centres of a rectangular grid's or a linear array's lenslets (mm);
/// `None` for other surfaces.
pub fn array_centres(o: &Object) -> Option<Vec<(f64, f64)>> {
    let f = &o.fields;
    let num = |name: &str| value::num(f, name);
    let (px, py, nx, ny) = match o.kind.name {
        "grid" => (
            num("pitch_x")?,
            num("pitch_y")?,
            num("count_x")?,
            num("count_y")?,
        ),
        "linear_array" if value::word(f, "axis") == Some("y") => {
            (0.0, num("pitch")?, 1.0, num("count")?)
        }
        "linear_array" => (num("pitch")?, 0.0, num("count")?, 1.0),
        _ => return None,
    };
    let (nx, ny) = (nx as usize, ny as usize);
    let mut centres = Vec::with_capacity(nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            centres.push((
                (i as f64 - (nx as f64 - 1.0) / 2.0) * px,
                (j as f64 - (ny as f64 - 1.0) / 2.0) * py,
            ));
        }
    }
    Some(centres)
}

/// The lenslet of an array as its own surface, with the radius of its
/// circular aperture: what the settling offset is measured on.
pub fn array_lenslet(o: &Object) -> Option<(LoweredSurface, f64)> {
    if !matches!(o.kind.name, "grid" | "hex_grid" | "linear_array") {
        return None;
    }
    let lenslet = value::object(&o.fields, "lenslet")?;
    let Domain::Circle { radius } = domain_of(region(lenslet)?).ok()? else {
        return None;
    };
    let mut g = Graph::new();
    let (x, y) = (g.x(), g.y());
    let z = height(&mut g, lenslet, x, y).ok()?;
    Some((
        LoweredSurface {
            tape: SurfaceTape::new(g, z),
            domain: Domain::Circle { radius },
        },
        radius,
    ))
}

fn array_height_settled(
    g: &mut Graph,
    o: &Object,
    x: Id,
    y: Id,
    settle: Option<f64>,
) -> Result<Id, LowerError> {
    let f = &o.fields;
    let lenslet =
        value::object(f, "lenslet").ok_or(LowerError::Unsupported("array without a lenslet"))?;
    let ap =
        domain_of(region(lenslet).ok_or(LowerError::Aperture("lenslet without an aperture"))?)?;
    let (hx, hy) = half_extent(&ap);
    // Continued lenslets reach past their apertures: look at neighbours.
    let (hx, hy) = if settle.is_some() {
        (1.5 * hx, 1.5 * hy)
    } else {
        (hx, hy)
    };
    // The rim height: the lenslet at the edge of its aperture along +x.
    let rim = {
        let mut h = Graph::new();
        let (u, v) = (h.x(), h.y());
        let z = height(&mut h, lenslet, u, v)?;
        let f = lensc_runtime::surface::ir::Interpreter::new(&SurfaceTape::new(h, z));
        let at = match ap {
            Domain::Circle { radius } | Domain::Annulus { outer: radius, .. } => (radius, 0.0),
            Domain::Rect { x, y } => (x.1, 0.5 * (y.0 + y.1)),
        };
        lensc_runtime::surface::ir::SurfaceFn::eval(&f, at.0, at.1)[0]
    };
    // Cell centres: (i, j) → (cx, cy) as nodes; candidate cells per point.
    let mut candidates: Vec<(Id, Id)> = Vec::new();
    let num = |name: &str| value::num(f, name).unwrap_or(1.0);
    match o.kind.name {
        "grid" | "linear_array" => {
            let along_y = value::word(f, "axis") == Some("y");
            let (px, py, nx, ny) = match o.kind.name {
                "grid" => (
                    num("pitch_x"),
                    num("pitch_y"),
                    num("count_x"),
                    num("count_y"),
                ),
                _ if along_y => (f64::INFINITY, num("pitch"), 1.0, num("count")),
                _ => (num("pitch"), f64::INFINITY, num("count"), 1.0),
            };
            let reach = |half: f64, pitch: f64| {
                if half > 1.5 * pitch {
                    None
                } else if half > 0.5 * pitch {
                    Some(1)
                } else {
                    Some(0)
                }
            };
            let (kx, ky) = match (reach(hx, px), reach(hy, py)) {
                (Some(a), Some(b)) => (a, b),
                _ => {
                    return Err(LowerError::Aperture(
                        "lenslet apertures reach past their neighbours",
                    ));
                }
            };
            let axis_cells = |g: &mut Graph, t: Id, pitch: f64, n: f64, k: i32| -> Vec<Id> {
                if n <= 1.0 {
                    return vec![g.constant_node(0.0)];
                }
                let inv = g.constant_node(1.0 / pitch);
                let q = g.mul(t, inv);
                let half = g.constant_node(n / 2.0);
                let qt = g.add(q, half);
                (-k..=k)
                    .map(|d| {
                        let i = cell_index(g, qt, n, f64::from(d));
                        // centre = (i − (n − 1)/2) · pitch
                        let mid = g.constant_node((n - 1.0) / 2.0);
                        let off = g.sub(i, mid);
                        let p = g.constant_node(pitch);
                        g.mul(off, p)
                    })
                    .collect()
            };
            let xs = axis_cells(g, x, px, nx, kx);
            let ys = axis_cells(g, y, py, ny, ky);
            for &cx in &xs {
                for &cy in &ys {
                    candidates.push((cx, cy));
                }
            }
        }
        _ => {
            // Hexagonal: rows of spacing p·√3/2, odd rows shifted by p/2.
            let (p, nx, ny) = (num("pitch"), num("count_x"), num("count_y"));
            if hx.max(hy) > 1.5 * p {
                return Err(LowerError::Aperture(
                    "lenslet apertures reach past their neighbours",
                ));
            }
            let row = p * 3f64.sqrt() / 2.0;
            let inv = g.constant_node(1.0 / row);
            let q = g.mul(y, inv);
            let half = g.constant_node(ny / 2.0);
            let qt = g.add(q, half);
            for dj in -1..=1 {
                let j = cell_index(g, qt, ny, f64::from(dj));
                let mid = g.constant_node((ny - 1.0) / 2.0);
                let joff = g.sub(j, mid);
                let rc = g.constant_node(row);
                let cy = g.mul(joff, rc);
                // parity of j: j − 2 floor(j/2), shifting the row by ±p/4.
                let h = g.constant_node(0.5);
                let jh = g.mul(j, h);
                let fl = g.floor(jh);
                let two = g.constant_node(2.0);
                let tf = g.mul(two, fl);
                let parity = g.sub(j, tf);
                let quarter = g.constant_node(p / 2.0);
                let pq = g.mul(parity, quarter);
                let back = g.constant_node(p / 4.0);
                let shift = g.sub(pq, back);
                let xl = g.sub(x, shift);
                let pinv = g.constant_node(1.0 / p);
                let xq = g.mul(xl, pinv);
                let nh = g.constant_node(nx / 2.0);
                let xt = g.add(xq, nh);
                for di in -1..=1 {
                    let i = cell_index(g, xt, nx, f64::from(di));
                    let mid = g.constant_node((nx - 1.0) / 2.0);
                    let ioff = g.sub(i, mid);
                    let pc = g.constant_node(p);
                    let cx0 = g.mul(ioff, pc);
                    let cx = g.add(cx0, shift);
                    candidates.push((cx, cy));
                }
            }
        }
    }
    // min over the candidates that contain the point; +BIG where none do.
    const BIG: f64 = 1e6;
    let big = g.constant_node(BIG);
    let rim_c = g.constant_node(rim);
    let mut best = big;
    for (cx, cy) in candidates {
        let u = g.sub(x, cx);
        let v = g.sub(y, cy);
        let zl = height(g, lenslet, u, v)?;
        let z = g.sub(zl, rim_c);
        if settle.is_some() {
            best = g.binary(Binary::Min, best, z);
            continue;
        }
        let inside_test = inside(g, &ap, u, v);
        let h = g.select(inside_test, z, big);
        best = g.binary(Binary::Min, best, h);
    }
    if let Some(h) = settle {
        let plateau = g.constant_node(h);
        return Ok(g.binary(Binary::Min, best, plateau));
    }
    let half_big = g.constant_node(BIG / 2.0);
    let test = g.sub(best, half_big);
    let land = g.constant_node(0.0);
    Ok(g.select(test, best, land))
}

/// The rectangle of every cell of an array (count × pitch), centred on
/// the origin: a wrapped array closes on itself when its cells do.
fn array_domain(o: &Object) -> Option<Domain> {
    let f = &o.fields;
    let lenslet = value::object(f, "lenslet")?;
    let ap = domain_of(region(lenslet)?).ok()?;
    let (hx, hy) = half_extent(&ap);
    let num = |name: &str| value::num(f, name).unwrap_or(1.0);
    let (ex, ey) = match o.kind.name {
        "grid" => (
            num("count_x") * num("pitch_x") / 2.0,
            num("count_y") * num("pitch_y") / 2.0,
        ),
        "hex_grid" => (
            num("count_x") * num("pitch") / 2.0 + num("pitch") / 4.0,
            num("count_y") * num("pitch") * 3f64.sqrt() / 4.0,
        ),
        _ if value::word(f, "axis") == Some("y") => (hx, num("count") * num("pitch") / 2.0),
        _ => (num("count") * num("pitch") / 2.0, hy),
    };
    Some(Domain::Rect {
        x: (-ex, ex),
        y: (-ey, ey),
    })
}

/// The domain a checked surface is evaluated over, if it can be lowered.
pub fn surface_domain(o: &Object) -> Option<Domain> {
    match region(o) {
        Some(r) => domain_of(r).ok(),
        None if matches!(o.kind.name, "grid" | "hex_grid" | "linear_array") => array_domain(o),
        None => value::object(&o.fields, "surface").and_then(|s| surface_domain(s)),
    }
}

/// x² + y².
fn radius_squared(g: &mut Graph, x: Id, y: Id) -> Id {
    let x2 = g.powi(x, 2);
    let y2 = g.powi(y, 2);
    g.add(x2, y2)
}

/// c s / (1 + sqrt(1 − (1+k) c² s)) with s = r² (or u²): the conic sag,
/// smooth through the vertex.
fn conic_sag(g: &mut Graph, c: f64, k: f64, s: Id) -> Id {
    let cc = g.constant_node(c);
    let num = g.mul(cc, s);
    let q = g.constant_node((1.0 + k) * c * c);
    let qs = g.mul(q, s);
    let one = g.constant_node(1.0);
    let u = g.sub(one, qs);
    let root = g.sqrt(u);
    let den = g.add(one, root);
    g.div(num, den)
}

/// The `Aj` coefficients of a checked surface, by power.
fn power_terms(f: &[value::Field]) -> Vec<(u32, f64)> {
    (1..=20u32)
        .filter_map(|j| value::num(f, &format!("A{j}")).map(|a| (j, a)))
        .collect()
}

/// sag + Σ A_j (s)^(j/2), with s = r². The even terms are one polynomial
/// in s, evaluated by Horner's rule (fewer nodes, and so fewer in every
/// derivative); odd terms are real powers of s.
fn add_power_terms(g: &mut Graph, mut sag: Id, s: Id, terms: &[(u32, f64)]) -> Id {
    let mut even: Vec<(u32, f64)> = terms
        .iter()
        .filter(|(j, _)| j % 2 == 0)
        .map(|&(j, a)| (j / 2, a))
        .collect();
    even.sort_unstable_by_key(|t| t.0);
    if let Some(&(lowest, _)) = even.first() {
        // Σ a_m s^m = s^lowest · (a_lowest + s (a_next + s (…)))
        let top = even.last().expect("non-empty").0;
        let mut poly = g.constant_node(0.0);
        for m in (lowest..=top).rev() {
            let a = even.iter().find(|t| t.0 == m).map_or(0.0, |t| t.1);
            let times = g.mul(poly, s);
            let ac = g.constant_node(a);
            poly = g.add(times, ac);
        }
        let base = g.powi(s, lowest as i32);
        let t = g.mul(base, poly);
        sag = g.add(sag, t);
    }
    for &(j, a) in terms.iter().filter(|(j, _)| j % 2 == 1) {
        let half = g.constant_node(f64::from(j) / 2.0);
        let t = g.binary(Binary::Pow, s, half);
        let ac = g.constant_node(a);
        let term = g.mul(ac, t);
        sag = g.add(sag, term);
    }
    sag
}

/// (n, m) of ANSI Z80.28 index j (from 0): m < 0 is a sine term.
pub fn zernike_ansi(j: u32) -> (u32, i32) {
    let n = ((-3.0 + (9.0 + 8.0 * f64::from(j)).sqrt()) / 2.0).ceil() as u32;
    let m = 2 * j as i32 - (n * (n + 2)) as i32;
    (n, m)
}

/// (n, m) of fringe index j (1 … 37): m < 0 is a sine term. Z1 … Z36 follow
/// the fringe rule; Z37 is the 12th-order spherical term.
pub fn zernike_fringe(j: u32) -> Option<(u32, i32)> {
    match j {
        0 => None,
        37 => Some((12, 0)),
        1..=36 => {
            let k = (f64::from(j).sqrt().ceil() as u32) - 1;
            let t = j - k * k - 1;
            let m = k - t / 2;
            let n = 2 * k - m;
            Some((n, if t % 2 == 1 { -(m as i32) } else { m as i32 }))
        }
        _ => None,
    }
}

/// R_n^|m|(ρ) · cos(mθ) (m ≥ 0) or · sin(|m|θ) (m < 0), over ρ = r / norm,
/// written as a polynomial in x and y: [R_n^m(ρ)/ρ^m] · Re or Im (u + iv)^m.
fn zernike_term(g: &mut Graph, (x, y): (Id, Id), n: u32, m: i32, norm: f64) -> Id {
    let ma = m.unsigned_abs();
    let inv = g.constant_node(1.0 / norm);
    let u = g.mul(x, inv);
    let v = g.mul(y, inv);
    // Re and Im of (u + iv)^|m|.
    let one = g.constant_node(1.0);
    let zero = g.constant_node(0.0);
    let (mut re, mut im) = (one, zero);
    for _ in 0..ma {
        let a = g.mul(re, u);
        let b = g.mul(im, v);
        let c = g.mul(re, v);
        let d = g.mul(im, u);
        re = g.sub(a, b);
        im = g.add(c, d);
    }
    let angular = if m < 0 { im } else { re };
    // R_n^m(ρ)/ρ^m = Σ_s (−1)^s (n−s)! / (s! ((n+m)/2 − s)! ((n−m)/2 − s)!) (ρ²)^((n−m)/2 − s)
    let u2 = g.powi(u, 2);
    let v2 = g.powi(v, 2);
    let rho2 = g.add(u2, v2);
    let fact = |k: u32| (1..=k).map(f64::from).product::<f64>();
    let mut radial = g.constant_node(0.0);
    for s in 0..=(n - ma) / 2 {
        let coef = if s % 2 == 0 { 1.0 } else { -1.0 } * fact(n - s)
            / (fact(s) * fact((n + ma) / 2 - s) * fact((n - ma) / 2 - s));
        let p = g.powi(rho2, ((n - ma) / 2 - s) as i32);
        let cc = g.constant_node(coef);
        let t = g.mul(cc, p);
        radial = g.add(radial, t);
    }
    g.mul(radial, angular)
}

fn domain_of(ap: &Object) -> Result<Domain, LowerError> {
    match ap.kind.name {
        "circle" => aperture_radius(ap)
            .map(|radius| Domain::Circle { radius })
            .ok_or(LowerError::Aperture("circle")),
        "annulus" => match (
            value::num(&ap.fields, "inner"),
            value::num(&ap.fields, "outer"),
        ) {
            (Some(inner), Some(outer)) => Ok(Domain::Annulus { inner, outer }),
            _ => Err(LowerError::Aperture("annulus")),
        },
        "rect" => match (value::range(&ap.fields, "x"), value::range(&ap.fields, "y")) {
            (Some(x), Some(y)) => Ok(Domain::Rect { x, y }),
            _ => Err(LowerError::Aperture("rect")),
        },
        _ => Err(LowerError::Aperture("unknown aperture")),
    }
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

/// Lowers a checked formula body (in base units: mm and rad) at the
/// coordinates `x`, `y`.
pub fn lower_formula(g: &mut Graph, f: &Formula, x: Id, y: Id) -> Id {
    lower_expr(g, f, (x, y), &f.body)
}

fn lower_expr(g: &mut Graph, f: &Formula, at: (Id, Id), e: &Expr) -> Id {
    let (x, y) = at;
    match &e.kind {
        ExprKind::Quantity { value, unit } => {
            let factor: f64 = unit
                .iter()
                .flat_map(|u| &u.parts)
                .map(|p| units::lookup(&p.name).map_or(f64::NAN, |d| d.factor.powi(p.power)))
                .product();
            g.constant_node(value * factor)
        }
        ExprKind::Name(n) => match n.as_str() {
            "x" if f.params.iter().any(|p| p == "x") => x,
            "y" if f.params.iter().any(|p| p == "y") => y,
            "r" if f.params.iter().any(|p| p == "r") => {
                let r2 = radius_squared(g, x, y);
                g.sqrt(r2)
            }
            other => g.constant_node(f.constants.get(other).copied().unwrap_or(f64::NAN)),
        },
        ExprKind::Unary {
            op: UnaryOp::Neg,
            operand,
        } => {
            let a = lower_expr(g, f, at, operand);
            g.neg(a)
        }
        ExprKind::Binary { op, lhs, rhs } => {
            let a = lower_expr(g, f, at, lhs);
            let b = lower_expr(g, f, at, rhs);
            let op = match op {
                BinaryOp::Add => Binary::Add,
                BinaryOp::Sub => Binary::Sub,
                BinaryOp::Mul => Binary::Mul,
                BinaryOp::Div => Binary::Div,
                BinaryOp::Pow | BinaryOp::Range => Binary::Pow,
            };
            g.binary(op, a, b)
        }
        ExprKind::Call { callee, args } => {
            let name = match &callee.kind {
                ExprKind::Name(n) => n.as_str(),
                _ => "",
            };
            let a: Vec<Id> = args
                .iter()
                .map(|a| lower_expr(g, f, at, &a.value))
                .collect();
            let unary = |op| move |g: &mut Graph, a: &[Id]| g.unary(op, a[0]);
            match name {
                "sin" => unary(Unary::Sin)(g, &a),
                "cos" => unary(Unary::Cos)(g, &a),
                "tan" => unary(Unary::Tan)(g, &a),
                "asin" => unary(Unary::Asin)(g, &a),
                "acos" => unary(Unary::Acos)(g, &a),
                "atan" => unary(Unary::Atan)(g, &a),
                "sqrt" => unary(Unary::Sqrt)(g, &a),
                "abs" => unary(Unary::Abs)(g, &a),
                "exp" => unary(Unary::Exp)(g, &a),
                "ln" => unary(Unary::Ln)(g, &a),
                "atan2" => g.binary(Binary::Atan2, a[0], a[1]),
                "min" | "max" => {
                    let op = if name == "min" {
                        Binary::Min
                    } else {
                        Binary::Max
                    };
                    a[1..].iter().fold(a[0], |acc, &b| g.binary(op, acc, b))
                }
                _ => g.constant_node(f64::NAN),
            }
        }
        // The checker admits no other node in a formula.
        _ => g.constant_node(f64::NAN),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lensc_runtime::surface::ir::{Interpreter, SurfaceFn};
    use lensc_runtime::surface::{RotationalSurface, Sense};

    /// The IR sag (in r² form, differentiated symbolically) against the
    /// runtime's closed-form profile (differentiated by hand), along x and,
    /// by symmetry, along y.
    #[test]
    fn ir_sag_matches_closed_form_profile() {
        let terms = vec![(3, 2e-4), (4, 1.5e-4), (6, -3e-6), (8, 2e-8), (16, 1e-14)];
        for (radius, k, sense) in [
            (22.405, 43.098, Sense::Convex),
            (4.254, -3.359, Sense::Concave),
            (8.5, -0.62, Sense::Convex),
            (5.0, 0.0, Sense::Concave),
        ] {
            let closed = RotationalSurface {
                radius,
                conic: k,
                sense,
                terms: terms.clone(),
                aperture_radius: 1.5,
            };
            let mut g = Graph::new();
            let z = rotational_sag(&mut g, radius, k, &terms, sense.sign());
            let f = Interpreter::new(&SurfaceTape::new(g, z));
            for r in [0.05, 0.4, 0.9, 1.5] {
                let p = closed.eval(r);
                let ox = f.eval(r, 0.0);
                let oy = f.eval(0.0, r);
                let tol = |a: f64| 1e-13 * (1.0 + a.abs());
                assert!(
                    (ox[0] - p.z).abs() <= tol(p.z),
                    "z R={radius} r={r}: {} vs {}",
                    ox[0],
                    p.z
                );
                assert!(
                    (ox[1] - p.dz).abs() <= tol(p.dz),
                    "dz/dx R={radius} r={r}: {} vs {}",
                    ox[1],
                    p.dz
                );
                assert!(
                    (ox[3] - p.d2z).abs() <= tol(p.d2z),
                    "d2z/dx2 R={radius} r={r}: {} vs {}",
                    ox[3],
                    p.d2z
                );
                assert!(
                    (oy[0] - p.z).abs() <= tol(p.z)
                        && (oy[2] - p.dz).abs() <= tol(p.dz)
                        && (oy[5] - p.d2z).abs() <= tol(p.d2z)
                );
                assert!(
                    ox[2].abs() < 1e-15 && ox[4].abs() < 1e-15,
                    "no slope across the section"
                );
            }
        }
    }

    /// A sphere's sag against R − sqrt(R² − r²) in 2-D, off the axes
    /// (written r²/(R + sqrt(R² − r²)) to avoid cancellation).
    #[test]
    fn sphere_sag_off_axis() {
        let mut g = Graph::new();
        let z = rotational_sag(&mut g, 20.0, 0.0, &[], 1.0);
        let f = Interpreter::new(&SurfaceTape::new(g, z));
        for (x, y) in [(0.3, 0.4), (-0.6, 0.8), (0.85, -0.1)] {
            let r2 = x * x + y * y;
            let want = r2 / (20.0 + (400.0f64 - r2).sqrt());
            let got = f.eval(x, y)[0];
            assert!((got - want).abs() <= 4e-16 * want, "{got} vs {want}");
        }
    }

    /// Checks `src` and lowers its surface `name`; evaluates at (x, y).
    fn eval_surface(src: &str, name: &str, x: f64, y: f64) -> [f64; 6] {
        let c = crate::check_text(&crate::loader::RealFs, "t.lens", src.as_bytes());
        assert!(!c.has_errors(), "{:?}", c.diags());
        let o = c.checked.declarations.get(name).expect("surface");
        let l = lower_surface(o).expect("lowers");
        Interpreter::new(&l.tape).eval(x, y)
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-14 * (1.0 + a.abs().max(b.abs()))
    }

    #[test]
    fn zernike_indices_follow_the_tables() {
        // Fringe: Z1 piston, Z4 defocus, Z5/Z6 astigmatism, Z9 spherical,
        // Z10 trefoil, Z16 5th-order spherical, Z36 (10,0), Z37 (12,0).
        assert_eq!(zernike_fringe(1), Some((0, 0)));
        assert_eq!(zernike_fringe(2), Some((1, 1)));
        assert_eq!(zernike_fringe(3), Some((1, -1)));
        assert_eq!(zernike_fringe(4), Some((2, 0)));
        assert_eq!(zernike_fringe(6), Some((2, -2)));
        assert_eq!(zernike_fringe(9), Some((4, 0)));
        assert_eq!(zernike_fringe(10), Some((3, 3)));
        assert_eq!(zernike_fringe(16), Some((6, 0)));
        assert_eq!(zernike_fringe(36), Some((10, 0)));
        assert_eq!(zernike_fringe(37), Some((12, 0)));
        assert_eq!(zernike_fringe(38), None);
        // ANSI Z80.28: j = (n(n+2) + m)/2.
        for n in 0..12u32 {
            for m in (-(n as i32)..=n as i32).step_by(2) {
                let j = ((n * (n + 2)) as i32 + m) / 2;
                assert_eq!(zernike_ansi(j as u32), (n, m), "j={j}");
            }
        }
    }

    #[test]
    fn zernike_terms_match_their_polynomials() {
        let base = "surface w = zernike { norm_radius: 2 mm, ordering: ORD, aperture: circle(radius: 2 mm), TERM: 1 um }";
        let at = |ord: &str, term: &str, x: f64, y: f64| {
            eval_surface(&base.replace("ORD", ord).replace("TERM", term), "w", x, y)[0]
        };
        let (x, y): (f64, f64) = (0.7, -1.1);
        let (rho, th) = ((x * x + y * y).sqrt() / 2.0, f64::atan2(y, x));
        let um = 1e-3;
        // Fringe Z9 = 6ρ⁴ − 6ρ² + 1; Z8 = (3ρ³ − 2ρ) sin θ; Z10 = ρ³ cos 3θ.
        assert!(close(
            at("fringe", "Z9", x, y),
            um * (6.0 * rho.powi(4) - 6.0 * rho * rho + 1.0)
        ));
        assert!(close(
            at("fringe", "Z8", x, y),
            um * (3.0 * rho.powi(3) - 2.0 * rho) * th.sin()
        ));
        assert!(close(
            at("fringe", "Z10", x, y),
            um * rho.powi(3) * (3.0 * th).cos()
        ));
        // ANSI j = 12 is (4, 0) normalised by sqrt(5); j = 3 is (2, −2) by sqrt(6).
        assert!(close(
            at("ansi", "Z12", x, y),
            um * 5f64.sqrt() * (6.0 * rho.powi(4) - 6.0 * rho * rho + 1.0)
        ));
        assert!(close(
            at("ansi", "Z3", x, y),
            um * 6f64.sqrt() * rho * rho * (2.0 * th).sin()
        ));
    }

    #[test]
    fn cylinder_toroid_biconic_ellipsoid_and_xy_polynomial() {
        let (x, y) = (0.3, -0.45);
        // A cylinder along y varies only with x.
        let cyl = eval_surface(
            "surface c = cylinder { radius: 2 mm, axis: y, sense: concave, aperture: circle(radius: 1 mm) }",
            "c",
            x,
            y,
        );
        assert!(
            close(cyl[0], x * x / (2.0 + (4.0 - x * x).sqrt())) && cyl[2] == 0.0 && cyl[5] == 0.0
        );
        // A biconic with equal radii and conics is the conic of revolution.
        let bic = eval_surface(
            "surface b = biconic { radius_x: 3 mm, radius_y: 3 mm, conic_x: -0.5, conic_y: -0.5, sense: convex, aperture: circle(radius: 1 mm) }",
            "b",
            x,
            y,
        );
        let con = eval_surface(
            "surface b = conic { radius: 3 mm, conic: -0.5, sense: convex, aperture: circle(radius: 1 mm) }",
            "b",
            x,
            y,
        );
        for k in 0..6 {
            assert!(
                close(bic[k], con[k]),
                "output {k}: {} vs {}",
                bic[k],
                con[k]
            );
        }
        // A toroid whose rotation radius equals its profile radius is a sphere.
        let tor = eval_surface(
            "surface t = toroid { radius: 4 mm, rotation_radius: 4 mm, sense: concave, aperture: circle(radius: 1 mm) }",
            "t",
            x,
            y,
        );
        let sph = eval_surface(
            "surface t = sphere { radius: 4 mm, sense: concave, aperture: circle(radius: 1 mm) }",
            "t",
            x,
            y,
        );
        for k in 0..6 {
            assert!(
                close(tor[k], sph[k]),
                "output {k}: {} vs {}",
                tor[k],
                sph[k]
            );
        }
        // At x = 0 a toroid is its y–z profile; along x a circle of the rotation radius.
        let tor = eval_surface(
            "surface t = toroid { radius: 4 mm, rotation_radius: 10 mm, sense: concave, aperture: circle(radius: 1 mm) }",
            "t",
            0.0,
            y,
        );
        assert!(close(tor[0], y * y / (4.0 + (16.0 - y * y).sqrt())));
        let tor = eval_surface(
            "surface t = toroid { radius: 4 mm, rotation_radius: 10 mm, sense: concave, aperture: circle(radius: 1 mm) }",
            "t",
            x,
            0.0,
        );
        assert!(close(tor[0], x * x / (10.0 + (100.0 - x * x).sqrt())));
        // Seed 002's lenslet: a = b = 0.505 mm, c = 1.01 mm, a dimple.
        let e = eval_surface(
            "surface e = ellipsoid { a: 0.505 mm, b: 0.505 mm, c: 1.01 mm, sense: concave, aperture: circle(diameter: 0.1 mm) }",
            "e",
            0.03,
            0.04,
        );
        assert!(close(
            e[0],
            1.01 * (1.0 - (1.0f64 - 0.0025 / (0.505 * 0.505)).sqrt())
        ));
        // XY polynomial on a plane: 0.01 x²y − 0.002 y³ (coefficients in mm^-2).
        let p = eval_surface(
            "surface p = xy_polynomial { aperture: circle(radius: 1 mm), X2Y1: 0.01 mm^-2, X0Y3: -0.002 mm^-2 }",
            "p",
            x,
            y,
        );
        assert!(close(p[0], 0.01 * x * x * y - 0.002 * y * y * y));
        assert!(close(p[4], 0.02 * x));
    }

    #[test]
    fn optical_sign_convention_matches_sense() {
        // Kim 2008's concave R = −4.254 mm, k = −3.359 in the optical
        // convention is the same surface as |R| with `sense: concave`; a
        // positive optical R is convex. Coefficients follow the sag's sign.
        let (x, y) = (0.4, 0.9);
        let opt = eval_surface(
            "surface s = asphere { radius: -4.254 mm, conic: -3.359, convention: optical, A4: 1e-3 mm^-3, aperture: circle(radius: 1.5 mm) }",
            "s",
            x,
            y,
        );
        let sen = eval_surface(
            "surface s = asphere { radius: 4.254 mm, conic: -3.359, sense: concave, A4: -1e-3 mm^-3, aperture: circle(radius: 1.5 mm) }",
            "s",
            x,
            y,
        );
        for k in 0..6 {
            assert!(
                close(opt[k], sen[k]),
                "output {k}: {} vs {}",
                opt[k],
                sen[k]
            );
        }
        let opt = eval_surface(
            "surface s = conic { radius: 22.405 mm, conic: 43.098, convention: optical, aperture: circle(radius: 1.6 mm) }",
            "s",
            x,
            y,
        );
        let sen = eval_surface(
            "surface s = conic { radius: 22.405 mm, conic: 43.098, sense: convex, aperture: circle(radius: 1.6 mm) }",
            "s",
            x,
            y,
        );
        assert!(close(opt[0], sen[0]) && opt[0] < 0.0);
    }

    #[test]
    fn off_axis_section_and_wrap() {
        // An off-axis section of a paraboloid z = r²/(2R) centred at (3, 0):
        // z(x, y) = ((x+3)² + y² − 9)/(2R); with the tilt removed, x²+y² over 2R.
        let src = "surface p = conic { radius: 10 mm, conic: -1, sense: concave, aperture: circle(radius: 5 mm) }
surface s = off_axis(p, x: 3 mm, y: 0 mm, aperture: circle(radius: 1 mm))
surface t = off_axis(p, x: 3 mm, y: 0 mm, tilt: remove, aperture: circle(radius: 1 mm))";
        let (x, y) = (0.4, -0.7);
        let s = eval_surface(src, "s", x, y);
        assert!(
            close(s[0], ((x + 3.0) * (x + 3.0) + y * y - 9.0) / 20.0)
                && close(s[1], (x + 3.0) / 10.0)
        );
        let t = eval_surface(src, "t", x, y);
        assert!(close(t[0], (x * x + y * y) / 20.0) && close(t[1], x / 10.0));
        // A wrapped design evaluates as the flat design.
        let w = eval_surface(
            "surface f = freeform { z(x, y) = 0.02 mm * sin(5 rad/mm * x), domain: rect(x: 0 mm .. 6 mm, y: 0 mm .. 18.84955592153876 mm) }
surface w = wrap(f, onto: roller(radius: 3 mm))",
            "w",
            0.3,
            1.0,
        );
        assert!(close(w[0], 0.02 * 1.5f64.sin()));
    }

    /// sag of a sphere of radius R at r: r²/(R + sqrt(R² − r²)).
    fn sphere_sag(radius: f64, r: f64) -> f64 {
        r * r / (radius + (radius * radius - r * r).sqrt())
    }

    #[test]
    fn grid_places_clips_and_lands() {
        let src =
            "surface l = sphere { radius: 2 mm, sense: concave, aperture: circle(radius: 0.3 mm) }
surface a = grid(l, pitch_x: 1 mm, pitch_y: 1 mm, count_x: 2, count_y: 2)";
        let rim = sphere_sag(2.0, 0.3);
        // Centres at (±0.5, ±0.5); the rim sits on the land, z = 0.
        assert!(close(eval_surface(src, "a", 0.5, 0.5)[0], -rim));
        assert!(close(eval_surface(src, "a", -0.5, 0.5)[0], -rim));
        assert!(close(
            eval_surface(src, "a", 0.6, 0.5)[0],
            sphere_sag(2.0, 0.1) - rim
        ));
        assert_eq!(
            eval_surface(src, "a", 0.0, 0.0)[0],
            0.0,
            "land between the lenslets"
        );
        assert_eq!(
            eval_surface(src, "a", 0.5, 0.85)[0],
            0.0,
            "outside the aperture"
        );
    }

    #[test]
    fn overlapping_lenslets_keep_the_deepest_cut() {
        // Convex bumps 1 mm apart whose apertures (0.8 mm) overlap: between
        // them the lower of the two profiles is what is left.
        let src =
            "surface l = sphere { radius: 2 mm, sense: convex, aperture: circle(radius: 0.8 mm) }
surface a = grid(l, pitch_x: 1 mm, pitch_y: 1 mm, count_x: 2, count_y: 1)";
        let rim = sphere_sag(2.0, 0.8);
        let near = rim - sphere_sag(2.0, 0.4);
        let far = rim - sphere_sag(2.0, 0.6);
        let z = eval_surface(src, "a", 0.1, 0.0)[0];
        assert!(
            close(z, near.min(far)) && far < near,
            "{z} vs {near} / {far}"
        );
        // Concave dimples: the nearer (deeper) one wins.
        let src = src.replace("convex", "concave");
        let z = eval_surface(&src, "a", 0.1, 0.0)[0];
        assert!(close(
            z,
            (sphere_sag(2.0, 0.4) - rim).min(sphere_sag(2.0, 0.6) - rim)
        ));
    }

    #[test]
    fn hex_rows_alternate_by_half_a_pitch() {
        let src =
            "surface l = sphere { radius: 2 mm, sense: concave, aperture: circle(radius: 0.2 mm) }
surface h = hex_grid(l, pitch: 1 mm, count_x: 3, count_y: 2)";
        let rim = sphere_sag(2.0, 0.2);
        let row = 3f64.sqrt() / 2.0;
        // Rows at y = ∓row/2; row 0 shifted by −1/4, row 1 by +1/4.
        for (x, y) in [
            (-1.25, -row / 2.0),
            (-0.25, -row / 2.0),
            (0.75, -row / 2.0),
            (-0.75, row / 2.0),
            (0.25, row / 2.0),
            (1.25, row / 2.0),
        ] {
            assert!(
                close(eval_surface(src, "h", x, y)[0], -rim),
                "no lenslet centre at ({x}, {y})"
            );
        }
        assert_eq!(eval_surface(src, "h", 0.25, -row / 2.0)[0], 0.0);
    }

    #[test]
    fn qbfs_is_the_sphere_plus_the_published_departure() {
        // Best-fit sphere R = 25 mm, ρ_max = 4 mm, a_0 … a_3 in µm.
        let src = "surface q = qbfs { radius: 25 mm, sense: concave, norm_radius: 4 mm, aperture: circle(radius: 4 mm), Q0: 2 um, Q1: -1 um, Q2: 0.5 um, Q3: 0.25 um }";
        let (x, y): (f64, f64) = (1.3, -2.1);
        let rho2 = x * x + y * y;
        let u2 = rho2 / 16.0;
        let q = [
            1.0,
            (13.0 - 16.0 * u2) / 19f64.sqrt(),
            (2.0f64 / 95.0).sqrt() * (29.0 - 4.0 * u2 * (25.0 - 19.0 * u2)),
            (2.0f64 / 2545.0).sqrt() * (207.0 - 4.0 * u2 * (315.0 - u2 * (577.0 - 320.0 * u2))),
        ];
        let a = [2e-3, -1e-3, 0.5e-3, 0.25e-3];
        let c = 1.0 / 25.0;
        let sum: f64 = a.iter().zip(q).map(|(a, q)| a * q).sum();
        let want = c * rho2 / (1.0 + (1.0 - c * c * rho2).sqrt())
            + u2 * (1.0 - u2) / (1.0 - c * c * rho2).sqrt() * sum;
        let got = eval_surface(src, "q", x, y)[0];
        assert!((got - want).abs() < 1e-15, "{got} vs {want}");
        // At the edge (u = 1) the departure vanishes: the best-fit sphere.
        let edge = eval_surface(src, "q", 4.0, 0.0)[0];
        assert!((edge - c * 16.0 / (1.0 + (1.0f64 - c * c * 16.0).sqrt())).abs() < 1e-15);
    }

    #[test]
    fn qcon_is_the_conic_plus_the_published_departure() {
        // Conic R = 12 mm, k = −0.8, ρ_max = 3 mm; Forbes 2007's closed forms
        // Q_0 = 1, Q_1 = −(5 − 6x), Q_2 = 15 − 14x(3 − 2x).
        let src = "surface q = qcon { radius: 12 mm, conic: -0.8, sense: convex, norm_radius: 3 mm, aperture: circle(radius: 3 mm), Q0: 1.5 um, Q1: -0.4 um, Q2: 0.2 um }
surface l = qcon { radius: 12 mm, conic: -0.8, sense: convex, norm_radius: 0.4 mm, aperture: circle(radius: 0.4 mm), Q1: 1 um }
surface a = grid(l, pitch_x: 1 mm, pitch_y: 1 mm, count_x: 2, count_y: 2)";
        let (x, y): (f64, f64) = (0.9, -2.2);
        let rho2 = x * x + y * y;
        let u2 = rho2 / 9.0;
        let (c, k) = (1.0 / 12.0, -0.8);
        let q = [1.0, -(5.0 - 6.0 * u2), 15.0 - 14.0 * u2 * (3.0 - 2.0 * u2)];
        let a = [1.5e-3, -0.4e-3, 0.2e-3];
        let sum: f64 = a.iter().zip(q).map(|(a, q)| a * q).sum();
        let sag = c * rho2 / (1.0 + (1.0 - (1.0 + k) * c * c * rho2).sqrt()) + u2 * u2 * sum;
        let got = eval_surface(src, "q", x, y)[0];
        assert!((got + sag).abs() < 1e-15, "{got} vs {}", -sag);
        // In an array the lenslet is the same surface about its centre, its
        // rim (ρ = 0.4 mm) at the land.
        let lens = |r2: f64| {
            let u2 = r2 / 0.16;
            c * r2 / (1.0 + (1.0 - (1.0 + k) * c * c * r2).sqrt())
                + u2 * u2 * 1e-3 * -(5.0 - 6.0 * u2)
        };
        let (dx, dy) = (0.1, -0.25);
        let want = lens(0.16) - lens(dx * dx + dy * dy);
        let got = eval_surface(src, "a", 0.5 + dx, 0.5 + dy)[0];
        assert!(close(got, want), "{got} vs {want}");
    }

    #[test]
    fn tilted_sphere_is_the_sphere_with_its_centre_turned() {
        // A concave sphere R = 5 mm (centre (0, 0, 5)) turned 10° about y has
        // its centre at (5 sin θ, 0, 5 cos θ); its lower cap is the height.
        let src =
            "surface s = sphere { radius: 5 mm, sense: concave, aperture: circle(radius: 2 mm) }
surface t = tilt(s, about: y, angle: 10 deg, aperture: circle(radius: 1.5 mm))
surface u = tilt(s, about: x, angle: -7 deg, aperture: circle(radius: 1.5 mm))";
        let th = 10f64.to_radians();
        let (xc, zc) = (5.0 * th.sin(), 5.0 * th.cos());
        for (x, y) in [(0.0, 0.0), (0.7, -0.4), (-1.1, 0.9)] {
            let o = eval_surface(src, "t", x, y);
            let d = (25.0 - (x - xc) * (x - xc) - y * y).sqrt();
            assert!(
                close(o[0], zc - d),
                "z at ({x}, {y}): {} vs {}",
                o[0],
                zc - d
            );
            assert!(
                close(o[1], (x - xc) / d),
                "dz/dx at ({x}, {y}): {} vs {}",
                o[1],
                (x - xc) / d
            );
            assert!(close(o[2], y / d), "dz/dy at ({x}, {y})");
        }
        // About x, right-handed: the centre (0, 0, 5) goes to (0, −5 sin φ, 5 cos φ).
        let ph = (-7f64).to_radians();
        let (yc, zc) = (-5.0 * ph.sin(), 5.0 * ph.cos());
        let (x, y) = (0.3, 0.8);
        let d = (25.0 - x * x - (y - yc) * (y - yc)).sqrt();
        assert!(close(eval_surface(src, "u", x, y)[0], zc - d));
    }
}
