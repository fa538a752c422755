//! A raster job's point count and program size, estimated before planning
//! (`job::estimate`).

use lensc_runtime::plan::optimise::{CHORD_SHARE, FIT_SHARE};
use lensc_runtime::surface::analysis::Domain;

use crate::job::Evaluate;
use crate::job::estimate::{Curve, Estimate, centre_curve, chord_for, chords};

/// Bytes of one motion block (measured on the examples).
const RASTER_BLOCK: f64 = 37.0;
/// A raster pass's own moves: over, down and up (short words).
const RASTER_PASS: f64 = 3.0 * 17.0;

/// A raster: a pass per span of each plane the planner cuts, the rim's
/// planes beyond the aperture and each pass's run on to the rim's reach
/// included (the planes lowering's scan found, `check_raster_planes`),
/// each bisected from its whole span until its chords meet the chords'
/// share of the tolerance, `max_step` and Lin's step; passes sampled up
/// to 256, each at the spacing of 512 points across the aperture along
/// the cut.
pub(crate) fn estimate(s: &super::RasterSpec, evaluate: Evaluate) -> Estimate {
    use lensc_runtime::plan::raster::{Axis, lin_step, section_radius};
    const PASSES: usize = 256;
    const ALONG: usize = 512;
    let r = &s.raster;
    let k = evaluate(&s.head.surface.lowered.tape);
    let rho = s.tool.radius();
    let domain = &s.head.surface.lowered.domain;
    let ((x0, x1), (y0, y1)) = bounds(domain);
    let (u0, u1) = match r.along {
        Axis::X => (x0, x1),
        Axis::Y => (y0, y1),
    };
    let scan = &s.planes;
    let stride = scan.planes.len().div_ceil(PASSES).max(1);
    let sampled = scan.planes.len().div_ceil(stride);
    let weight = scan.weight * scan.planes.len() as f64 / sampled.max(1) as f64;
    let tol = r.chord_tolerance * CHORD_SHARE;
    let xy = |u: f64, v: f64| match r.along {
        Axis::X => (u, v),
        Axis::Y => (v, u),
    };
    let spacing = (u1 - u0) / ALONG as f64;
    let (mut points, mut bytes) = (0.0, 0.0);
    for (_, spans) in scan.planes.iter().step_by(stride) {
        for &[(ua, va), (ub, vb)] in spans {
            // The pass from its first contact to its last, sampled at
            // about `spacing`.
            let span = ub - ua;
            let steps = (span / spacing).ceil().clamp(1.0, 4.0 * ALONG as f64);
            let du = span / steps;
            let mut curve = Curve {
                ds: Vec::new(),
                kappa: Vec::new(),
            };
            let mut n = 1.0;
            for i in 0..=steps as usize {
                let t = i as f64 / steps;
                let (x, y) = xy(ua + span * t, va + (vb - va) * t);
                let o = k.eval(x, y);
                let (zu, zuu) = match r.along {
                    Axis::X => (o[1], o[3]),
                    Axis::Y => (o[2], o[5]),
                };
                let (kappa, offset) = centre_curve(zu, zuu, rho);
                let stretch = (1.0 + zu * zu).sqrt() * offset;
                let mut h = chord_for(kappa, tol) / stretch;
                if let Some(m) = r.max_step {
                    h = h.min(m / stretch);
                }
                if let Some(alpha) = r.lin_angle {
                    let lin = lin_step(section_radius(zu, zuu), alpha, zu);
                    if lin.is_finite() && lin > 0.0 {
                        h = h.min(lin);
                    }
                }
                if i > 0 {
                    n += chords(du, span, h);
                }
                curve.ds.push(if i == 0 { 0.0 } else { du * stretch });
                curve.kappa.push(kappa);
            }
            points += weight * n;
            let arcs = curve.arcs(r.chord_tolerance * FIT_SHARE).min(n);
            bytes += weight * (RASTER_PASS + arcs * RASTER_BLOCK);
        }
    }
    Estimate {
        servo_samples: 0.0,
        points,
        program_bytes: bytes,
        driver: "chord_tolerance",
    }
}

/// The box (x, y) around a domain.
fn bounds(d: &Domain) -> ((f64, f64), (f64, f64)) {
    match *d {
        Domain::Circle { radius } | Domain::Annulus { outer: radius, .. } => {
            ((-radius, radius), (-radius, radius))
        }
        Domain::Rect { x, y } => (x, y),
    }
}
