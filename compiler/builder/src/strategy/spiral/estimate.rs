//! A spiral job's point count, program size and servo samples, estimated
//! before planning (`job::estimate`).

use lensc_runtime::plan::optimise::UNOPTIMISED_CHORD_SHARE;

use crate::job::Evaluate;
use crate::job::estimate::{Estimate, chord_for, chords};

/// Bytes of one motion block (measured on the examples).
const SPIRAL_BLOCK: f64 = 43.0;

/// A spiral: each revolution's seeds a seed arc apart, each seed interval
/// bisected until W's chords in (C, W) are within their share of the
/// tolerance or down to the servo's data period; where the trajectory is
/// level (outside an array's lenslets) a stretch is one move. Revolutions
/// are sampled on up to 256 rings, each ring on up to 4096 angles.
pub(crate) fn estimate(s: &super::SpiralSpec, evaluate: Evaluate) -> Estimate {
    const RINGS: usize = 256;
    const ANGLES: usize = 4096;
    let sp = &s.spiral;
    let k = evaluate(&s.trajectory.tape);
    let tau = std::f64::consts::TAU;
    let revs = ((sp.start_radius - sp.end_radius) / sp.feed_per_rev)
        .ceil()
        .max(0.0);
    if !revs.is_finite() || revs > 1e12 {
        return Estimate {
            points: f64::INFINITY,
            program_bytes: f64::INFINITY,
            driver: "feed",
            servo_samples: f64::INFINITY,
        };
    }
    let tol = sp.chord_tolerance * UNOPTIMISED_CHORD_SHARE;
    let rings = (revs as usize).clamp(1, RINGS);
    let per_ring = revs / rings as f64;
    let grow = s.nose_radius * s.bounds.max_slope.sin() + sp.seed_arc;
    // Within reach of a feature (a lenslet's centre and rim radius). The
    // box test first: a hypotenuse is at least its longer side, so a point
    // outside the box is outside the circle, and the answer is the same as
    // `hypot` alone at a fraction of the cost (an array's hundreds of
    // lenslets at each of up to a million samples).
    let on_feature = |x: f64, y: f64| {
        s.bounds.features.as_ref().is_none_or(|f| {
            f.iter().any(|&(fx, fy, fr)| {
                let (dx, dy, reach) = (x - fx, y - fy, fr + grow);
                dx.abs() <= reach && dy.abs() <= reach && dx.hypot(dy) <= reach
            })
        })
    };
    // Where the program leads the servo, a bending point whose moves are
    // longer than two data periods gets a point of the path added a
    // period either side (`machine::lead`): up to three points where the
    // path had one.
    let leads = super::servo::program_leads(s);
    let led = |h: f64, shortest: f64| {
        if leads && h > 2.0 * shortest {
            3.0
        } else {
            1.0
        }
    };
    let (mut points, mut seeded, mut seconds) = (1.0, 0.0, 0.0);
    let (mut xs, mut ys) = (Vec::new(), Vec::new());
    let mut out = Vec::new();
    for j in 0..rings {
        let r =
            sp.start_radius - (sp.start_radius - sp.end_radius) * (j as f64 + 0.5) / rings as f64;
        let seeds = (tau * r.max(sp.seed_arc) / sp.seed_arc).ceil().max(2.0);
        let span = tau / seeds;
        let m = (seeds as usize).min(ANGLES);
        let dc = tau / m as f64;
        xs.clear();
        ys.clear();
        for i in 0..m {
            let c = dc * (i as f64 + 0.5);
            xs.push(r * c.cos());
            ys.push(r * c.sin());
        }
        out.resize(6 * m, 0.0);
        k.eval_batch(&xs, &ys, &mut out);
        let shortest = sp.speed.at(r) * sp.min_interval;
        let mut n = 0.0;
        let mut was_on = false;
        for i in 0..m {
            let (x, y) = (xs[i], ys[i]);
            let on = on_feature(x, y);
            if !on {
                // A level stretch: its two ends (bends, its moves long).
                if was_on {
                    n += 2.0 * led(f64::INFINITY, shortest);
                }
                was_on = false;
                continue;
            }
            was_on = true;
            let o = &out[6 * i..6 * i + 6];
            let (cs, sn) = (x / r, y / r);
            // W'' along the circle: r² tᵀHt − r ∇z·r̂.
            let tht = sn * sn * o[3] - 2.0 * sn * cs * o[4] + cs * cs * o[5];
            let w2 = r * r * tht - r * (cs * o[1] + sn * o[2]);
            let h = chord_for(w2, tol).max(shortest);
            n += chords(dc, span, h) * led(h, shortest);
            seeded += per_ring * dc / span;
        }
        points += per_ring * n.max(1.0);
        seconds += per_ring * tau / sp.speed.at(r);
    }
    // The following simulation samples the servo at its data rate.
    let servo_samples = if s.servo.is_some() {
        seconds / sp.min_interval
    } else {
        0.0
    };
    Estimate {
        points,
        servo_samples,
        program_bytes: points * SPIRAL_BLOCK,
        // Where the seeds alone make most of the points, the feed per
        // revolution sets the count; else the tolerance does.
        driver: if points > 2.0 * seeded {
            "chord_tolerance"
        } else {
            "feed"
        },
    }
}
