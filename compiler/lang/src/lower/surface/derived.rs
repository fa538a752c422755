//! Surfaces built from another at moved coordinates: a design wrapped
//! onto a roller, a profile revolved, an off-axis section, a tilted surface.

use lensc_runtime::surface::ir::{Graph, Id, SurfaceTape, Unary, Var};

use super::{LowerError, height, radius_squared};
use crate::schema::{self, Axis, OffAxis, Revolve, Surface, Wrap};

/// A wrapped design: the flat design's height; the roller only maps y to
/// the arc around it.
pub(super) fn wrap_height(g: &mut Graph, p: &Wrap, x: Id, y: Id) -> Result<Id, LowerError> {
    height(g, &p.surface, x, y)
}

/// A profile revolved about z: its height at u = start + r, v = 0.
pub(super) fn revolve_height(g: &mut Graph, p: &Revolve, x: Id, y: Id) -> Result<Id, LowerError> {
    let at = revolved_at(g, p, x, y);
    height(g, at.profile, at.u, at.zero)
}

/// Where a revolved profile is read at (x, y): the profile, r, u = start +
/// r and the constant 0 (its v).
struct RevolvedAt<'p> {
    profile: &'p Surface,
    r: Id,
    u: Id,
    zero: Id,
}

fn revolved_at<'p>(g: &mut Graph, p: &'p Revolve, x: Id, y: Id) -> RevolvedAt<'p> {
    let start = g.constant_node(p.start);
    let r2 = radius_squared(g, x, y);
    let r = g.sqrt(r2);
    let u = g.add(start, r);
    let zero = g.constant_node(0.0);
    RevolvedAt {
        profile: &p.profile,
        r,
        u,
        zero,
    }
}

/// The six outputs of a revolved profile (the order of
/// `SurfaceTape::outputs`) by the chain rule through u = start + r: with
/// the profile's f, f′ and f″ along its own x at (u, 0) — an array's from
/// its closed forms (`arrays::array_outputs`), any other profile's
/// differentiated in a scratch graph — and (a, b) = (x, y)/r,
///
/// ```text
/// z_x = f′ a    z_xx = f″ a² + f′ b²/r    z_xy = (f″ − f′/r) a b
/// z_y = f′ b    z_yy = f″ b² + f′ a²/r
/// ```
///
/// rather than differentiating the profile's height through the square
/// root twice (the rings of `examples/lei2021_cylinder_array.lens`: 174 →
/// 107 live nodes). z is `revolve_height`'s, node for node. On the axis
/// (r = 0) the limits where the profile is level there (slopes 0, both
/// curvatures f″; a land's all 0, as the graph's selects gave) and NaN
/// where it is not, as at a cone's tip.
pub(super) fn revolved_outputs(
    g: &mut Graph,
    p: &Revolve,
    x: Id,
    y: Id,
) -> Result<[Id; 6], LowerError> {
    let RevolvedAt {
        profile,
        r,
        u,
        zero,
    } = revolved_at(g, p, x, y);
    // The profile over (u, v), in a scratch graph, at v = 0.
    let mut h = Graph::new();
    let (hu, hv) = (h.x(), h.constant_node(0.0));
    let (hz, hzu, hzuu) = if let Surface::Array(array) = profile {
        let [z, zu, _, zuu, _, _] = super::arrays::array_outputs(&mut h, array, hu, hv)?;
        (z, zu, zuu)
    } else {
        let z = height(&mut h, profile, hu, hv)?;
        let zu = h.derivative(z, Var::X);
        let zuu = h.derivative(zu, Var::X);
        (z, zu, zuu)
    };
    let map = g.import(&h, u, zero);
    let (z, f1, f2) = (
        map[hz.0 as usize],
        map[hzu.0 as usize],
        map[hzuu.0 as usize],
    );
    // Off the axis (−r < 0) the closed forms; on it, the limits where the
    // profile is level there (f′ = 0: slopes 0, both curvatures f″) and
    // NaN where it is not (a cone's tip has no slope).
    let off_axis = g.neg(r);
    let level = {
        let m = g.unary(Unary::Abs, f1);
        g.neg(m)
    };
    let nan = g.constant_node(f64::NAN);
    let tip = g.select(level, nan, zero);
    let a = {
        let q = g.div(x, r);
        g.select(off_axis, q, tip)
    };
    let b = {
        let q = g.div(y, r);
        g.select(off_axis, q, tip)
    };
    let zx = g.mul(f1, a);
    let zy = g.mul(f1, b);
    let f1r = {
        let q = g.div(f1, r);
        g.select(off_axis, q, f2)
    };
    // On the axis a² = 1, b² = 0 (so z_xx = z_yy = f″), or NaN at a tip.
    let a2 = {
        let q = g.mul(a, a);
        let one = g.constant_node(1.0);
        let tip_one = g.select(level, nan, one);
        g.select(off_axis, q, tip_one)
    };
    let b2 = g.mul(b, b);
    let ab = g.mul(a, b);
    let zxx = {
        let t = g.mul(f2, a2);
        let s = g.mul(f1r, b2);
        g.add(t, s)
    };
    let zyy = {
        let t = g.mul(f2, b2);
        let s = g.mul(f1r, a2);
        g.add(t, s)
    };
    let zxy = {
        let d = g.sub(f2, f1r);
        g.mul(d, ab)
    };
    Ok([z, zx, zy, zxx, zxy, zyy])
}

/// An off-axis section: the parent moved to the section's centre, less
/// its height there; with `tilt: remove`, that section turned rigidly
/// until its normal at the centre is along z (`tilt_removed`).
pub(super) fn off_axis_height(g: &mut Graph, p: &OffAxis, x: Id, y: Id) -> Result<Id, LowerError> {
    if p.remove_tilt {
        return tilt_removed(g, p, x, y);
    }
    let parent = &p.parent;
    let (x0, y0) = (p.x, p.y);
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
    Ok(g.sub(zp, z0))
}

/// The largest slope at a section's centre whose tilt `tilt: remove`
/// takes off (45°): the tilt's Newton steps converge for turns under it.
pub const MAX_REMOVED_TILT: f64 = std::f64::consts::FRAC_PI_4;

/// `tilt: remove`: the section (the parent moved to the centre, level
/// there) turned rigidly so that its normal at the centre is along z:
/// about y by atan(s_x), which leaves a slope s_y / sqrt(1 + s_x²) along
/// y, then about x by that slope's angle (each a `tilt`, solved exactly
/// by Newton's method). The exact tilted segment, not the small-angle
/// shear z − s_x x − s_y y, which is off by about z·(1 − cos θ) plus the
/// sag's shift along the slope (36 µm at 12 mm for 14°). A section
/// sloping 45° or more at its centre is refused.
fn tilt_removed(g: &mut Graph, p: &OffAxis, x: Id, y: Id) -> Result<Id, LowerError> {
    let level = OffAxis {
        remove_tilt: false,
        ..p.clone()
    };
    // The slope at the centre of the level section.
    let mut h = Graph::new();
    let (hx, hy) = (h.x(), h.y());
    let hz = off_axis_height(&mut h, &level, hx, hy)?;
    let at = lensc_runtime::surface::ir::Interpreter::new(&SurfaceTape::new(h, hz));
    let o = lensc_runtime::surface::ir::SurfaceFn::eval(&at, 0.0, 0.0);
    let (sx, sy) = (o[1], o[2]);
    let angle = sx.hypot(sy).atan();
    if angle.is_nan() || angle >= MAX_REMOVED_TILT {
        return Err(LowerError::Unsupported(
            "`tilt: remove` of a section sloping 45° or more at its centre",
        ));
    }
    let mut surface = Surface::OffAxis(level);
    if sx != 0.0 {
        surface = Surface::Tilt(schema::Tilt {
            parent: Box::new(surface),
            about: Axis::Y,
            angle: sx.atan(),
            aperture: p.aperture,
        });
    }
    let sy_left = sy / sx.hypot(1.0);
    if sy_left != 0.0 {
        // A positive turn about x lifts +y: turning by −atan(s) levels a
        // slope s along y.
        surface = Surface::Tilt(schema::Tilt {
            parent: Box::new(surface),
            about: Axis::X,
            angle: -sy_left.atan(),
            aperture: p.aperture,
        });
    }
    height(g, &surface, x, y)
}

/// A parent surface turned by θ about the y (or x) axis through its vertex.
/// A parent point (p, q, z(p, q)) lands at P = p cosθ + z sinθ over the
/// turning direction, Z = −p sinθ + z cosθ. For the machine coordinate P
/// the parent coordinate p solves p cosθ + z(p, q) sinθ = P: Newton's
/// method, unrolled six times in the graph from p = P cosθ, converges
/// quadratically to machine precision for the gentle tilts allowed
/// (|θ| < 45°), and the derivatives flow through the iterations (used
/// where the tilt is part of another surface; a tilted surface of its own
/// has its derivatives in closed form, `tilted_outputs`).
pub(super) fn tilted_height(
    g: &mut Graph,
    p: &schema::Tilt,
    x: Id,
    y: Id,
) -> Result<Id, LowerError> {
    let t = Tilt::solve(g, p, x, y, Steps::WrittenOut)?;
    Ok(t.height(g))
}

/// The six outputs of a tilted surface (z, its slopes and curvatures, in
/// the order of `SurfaceTape::outputs`): z is `tilted_height`'s, the same
/// nodes; the derivatives are the implicit function theorem's at the
/// solved parent point rather than derivatives of the six Newton steps.
/// With D = cosθ + z_p sinθ (the residual's slope, never small for
/// |θ| < 45° and slopes under 45°) and the parent's derivatives at (p, q):
///
/// ```text
/// Z_P = (z_p cosθ − sinθ) / D        Z_q = z_q / D
/// Z_PP = z_pp / D³                   Z_Pq = m / D²,  m = z_pp p_q + z_pq
/// Z_qq = ((z_pq p_q + z_qq) D − z_q sinθ m) / D²,  p_q = −z_q sinθ / D
/// ```
///
/// (P is x for a turn about y, y for a turn about x.) The same values as
/// the derivatives through the converged iterations to within rounding,
/// from about a tenth of the nodes (the tilted lens of
/// `examples/off_axis_and_tilt.lens`: 1760 live nodes → ~200), so a
/// fraction of the compile and evaluation time. Nothing differentiates
/// the steps here, so they are one loop (`Steps::Loop`), its body in the
/// graph once: the same values, a sixth of Newton's nodes.
pub(super) fn tilted_outputs(
    g: &mut Graph,
    p: &schema::Tilt,
    x: Id,
    y: Id,
) -> Result<[Id; 6], LowerError> {
    tilted_outputs_with(g, p, x, y, Steps::Loop)
}

/// `tilted_outputs` with the Newton steps put in the graph as `steps`
/// says (the same values either way).
pub(super) fn tilted_outputs_with(
    g: &mut Graph,
    p: &schema::Tilt,
    x: Id,
    y: Id,
    steps: Steps,
) -> Result<[Id; 6], LowerError> {
    let mut t = Tilt::solve(g, p, x, y, steps)?;
    let z = t.height(g);
    let h = &mut t.parent;
    let hzq = h.derivative(t.hz, Var::Y);
    let hzpp = h.derivative(t.hzp, Var::X);
    let hzpq = h.derivative(t.hzp, Var::Y);
    let hzqq = h.derivative(hzq, Var::Y);
    let map = g.import(h, t.p, t.q);
    let at = |i: Id| map[i.0 as usize];
    let (zp, zq, zpp, zpq, zqq) = (at(t.hzp), at(hzq), at(hzpp), at(hzpq), at(hzqq));
    let (c, s) = (t.cos, t.sin);
    // D = cosθ + z_p sinθ, as the Newton steps write it.
    let zps = g.mul(zp, s);
    let d = g.add(c, zps);
    let d2 = g.mul(d, d);
    let d3 = g.mul(d2, d);
    let zpc = g.mul(zp, c);
    let a = g.sub(zpc, s);
    let z_big_p = g.div(a, d);
    let z_q = g.div(zq, d);
    let z_pp = g.div(zpp, d3);
    // p_q = −z_q sinθ / D; m = z_pp p_q + z_pq.
    let zqs = g.mul(zq, s);
    let ratio = g.div(zqs, d);
    let p_q = g.neg(ratio);
    let zpp_pq = g.mul(zpp, p_q);
    let m = g.add(zpp_pq, zpq);
    let z_pq = g.div(m, d2);
    let zpq_pq = g.mul(zpq, p_q);
    let n = g.add(zpq_pq, zqq);
    let nd = g.mul(n, d);
    let zqsm = g.mul(zqs, m);
    let num = g.sub(nd, zqsm);
    let z_qq = g.div(num, d2);
    Ok(if t.about_x {
        // P = y, q = x.
        [z, z_q, z_big_p, z_qq, z_pq, z_pp]
    } else {
        [z, z_big_p, z_q, z_pp, z_pq, z_qq]
    })
}

/// How a tilt's Newton steps are put in the graph; either way the same
/// operations in the same order, so the same bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Steps {
    /// One after another, each a copy: what a derivative of the height
    /// goes through (a tilt inside another surface).
    WrittenOut,
    /// One loop (`Graph::repeat`), the body once: a surface of its own,
    /// whose derivatives are in closed form.
    Loop,
}

/// The Newton steps of a tilt (|θ| < 45°, from p = P cosθ: converged to
/// machine precision).
const NEWTON_STEPS: u32 = 6;

/// A tilt's parent coordinate solved by Newton's method in a graph.
struct Tilt {
    /// The parent's height over (p, q) = (turning coordinate, the other
    /// one), in a scratch graph, with its slope along p.
    parent: Graph,
    hz: Id,
    hzp: Id,
    /// The solved parent coordinates, nodes of the surface's graph.
    p: Id,
    q: Id,
    /// cosθ and sinθ (signed for the turning direction), constant nodes.
    cos: Id,
    sin: Id,
    about_x: bool,
}

impl Tilt {
    fn solve(
        g: &mut Graph,
        p: &schema::Tilt,
        x: Id,
        y: Id,
        steps: Steps,
    ) -> Result<Tilt, LowerError> {
        let parent = &p.parent;
        let theta = p.angle;
        let about_x = p.about == Axis::X;
        // Turning about y moves x; about x moves y, with the sign of the
        // right-hand rule (a positive turn about x lifts +y).
        let (cos, sin) = (
            theta.cos(),
            if about_x { -theta.sin() } else { theta.sin() },
        );
        // The parent and its slope along the turning direction, in a
        // scratch graph over (p, q) = (turning coordinate, the other one).
        let mut h = Graph::new();
        let (hp, hq) = (h.x(), h.y());
        let (hx, hy) = if about_x { (hq, hp) } else { (hp, hq) };
        let hz = height(&mut h, parent, hx, hy)?;
        let hzp = h.derivative(hz, Var::X);
        let (big_p, q) = if about_x { (y, x) } else { (x, y) };
        let c = g.constant_node(cos);
        let sn = g.constant_node(sin);
        let newton = |g: &mut Graph, p: Id| {
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
            g.sub(p, step)
        };
        let start = g.mul(big_p, c);
        // No turn (sin θ = 0): the steps written out fold to p = P, which
        // a loop's body, over an unknown estimate, could not.
        let p = if steps == Steps::Loop && sin != 0.0 {
            let estimate = g.carried();
            let next = newton(g, estimate);
            g.repeat(estimate, start, next, NEWTON_STEPS)
        } else {
            (0..NEWTON_STEPS).fold(start, |p, _| newton(g, p))
        };
        Ok(Tilt {
            parent: h,
            hz,
            hzp,
            p,
            q,
            cos: c,
            sin: sn,
            about_x,
        })
    }

    /// Z = −p sinθ + z(p, q) cosθ at the solved point.
    fn height(&self, g: &mut Graph) -> Id {
        let map = g.import(&self.parent, self.p, self.q);
        let z = map[self.hz.0 as usize];
        let ps = g.mul(self.p, self.sin);
        let zc = g.mul(z, self.cos);
        g.sub(zc, ps)
    }
}
