//! A profile-turning job's point count and program size, estimated before
//! planning (`job::estimate`).

use lensc_runtime::plan::optimise::{CHORD_SHARE, FIT_SHARE};
use lensc_runtime::plan::turning::{ProfileTurning, Stock};

use crate::job::Evaluate;
use crate::job::estimate::{Curve, Estimate, centre_curve, chord_for, chords};

/// Bytes of one motion block (measured on the examples).
const TURNING_BLOCK: f64 = 42.0;

/// Profile turning: the finish pass from 32 seeds, each bisected to the
/// chords' share of the tolerance; roughing passes as many again each.
pub(crate) fn estimate(s: &super::TurningSpec, evaluate: Evaluate) -> Estimate {
    const SEEDS: usize = 32;
    const PER_SEED: usize = 64;
    let st = &s.job.strategy;
    let k = evaluate(&s.head.surface.lowered.tape);
    let rho = s.job.tool.nose_radius;
    let (a, b) = (
        st.start_radius.unwrap_or(s.job.surface.aperture_radius),
        st.end_radius,
    );
    let tol = st.chord_tolerance * CHORD_SHARE;
    let n = SEEDS * PER_SEED;
    let mut curve = Curve {
        ds: vec![0.0],
        kappa: vec![0.0],
    };
    let mut points = 1.0;
    let mut prev: Option<[f64; 6]> = None;
    let mut seed_len = vec![0.0; SEEDS];
    let mut samples = Vec::with_capacity(n);
    let mut lowest = f64::INFINITY;
    for i in 0..=n {
        let r = a + (b - a) * i as f64 / n as f64;
        let p = k.eval(r, 0.0);
        lowest = lowest.min(p[0]);
        if let Some(q) = prev {
            let ds = (r - a - (b - a) * (i - 1) as f64 / n as f64).hypot(p[0] - q[0]);
            let (kappa, stretch) = centre_curve(p[1], p[3], rho);
            let ds = if ds.is_finite() { ds * stretch } else { 0.0 };
            seed_len[(i - 1) / PER_SEED] += ds;
            samples.push(((i - 1) / PER_SEED, ds, kappa));
            curve.ds.push(ds);
            curve.kappa.push(kappa);
        } else {
            curve.kappa[0] = centre_curve(p[1], p[3], rho).0;
        }
        prev = Some(p);
    }
    let mut per_seed = [0.0f64; SEEDS];
    for (seed, ds, kappa) in samples {
        per_seed[seed] += chords(ds, seed_len[seed].max(1e-300), chord_for(kappa, tol));
    }
    points += per_seed.iter().map(|c| c.max(1.0)).sum::<f64>();
    let passes = 1.0 + roughing_passes(st, lowest);
    let arcs = curve.arcs(st.chord_tolerance * FIT_SHARE).min(points);
    let blocks = passes * (4.0 + arcs);
    Estimate {
        servo_samples: 0.0,
        points,
        program_bytes: blocks * TURNING_BLOCK,
        driver: "chord_tolerance",
    }
}

/// Roughing passes before the finish, as the planner counts them, down to
/// the profile's `lowest` point.
fn roughing_passes(st: &ProfileTurning, lowest: f64) -> f64 {
    let Some(r) = st.roughing else {
        return 0.0;
    };
    let depth = match r.stock {
        Stock::Offset { allowance } => allowance - r.finish_allowance,
        Stock::Flat { top } => top - lowest - r.finish_allowance,
    };
    (depth / r.depth_of_cut).ceil().clamp(0.0, 10_000.0) + 1.0
}
