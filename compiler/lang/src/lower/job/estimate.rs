//! Limits stated up front: before any path is planned, each job's point
//! count and program size are estimated from its parameters (the surface's
//! extent and curvature, the chord tolerance, the feed per revolution,
//! stepover, pitch, C step, interval…), and a job whose estimate is over a
//! limit is refused with what it asks for, the limit, and the parameter to
//! change — instead of planning for hours, filling the disk, or stopping
//! at a silent cap.
//!
//! The estimate follows each planner's own rule: chords bisected from a
//! span (the whole pass, a seed interval) until their sag is within the
//! planner's share of the tolerance, so a chord is the span halved k times
//! where `sqrt(8 tol / κ)` first fits (κ the path's curvature); the
//! spiral's chords stop at the servo's data period; raster steps are
//! capped by `max_step` and Lin's rule; grinding intervals and the roller's
//! C steps are counted exactly. Where the program is optimised (turning,
//! raster), arcs are counted from how fast the curvature changes: an arc
//! of length L strays about |κ′| L³ / 54 from a curve whose curvature
//! changes at κ′. Every example's estimate is within 2× of what its build
//! writes (`tests/it/limits.rs`).

use lensc_grammar::Diagnostic;
use lensc_runtime::plan::optimise::{CHORD_SHARE, FIT_SHARE, UNOPTIMISED_CHORD_SHARE};
use lensc_runtime::plan::turning::{ProfileTurning, Stock};
use lensc_runtime::surface::analysis::Domain;

use super::{Evaluate, JobSpec, SpiralSpec, TurningSpec};
use super::{GrindingSpec, RasterSpec, RollerSpec};
use crate::codes;

/// The most points lensc plans for one job: 200 million (a spiral's or a
/// roller's program of that many points is 6–9 GB of text).
pub const MAX_POINTS: u64 = 200_000_000;

/// Most samples of a fast tool servo's following simulation for one job:
/// ten times seed 003's whole array (231 M samples, about 8 s), so about
/// a minute and a half of simulation at most.
pub const MAX_SERVO_SAMPLES: u64 = 2_000_000_000;

/// The default largest program (bytes) a build writes: 4 GB.
pub const DEFAULT_MAX_PROGRAM_SIZE: u64 = 4_000_000_000;

/// The limits a build is held to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Largest program (bytes): `--max-program-size`.
    pub max_program_size: u64,
    /// Most points: [`MAX_POINTS`].
    pub max_points: u64,
}

impl Default for Limits {
    fn default() -> Limits {
        Limits {
            max_program_size: DEFAULT_MAX_PROGRAM_SIZE,
            max_points: MAX_POINTS,
        }
    }
}

/// What a job is expected to write, estimated before planning.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    /// Cut points (as the report counts them: the finish pass of a
    /// profile-turning job, every point of the others).
    pub points: f64,
    /// Bytes of the program.
    pub program_bytes: f64,
    /// The strategy's parameter that sets the point count, for the help.
    pub driver: &'static str,
    /// Samples of the fast tool servo's following simulation: the cutting
    /// time at the servo's data rate (0 where no servo is simulated).
    pub servo_samples: f64,
}

/// The job's estimate, from its typed spec; surfaces are evaluated with
/// `evaluate` on a coarse grid.
pub fn estimate(spec: &JobSpec, evaluate: Evaluate) -> Estimate {
    let header = 900.0 + spec.head().surface.words.len() as f64;
    let mut e = match spec {
        JobSpec::Turning(s) => turning(s, evaluate),
        JobSpec::Spiral(s) => spiral(s, evaluate),
        JobSpec::Raster(s) => raster(s, evaluate),
        JobSpec::Grinding(s) => grinding(s),
        JobSpec::Roller(s) => roller(s),
    };
    e.program_bytes += header;
    e
}

/// Every limit the estimate is over, as an error at the job.
pub fn refusals(spec: &JobSpec, e: &Estimate, limits: &Limits) -> Vec<Diagnostic> {
    let head = spec.head();
    let mut out = Vec::new();
    // (NaN is over every limit.)
    if over(e.points, limits.max_points) {
        out.push(
            head.error(
                codes::TOO_MANY_POINTS,
                format!(
                    "this job asks for about {} points, more than the {} lensc plans for one job",
                    count(e.points),
                    count(limits.max_points as f64)
                ),
            )
            .with_help(format!(
                "make `{}` coarser: the point count scales with it",
                e.driver
            )),
        );
    }
    // (The servo is simulated sample by sample: a spindle crawling at
    // 1e-9 rpm would take forever, whatever its points.)
    if over(e.servo_samples, MAX_SERVO_SAMPLES) {
        out.push(
            head.error(
                codes::TOO_MANY_POINTS,
                format!(
                    "this job's servo simulation needs about {} samples (its cutting time at the servo's data rate), more than the {} lensc simulates for one job",
                    count(e.servo_samples),
                    count(MAX_SERVO_SAMPLES as f64)
                ),
            )
            .with_help("raise `spindle_speed` (or `surface_speed`): the cutting time scales with its inverse"),
        );
    }
    if over(e.program_bytes, limits.max_program_size) {
        out.push(
            head.error(
                codes::PROGRAM_TOO_LARGE,
                format!(
                    "this job's program would be about {}, more than the {} allowed",
                    size(e.program_bytes),
                    size(limits.max_program_size as f64)
                ),
            )
            .with_help(format!(
                "make `{}` coarser, or raise the limit with `--max-program-size`",
                e.driver
            )),
        );
    }
    out
}

/// Whether `estimate` is over `limit` (or not a number).
fn over(estimate: f64, limit: u64) -> bool {
    estimate.partial_cmp(&(limit as f64)) != Some(std::cmp::Ordering::Less)
        && estimate != limit as f64
}

/// A count in words: "3.2 million".
fn count(n: f64) -> String {
    match n {
        n if !n.is_finite() => "infinitely many".into(),
        n if n >= 1e12 => format!("{:.3e}", n),
        n if n >= 1e9 => format!(
            "{} billion",
            crate::check::trim_num((n / 1e8).round() / 10.0)
        ),
        n if n >= 1e6 => format!(
            "{} million",
            crate::check::trim_num((n / 1e5).round() / 10.0)
        ),
        n => format!("{}", n.round()),
    }
}

/// A size in bytes, in words: "4.0 GB".
fn size(n: f64) -> String {
    match n {
        n if !n.is_finite() => "unbounded".into(),
        n if n >= 1e12 => format!("{:.3e} bytes", n),
        n if n >= 1e9 => format!("{} GB", crate::check::trim_num((n / 1e8).round() / 10.0)),
        n if n >= 1e6 => format!("{} MB", crate::check::trim_num((n / 1e5).round() / 10.0)),
        n if n >= 1e3 => format!("{} kB", crate::check::trim_num((n / 1e2).round() / 10.0)),
        n => format!("{} bytes", n.round()),
    }
}

/// Bytes of one motion block, by strategy (measured on the examples).
const TURNING_BLOCK: f64 = 42.0;
const SPIRAL_BLOCK: f64 = 43.0;
const RASTER_BLOCK: f64 = 37.0;
/// A raster pass's own moves: over, down and up (short words).
const RASTER_PASS: f64 = 3.0 * 17.0;
const GRINDING_BLOCK: f64 = 33.0;
const ROLLER_BLOCK: f64 = 38.0;

/// Chords a bisection from a span of `span` makes over a stretch `ds`
/// where a chord may be at most `h` long: the span halved until it fits.
fn chords(ds: f64, span: f64, h: f64) -> f64 {
    // A tolerance so fine it is zero once shared out (5e-324 mm): no chord
    // is short enough, and the sampler would halve every seed 40 times.
    if h == 0.0 {
        return f64::INFINITY;
    }
    if !(h.is_finite() && h > 0.0) || h >= span {
        return ds / span;
    }
    let k = (span / h).log2().ceil().min(1000.0);
    ds / (span / k.exp2())
}

/// The longest chord (along its curve) whose sag on curvature `kappa`
/// stays within `tol`.
fn chord_for(kappa: f64, tol: f64) -> f64 {
    (8.0 * tol / kappa.abs()).sqrt()
}

/// |κ′| L³ / `ARC_FIT` is how far an arc of length L strays from a curve
/// whose curvature changes at κ′: 192 for the best arc over the stretch,
/// less for the optimiser's greedy fit from each point on (measured on the
/// examples' rasters).
const ARC_FIT: f64 = 54.0;

/// Arcs per unit length where the curvature changes at `dkappa` per unit
/// length and fits are held to `tol`.
fn arcs_per_length(dkappa: f64, tol: f64) -> f64 {
    (dkappa.abs() / (ARC_FIT * tol)).cbrt()
}

/// The nose-centre curve that rides `rho` above a section of slope `dz`
/// and second derivative `d2z`: its curvature (positive: concave, the
/// centre curve tighter) and its length per unit length of the section.
fn centre_curve(dz: f64, d2z: f64, rho: f64) -> (f64, f64) {
    let k = d2z / (1.0 + dz * dz).powf(1.5);
    if rho * k >= 1.0 {
        // Tighter than the nose: the nose bridges it (a seam), its centre
        // turning a corner there.
        return (0.0, 0.0);
    }
    let stretch = 1.0 - rho * k;
    let c = k / (1.0 - rho * k);
    if c.is_finite() {
        (c, stretch)
    } else {
        (0.0, 1.0)
    }
}

/// A curve sampled in order: the arc length of each step and the centre
/// curvature at its end.
struct Curve {
    ds: Vec<f64>,
    kappa: Vec<f64>,
}

impl Curve {
    /// Arcs a fit to `tol` needs along the curve (at least one).
    fn arcs(&self, tol: f64) -> f64 {
        let mut n = 0.0;
        for i in 1..self.ds.len() {
            let ds = self.ds[i];
            if ds > 0.0 {
                n += ds * arcs_per_length((self.kappa[i] - self.kappa[i - 1]) / ds, tol);
            }
        }
        n.max(1.0)
    }
}

/// Profile turning: the finish pass from 32 seeds, each bisected to the
/// chords' share of the tolerance; roughing passes as many again each.
fn turning(s: &TurningSpec, evaluate: Evaluate) -> Estimate {
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

/// A spiral: each revolution's seeds a seed arc apart, each seed interval
/// bisected until W's chords in (C, W) are within their share of the
/// tolerance or down to the servo's data period; where the trajectory is
/// level (outside an array's lenslets) a stretch is one move. Revolutions
/// are sampled on up to 256 rings, each ring on up to 4096 angles.
fn spiral(s: &SpiralSpec, evaluate: Evaluate) -> Estimate {
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
                // A level stretch: its two ends.
                if was_on {
                    n += 2.0;
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
            n += chords(dc, span, h);
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

/// A raster: a pass per stepover across the aperture, each bisected from
/// its whole span until its chords meet the chords' share of the
/// tolerance, `max_step` and Lin's step; passes sampled up to 256, each
/// at 512 points along the cut.
fn raster(s: &RasterSpec, evaluate: Evaluate) -> Estimate {
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

/// Profile grinding: one point per interval and one more, one block each.
fn grinding(s: &GrindingSpec) -> Estimate {
    let g = &s.grinding;
    let points = ((g.end - g.start).abs() / g.interval).ceil() + 1.0;
    Estimate {
        servo_samples: 0.0,
        points,
        program_bytes: points * GRINDING_BLOCK,
        driver: "interval",
    }
}

/// A roller helix: each pass a point per C step over its helix, one block
/// each.
fn roller(s: &RollerSpec) -> Estimate {
    let h = &s.helix;
    let tau = std::f64::consts::TAU;
    let points: f64 = h
        .passes
        .iter()
        .map(|p| (tau * (h.z_end - h.z_start) / p.pitch / p.c_step).ceil() + 1.0)
        .sum();
    Estimate {
        servo_samples: 0.0,
        points,
        program_bytes: points * ROLLER_BLOCK,
        driver: "c_step",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bisection_halves_the_span_until_the_chord_fits() {
        assert_eq!(chords(1.0, 1.0, 2.0), 1.0);
        assert_eq!(chords(1.0, 1.0, 0.3), 4.0);
        assert_eq!(chords(0.5, 1.0, 0.25), 2.0);
    }

    #[test]
    fn counts_and_sizes_read_as_words() {
        assert_eq!(count(3.2e6), "3.2 million");
        assert_eq!(size(4e9), "4 GB");
        assert_eq!(count(2e8), "200 million");
        assert_eq!(count(f64::INFINITY), "infinitely many");
    }
}
