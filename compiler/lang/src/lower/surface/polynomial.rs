//! Polynomial surfaces: x-y polynomials and Zernike expansions.

use lensc_runtime::surface::ir::{Graph, Id};

use super::{LowerError, Side, conic_sag, radius_squared};
use crate::schema::{Base, Ordering, XyPolynomial, Zernike};

/// An x-y polynomial: the base conic (if a radius is given) plus
/// Σ c_ij x^i y^j, in order of the powers.
pub(super) fn xy_polynomial_height(g: &mut Graph, p: &XyPolynomial, x: Id, y: Id) -> Id {
    let side = Side::from(p.facing);
    let mut sag = base_conic(g, p.base, side, x, y);
    for &(i, j, cij) in &p.terms {
        let xi = g.powi(x, i as i32);
        let yj = g.powi(y, j as i32);
        let m = g.mul(xi, yj);
        let cc = g.constant_node(cij);
        let t = g.mul(cc, m);
        sag = g.add(sag, t);
    }
    side.apply(g, sag)
}

/// The base conic of a polynomial surface in r² = x² + y²: zero when no
/// `radius` is given.
fn base_conic(g: &mut Graph, base: Option<Base>, side: Side, x: Id, y: Id) -> Id {
    let r2 = radius_squared(g, x, y);
    match base {
        Some(Base { radius, conic }) => conic_sag(g, side.curvature(radius), conic, r2),
        None => g.constant_node(0.0),
    }
}

/// A Zernike surface: the base conic (if a radius is given) plus the terms
/// over ρ = r / `norm_radius`, in the fringe or ANSI numbering.
pub(super) fn zernike_height(g: &mut Graph, p: &Zernike, x: Id, y: Id) -> Result<Id, LowerError> {
    let side = Side::from(p.facing);
    let mut sag = base_conic(g, p.base, side, x, y);
    let norm = p.norm_radius;
    let ansi = p.ordering == Ordering::Ansi;
    for &(j, coef) in &p.terms {
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
    Ok(side.apply(g, sag))
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
