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

use super::JobHead;
use lensc_lang::codes;

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

/// Every limit the estimate is over, as an error at the job.
pub fn refusals(head: &JobHead, e: &Estimate, limits: &Limits) -> Vec<Diagnostic> {
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
pub(crate) fn count(n: f64) -> String {
    match n {
        n if !n.is_finite() => "infinitely many".into(),
        n if n >= 1e12 => format!("{:.3e}", n),
        n if n >= 1e9 => format!(
            "{} billion",
            lensc_lang::check::trim_num((n / 1e8).round() / 10.0)
        ),
        n if n >= 1e6 => format!(
            "{} million",
            lensc_lang::check::trim_num((n / 1e5).round() / 10.0)
        ),
        n => format!("{}", n.round()),
    }
}

/// A size in bytes, in words: "4.0 GB".
fn size(n: f64) -> String {
    match n {
        n if !n.is_finite() => "unbounded".into(),
        n if n >= 1e12 => format!("{:.3e} bytes", n),
        n if n >= 1e9 => format!(
            "{} GB",
            lensc_lang::check::trim_num((n / 1e8).round() / 10.0)
        ),
        n if n >= 1e6 => format!(
            "{} MB",
            lensc_lang::check::trim_num((n / 1e5).round() / 10.0)
        ),
        n if n >= 1e3 => format!(
            "{} kB",
            lensc_lang::check::trim_num((n / 1e2).round() / 10.0)
        ),
        n => format!("{} bytes", n.round()),
    }
}

/// Chords a bisection from a span of `span` makes over a stretch `ds`
/// where a chord may be at most `h` long: the span halved until it fits.
pub(crate) fn chords(ds: f64, span: f64, h: f64) -> f64 {
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
pub(crate) fn chord_for(kappa: f64, tol: f64) -> f64 {
    (8.0 * tol / kappa.abs()).sqrt()
}

/// |κ′| L³ / `ARC_FIT` is how far an arc of length L strays from a curve
/// whose curvature changes at κ′: 192 for the best arc over the stretch,
/// less for the optimiser's greedy fit from each point on (measured on the
/// examples' rasters).
const ARC_FIT: f64 = 54.0;

/// Arcs per unit length where the curvature changes at `dkappa` per unit
/// length and fits are held to `tol`.
pub(crate) fn arcs_per_length(dkappa: f64, tol: f64) -> f64 {
    (dkappa.abs() / (ARC_FIT * tol)).cbrt()
}

/// The nose-centre curve that rides `rho` above a section of slope `dz`
/// and second derivative `d2z`: its curvature (positive: concave, the
/// centre curve tighter) and its length per unit length of the section.
pub(crate) fn centre_curve(dz: f64, d2z: f64, rho: f64) -> (f64, f64) {
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
pub(crate) struct Curve {
    pub ds: Vec<f64>,
    pub kappa: Vec<f64>,
}

impl Curve {
    /// Arcs a fit to `tol` needs along the curve (at least one).
    pub fn arcs(&self, tol: f64) -> f64 {
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
