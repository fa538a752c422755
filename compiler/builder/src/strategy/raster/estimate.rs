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

/// A raster: a pass per stepover across the aperture, each bisected from
/// its whole span until its chords meet the chords' share of the
/// tolerance, `max_step` and Lin's step; passes sampled up to 256, each
/// at 512 points along the cut.
pub(crate) fn estimate(s: &super::RasterSpec, evaluate: Evaluate) -> Estimate {
    use lensc_runtime::plan::raster::{Axis, lin_step, section_radius};
    const PASSES: usize = 256;
    const ALONG: usize = 512;
    let r = &s.raster;
    let k = evaluate(&s.head.surface.lowered.tape);
    let rho = s.tool.radius();
    let ((x0, x1), (y0, y1)) = bounds(&s.head.surface.lowered.domain);
    let ((u0, u1), (v0, v1)) = match r.along {
        Axis::X => ((x0, x1), (y0, y1)),
        Axis::Y => ((y0, y1), (x0, x1)),
    };
    let planes = ((v1 - v0) / r.stepover + 1e-9).floor() + 1.0;
    if !planes.is_finite() || planes > 1e9 {
        return Estimate {
            servo_samples: 0.0,
            points: f64::INFINITY,
            program_bytes: f64::INFINITY,
            driver: "stepover",
        };
    }
    let sampled = (planes as usize).clamp(1, PASSES);
    let weight = planes / sampled as f64;
    let tol = r.chord_tolerance * CHORD_SHARE;
    let xy = |u: f64, v: f64| match r.along {
        Axis::X => (u, v),
        Axis::Y => (v, u),
    };
    let (mut points, mut bytes) = (0.0, 0.0);
    for j in 0..sampled {
        let v = v0 + (v1 - v0) * (j as f64 + 0.5) / sampled as f64;
        // The span the plane cuts: the aperture's chord at v.
        let du = (u1 - u0) / ALONG as f64;
        let inside: Vec<f64> = (0..=ALONG)
            .map(|i| u0 + du * i as f64)
            .filter(|&u| {
                let (x, y) = xy(u, v);
                s.head.surface.lowered.domain.contains(x, y)
            })
            .collect();
        if inside.len() < 2 {
            continue;
        }
        let span = inside[inside.len() - 1] - inside[0];
        let mut curve = Curve {
            ds: Vec::new(),
            kappa: Vec::new(),
        };
        let mut n = 1.0;
        for &u in &inside {
            let (x, y) = xy(u, v);
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
            if !curve.kappa.is_empty() {
                n += chords(du, span, h);
            }
            curve.ds.push(if curve.kappa.is_empty() {
                0.0
            } else {
                du * stretch
            });
            curve.kappa.push(kappa);
        }
        points += weight * n;
        let arcs = curve.arcs(r.chord_tolerance * FIT_SHARE).min(n);
        bytes += weight * (RASTER_PASS + arcs * RASTER_BLOCK);
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
