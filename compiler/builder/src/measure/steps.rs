//! Stepped rims: registering a map of an array whose lenslets meet the
//! land at a step instead of in a valley (a biconic clipped to a circle
//! has its rim on the land along one axis and stands 12 µm off it along
//! the other). Least squares on heights cannot follow a pixel across a
//! step: the design's slope there says nothing of it, so the fit is
//! pulled by the pixels that cross it (a clocking 72 µrad wrong) or does
//! not settle at all (E0365). The pixels within a stated distance of a
//! stepped rim are left out of the fit: three pixels either side of the
//! rim where the registration ends, and while the placement is still
//! moving, twice the distance the last fit moved it; each fit starts
//! where the last ended. The rims step where the design just inside and
//! just outside them differs by more than a nanometre; an array whose
//! rims meet the land smoothly is registered on every pixel, as before.

use lensc_measure::register::{self, Options as Fit, RegisterError, Registration};
use lensc_runtime::surface::analysis::Domain;
use lensc_runtime::surface::ir::SurfaceFn;
use lensc_runtime::verify::lenslets::Lenslets;

/// A rim steps where the design either side of it differs by more than
/// this (mm): 1 nm.
pub const STEP: f64 = 1e-6;

/// How far either side of a stepped rim the pixels are left out of the
/// fit where the registration ends, in pixels (an assumption of ours: a
/// pixel's value is its centre's height, and an instrument's lateral
/// resolution spreads a step over a pixel or two).
pub const BAND_PIXELS: f64 = 3.0;

/// How far either side of a rim (mm) the design is compared: 0.1 nm, so
/// that a rim slope of 1 moves the height by 0.2 nm, well under `STEP`.
const ACROSS: f64 = 1e-7;

/// Points compared along each rim (a circle's, or a rectangle's side).
const ALONG: usize = 360;

/// At most this many fits, each from where the last ended.
const ROUNDS: usize = 5;

/// An array's rims that step onto the land.
pub struct SteppedRims {
    /// The lenslets, each holding its aperture widened half again: a
    /// pixel is held to the rim of the lenslet that holds it so.
    near: Lenslets,
    aperture: Domain,
    /// The largest step found (mm).
    pub largest: f64,
}

impl SteppedRims {
    /// The rims of `lenslets` on the design `f` (the whole array, in the
    /// part's x and y) that step by more than `STEP` anywhere; `None`
    /// where every rim meets the land within it.
    pub fn of(f: &dyn SurfaceFn, lenslets: &Lenslets) -> Option<SteppedRims> {
        let aperture = lenslets.aperture();
        let rim = rim_points(&aperture);
        let mut largest = 0.0f64;
        for &(cx, cy) in lenslets.centres() {
            for &(x, y, nx, ny) in &rim {
                let inside = f.eval(cx + x - ACROSS * nx, cy + y - ACROSS * ny)[0];
                let outside = f.eval(cx + x + ACROSS * nx, cy + y + ACROSS * ny)[0];
                let step = (outside - inside).abs();
                if step.is_finite() {
                    largest = largest.max(step);
                }
            }
        }
        (largest > STEP).then(|| SteppedRims {
            near: lenslets.widened(1.5).unwrap_or_else(|| lenslets.clone()),
            aperture,
            largest,
        })
    }

    /// The registration's method says so: the pixels within `band` (mm)
    /// of the rims left out.
    pub fn words(&self, band: f64) -> String {
        format!(
            ", leaving out the pixels within {:.1} µm of the lenslets' rims, which step onto the land by up to {:.1} µm",
            band * 1000.0,
            self.largest * 1000.0
        )
    }

    /// How far (mm) the part's point (x, y) lies from the rim of the
    /// lenslet whose aperture, widened half again, holds it; infinite
    /// elsewhere (on the land, farther than half an aperture from a rim).
    pub fn distance(&self, x: f64, y: f64) -> f64 {
        match self.near.which(x, y) {
            Some(k) => {
                let c = self.near.centre(k);
                from_rim(&self.aperture, x - c.0, y - c.1)
            }
            None => f64::INFINITY,
        }
    }
}

/// Points on an aperture's rim about its centre, with the rim's outward
/// normal there: (x, y, nx, ny).
fn rim_points(d: &Domain) -> Vec<(f64, f64, f64, f64)> {
    let circle = |r: f64, out: f64| {
        (0..ALONG).map(move |i| {
            let (s, c) = (std::f64::consts::TAU * i as f64 / ALONG as f64).sin_cos();
            (r * c, r * s, out * c, out * s)
        })
    };
    match *d {
        Domain::Circle { radius } => circle(radius, 1.0).collect(),
        Domain::Annulus { inner, outer } => circle(outer, 1.0).chain(circle(inner, -1.0)).collect(),
        Domain::Rect { x, y } => {
            // Each side's points short of its corners.
            let t = |i: usize| (i as f64 + 0.5) / ALONG as f64;
            let mut out = Vec::with_capacity(4 * ALONG);
            for i in 0..ALONG {
                let (u, v) = (x.0 + t(i) * (x.1 - x.0), y.0 + t(i) * (y.1 - y.0));
                out.push((u, y.0, 0.0, -1.0));
                out.push((u, y.1, 0.0, 1.0));
                out.push((x.0, v, -1.0, 0.0));
                out.push((x.1, v, 1.0, 0.0));
            }
            out
        }
    }
}

/// How far (mm) the point (u, v) about an aperture's centre lies from its
/// rim, inside or out.
fn from_rim(d: &Domain, u: f64, v: f64) -> f64 {
    match *d {
        Domain::Circle { radius } => (u.hypot(v) - radius).abs(),
        Domain::Annulus { inner, outer } => {
            let r = u.hypot(v);
            (r - outer).abs().min((r - inner).abs())
        }
        Domain::Rect { x, y } => {
            let dx = (x.0 - u).max(u - x.1);
            let dy = (y.0 - v).max(v - y.1);
            if dx <= 0.0 && dy <= 0.0 {
                // Inside: the nearest side.
                (-dx).min(-dy)
            } else {
                dx.max(0.0).hypot(dy.max(0.0))
            }
        }
    }
}

/// A registration of heights to the design (`register::register_heights`
/// or its parallel form) under the given options.
pub(crate) type HeightFit<'a> =
    dyn Fn(&[[f64; 3]], Fit) -> Result<Registration, RegisterError> + 'a;

/// Registers the heights `pts` to the design by `heights` (the design's
/// `register::register_heights`, or its parallel form), leaving out the pixels (`pixel`
/// apart, mm) near the stepped rims `rims`, if any: a point (u, v) of
/// `f`'s frame lies at (u, v) + `origin` on the part. Each fit leaves out
/// the pixels within `band` of a rim where its start places them (three
/// pixels at first); a fit that moved no point by more than half that
/// band is the registration; otherwise the next starts where it ended,
/// its band twice the farthest move (and at least three pixels). The
/// registration, and the band of its last fit (none without rims).
pub(crate) fn register_clear(
    heights: &HeightFit,
    pts: &[[f64; 3]],
    fit: Fit,
    rims: Option<(&SteppedRims, (f64, f64))>,
    pixel: f64,
) -> Result<(Registration, Option<f64>), RegisterError> {
    let Some((rims, origin)) = rims else {
        return heights(pts, fit).map(|r| (r, None));
    };
    let least = BAND_PIXELS * pixel;
    let mut band = least;
    let mut start = fit.start;
    let mut iterations = 0;
    for _ in 0..ROUNDS {
        let (us, vs) = register::moved(pts, &start);
        let kept: Vec<[f64; 3]> = pts
            .iter()
            .zip(us.iter().zip(&vs))
            .filter(|(_, (u, v))| rims.distance(*u + origin.0, *v + origin.1) > band)
            .map(|(q, _)| *q)
            .collect();
        let mut reg = heights(&kept, Fit { start, ..fit })?;
        iterations += reg.iterations;
        let (u2, v2) = register::moved(&kept, &reg.values);
        let (u1, v1) = register::moved(&kept, &start);
        let moved = (0..kept.len())
            .map(|k| (u2[k] - u1[k]).hypot(v2[k] - v1[k]))
            .fold(0.0f64, f64::max);
        if moved <= band / 2.0 {
            reg.iterations = iterations;
            return Ok((reg, Some(band)));
        }
        start = reg.values;
        band = least.max(2.0 * moved);
    }
    Err(RegisterError::NotConverged {
        iterations,
        rms: f64::NAN,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distance_from_a_rim_inside_and_out() {
        let disc = Domain::Circle { radius: 1.0 };
        assert!((from_rim(&disc, 0.3, 0.4) - 0.5).abs() < 1e-15);
        assert!((from_rim(&disc, 0.0, 1.25) - 0.25).abs() < 1e-15);
        let ring = Domain::Annulus {
            inner: 0.5,
            outer: 1.0,
        };
        assert!((from_rim(&ring, 0.6, 0.0) - 0.1).abs() < 1e-15);
        assert!((from_rim(&ring, 0.0, 0.0) - 0.5).abs() < 1e-15);
        let rect = Domain::Rect {
            x: (-1.0, 1.0),
            y: (-0.5, 0.5),
        };
        assert!((from_rim(&rect, 0.9, 0.0) - 0.1).abs() < 1e-15);
        assert!((from_rim(&rect, 0.0, 0.2) - 0.3).abs() < 1e-15);
        assert!((from_rim(&rect, 1.3, 0.9) - 0.5).abs() < 1e-15);
    }
}
