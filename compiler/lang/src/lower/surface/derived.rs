//! Surfaces built from another at moved coordinates: a design wrapped
//! onto a roller, a profile revolved, an off-axis section, a tilted surface.

use lensc_runtime::surface::ir::{Graph, Id, SurfaceTape};

use super::{LowerError, height, radius_squared};
use crate::value::{self, Object};

/// A wrapped design: the flat design's height; the roller only maps y to
/// the arc around it.
pub(super) fn wrap_height(g: &mut Graph, o: &Object, x: Id, y: Id) -> Result<Id, LowerError> {
    let f = &o.fields;
    // The flat design; the roller only maps y to the arc around it.
    let design =
        value::object(f, "surface").ok_or(LowerError::Unsupported("wrap without a design"))?;
    height(g, design, x, y)
}

/// A profile revolved about z: its height at u = start + r, v = 0.
pub(super) fn revolve_height(g: &mut Graph, o: &Object, x: Id, y: Id) -> Result<Id, LowerError> {
    let f = &o.fields;
    let profile =
        value::object(f, "profile").ok_or(LowerError::Unsupported("revolve without a profile"))?;
    let start = g.constant_node(value::num(f, "start").unwrap_or(0.0));
    let r2 = radius_squared(g, x, y);
    let r = g.sqrt(r2);
    let u = g.add(start, r);
    let zero = g.constant_node(0.0);
    height(g, profile, u, zero)
}

/// An off-axis section: the parent moved to the section's centre, less
/// its height there (and its slope, with `tilt: remove`).
pub(super) fn off_axis_height(g: &mut Graph, o: &Object, x: Id, y: Id) -> Result<Id, LowerError> {
    let f = &o.fields;
    let parent =
        value::object(f, "parent").ok_or(LowerError::Unsupported("off_axis without a parent"))?;
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
    Ok(z)
}

/// A parent surface turned by θ about the y (or x) axis through its vertex.
/// A parent point (p, q, z(p, q)) lands at P = p cosθ + z sinθ over the
/// turning direction, Z = −p sinθ + z cosθ. For the machine coordinate P
/// the parent coordinate p solves p cosθ + z(p, q) sinθ = P: Newton's
/// method, unrolled six times in the graph from p = P cosθ, converges
/// quadratically to machine precision for the gentle tilts allowed
/// (|θ| < 45°), and the derivatives flow through the iterations.
pub(super) fn tilted_height(g: &mut Graph, o: &Object, x: Id, y: Id) -> Result<Id, LowerError> {
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
