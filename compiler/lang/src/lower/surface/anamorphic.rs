//! Surfaces with different curvatures across and along: cylinder and
//! acylinder, biconic, toroid and ellipsoid.

use lensc_runtime::surface::ir::{Graph, Id};

use super::{Side, add_power_terms, conic_sag};
use crate::schema::{Axis, Biconic, Cylinder, Ellipsoid, Toroid};

/// A cylinder or acylinder: the conic profile (with its power terms)
/// across `axis`, extruded along it.
pub(super) fn cylinder_height(g: &mut Graph, p: &Cylinder, x: Id, y: Id) -> Id {
    let side = Side::from(p.facing);
    let k = p.base.conic;
    let c = side.curvature(p.base.radius);
    // Extruded along `axis`: the profile varies across it.
    let u = match p.axis {
        Axis::X => y,
        Axis::Y => x,
    };
    let u2 = g.powi(u, 2);
    let sag = conic_sag(g, c, k, u2);
    let sag = add_power_terms(g, sag, u2, &p.terms);
    side.apply(g, sag)
}

/// A biconic: conic sections of their own radius and conic constant in x
/// and in y, in one sag formula.
pub(super) fn biconic_height(g: &mut Graph, p: &Biconic, x: Id, y: Id) -> Id {
    let side = Side::from(p.facing);
    let cx = side.curvature(p.radius_x);
    let cy = side.curvature(p.radius_y);
    let (kx, ky) = (p.conic_x, p.conic_y);
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
    side.apply(g, sag)
}

/// A toroid: the y profile (conic and power terms) swept about an axis
/// parallel to y at `rotation_radius`.
pub(super) fn toroid_height(g: &mut Graph, p: &Toroid, x: Id, y: Id) -> Id {
    let side = Side::from(p.facing);
    let k = p.base.conic;
    let c = side.curvature(p.base.radius);
    let rr = p.rotation_radius;
    // The rotation axis lies on the profile's side of the vertex.
    let rr = if c < 0.0 { -rr } else { rr };
    let y2 = g.powi(y, 2);
    let zy = conic_sag(g, c, k, y2);
    let zy = add_power_terms(g, zy, y2, &p.terms);
    let x2 = g.powi(x, 2);
    let r = g.constant_node(rr);
    let d = g.sub(r, zy);
    let d2 = g.powi(d, 2);
    let under = g.sub(d2, x2);
    let root = g.sqrt(under);
    // z = Rr − sign(Rr) sqrt((Rr − z_y)² − x²), written without the
    // cancellation of two near-equal terms (a sag of 0.1 µm under a 76 mm
    // radius of rotation kept only ten digits):
    // z = (2 Rr z_y − z_y² + x²) / (Rr + sign(Rr) sqrt(…)).
    let signed_root = if rr < 0.0 { g.neg(root) } else { root };
    let two_r = g.constant_node(2.0 * rr);
    let t = g.mul(two_r, zy);
    let zy2 = g.powi(zy, 2);
    let t = g.sub(t, zy2);
    let numerator = g.add(t, x2);
    let denominator = g.add(r, signed_root);
    let sag = g.div(numerator, denominator);
    side.apply(g, sag)
}

/// An ellipsoid cap: depth c·(1 − sqrt(1 − x²/a² − y²/b²)).
pub(super) fn ellipsoid_height(g: &mut Graph, p: &Ellipsoid, x: Id, y: Id) -> Id {
    let side = Side::from(p.facing);
    let (a, b, c) = (p.a, p.b, p.c);
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
