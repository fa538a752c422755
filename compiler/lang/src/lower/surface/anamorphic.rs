//! Surfaces with different curvatures across and along: cylinder and
//! acylinder, biconic, toroid and ellipsoid.

use lensc_runtime::surface::ir::{Graph, Id};

use super::{LowerError, Side, add_power_terms, conic_sag, power_terms};
use crate::value::{self, Object};

/// A cylinder or acylinder: the conic profile (with its power terms)
/// across `axis`, extruded along it.
pub(super) fn cylinder_height(g: &mut Graph, o: &Object, x: Id, y: Id) -> Result<Id, LowerError> {
    let f = &o.fields;
    let side = Side::of(f);
    let k = value::num(f, "conic").unwrap_or(0.0);
    let c = side.curvature(value::num(f, "radius").ok_or(LowerError::Unsupported("radius"))?);
    // Extruded along `axis`: the profile varies across it.
    let u = if value::word(f, "axis") == Some("x") {
        y
    } else {
        x
    };
    let u2 = g.powi(u, 2);
    let sag = conic_sag(g, c, k, u2);
    let sag = add_power_terms(g, sag, u2, &power_terms(f));
    Ok(side.apply(g, sag))
}

/// A biconic: conic sections of their own radius and conic constant in x
/// and in y, in one sag formula.
pub(super) fn biconic_height(g: &mut Graph, o: &Object, x: Id, y: Id) -> Result<Id, LowerError> {
    let f = &o.fields;
    let side = Side::of(f);
    let cx = side.curvature(value::num(f, "radius_x").ok_or(LowerError::Unsupported("radius_x"))?);
    let cy = side.curvature(value::num(f, "radius_y").ok_or(LowerError::Unsupported("radius_y"))?);
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
    Ok(side.apply(g, sag))
}

/// A toroid: the y profile (conic and power terms) swept about an axis
/// parallel to y at `rotation_radius`.
pub(super) fn toroid_height(g: &mut Graph, o: &Object, x: Id, y: Id) -> Result<Id, LowerError> {
    let f = &o.fields;
    let side = Side::of(f);
    let k = value::num(f, "conic").unwrap_or(0.0);
    let c = side.curvature(value::num(f, "radius").ok_or(LowerError::Unsupported("radius"))?);
    let rr = value::num(f, "rotation_radius").ok_or(LowerError::Unsupported("rotation_radius"))?;
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
    Ok(side.apply(g, sag))
}

/// An ellipsoid cap: depth c·(1 − sqrt(1 − x²/a² − y²/b²)).
pub(super) fn ellipsoid_height(g: &mut Graph, o: &Object, x: Id, y: Id) -> Result<Id, LowerError> {
    let f = &o.fields;
    let side = Side::of(f);
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
    Ok(g.mul(cc, depth))
}
