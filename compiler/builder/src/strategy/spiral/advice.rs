//! The advice of a spiral refused for its fast axis's acceleration
//! (E0147), or for a move written faster than the machine's feed
//! (E0192): the highest speed that passes, found by planning the real
//! check at trial speeds, a bounded number of them.
//!
//! No scaling law gives it. Were the points and the trajectory fixed,
//! every second divided difference in time would scale with the square
//! of the speed; but where the trajectory has a corner (a lenslet's
//! continuation meeting the settling plateau, a rim on the land) the
//! sampler splits down to the servo's data period, a time, and there the
//! acceleration (a jump in slope over one period) scales with the speed
//! itself; and the settling offset, so the trajectory, grows with the
//! surface speed. So each trial speed is planned (`Planner::check`, which
//! stops at the first revolution over the limit) and the advice is the
//! fastest trial that passed: building at it passes. Trial speeds are
//! decimals of four significant figures in the job's own unit, parsed
//! as the checker parses them, so the speed a user copies from the help
//! is the one that was checked.
//!
//! The servo is simulated at the speed found, where the job gates its
//! following error (a servo model; `max_following_error` stated or
//! default), and a lag over the limit is part of the advice: the limit
//! that accepts it. Speed is no cure there. A second-order servo lags its
//! command by about a fixed time (2ζ/ω_n), so its error falls with the
//! speed, but only to where the data period's corners and the printed
//! resolution take over, and not monotonically: the hex array of
//! tests/bad_builds/ lags 1243 nm at 185.1 rpm, 514 nm at 60, 170 nm at
//! 20, 54 nm at 6, 12.6 nm at 2, 16.8 nm at 1.2 and within its default
//! 11 nm only at 1 rpm, a cut of hours. A pure lag at a constant spindle
//! speed turns the cut pattern about the axis (0.12° there) rather than
//! changing its form; compensating it belongs to the planner (commands
//! led by the servo's delay), not to a slower spindle.

use super::SpiralSpec;
use lensc_lang::check::trim_num;
use lensc_lang::units;
use lensc_runtime::plan::spiral::{FtsError, LagMissed, Planner, SpeedAdvice, SpindleSpeed};

use crate::evaluate::evaluator;
use crate::job::accept::Criterion;
use crate::strategy::Strategy;

/// Most plans a search makes: failing ones stop early, passing ones run
/// the whole spiral.
const MAX_TRIALS: usize = 14;

/// The search stops once the fastest pass is within this ratio of the
/// slowest failure above it.
const PRECISION: f64 = 1.02;

/// The highest speed that passes, below the job's own, which accelerated
/// at `acceleration` (mm/s²), planned without the servo (cheaply); then
/// the servo simulated at it, and its lag where that misses the job's
/// limit.
pub fn search(spec: &SpiralSpec, acceleration: f64) -> SpeedAdvice {
    search_below(spec, acceleration / spec.fast_axis.max_acceleration)
}

/// The highest speed that passes, below the job's own, whose fastest
/// move as written fed at `feed` (mm/s) over the machine's `max_feed`
/// (E0192): planned at trial speeds, each trial's commands led as the
/// build leads them.
pub fn search_feed(spec: &SpiralSpec, feed: f64) -> SpeedAdvice {
    search_below(spec, feed / spec.max_feed)
}

/// The highest speed that passes, below the job's own, whose fastest
/// servo move, the servo written on its own letter, drove it at `velocity`
/// (mm/s) over its `max_velocity` (E0192).
pub fn search_servo(spec: &SpiralSpec, velocity: f64) -> SpeedAdvice {
    let most = spec.servo_axis.map_or(f64::INFINITY, |(_, v)| v);
    search_below(spec, velocity / most)
}

/// The search below the job's speed, which failed by `excess` (its
/// acceleration or feed over the limit).
fn search_below(spec: &SpiralSpec, excess: f64) -> SpeedAdvice {
    let unit = Unit::of(spec.spiral.speed);
    // The slowest failure so far (in the job's unit) and by how much it
    // failed (the acceleration or feed over its limit).
    let mut fails = (unit.shown(spec.spiral.speed), excess);
    let mut passes: Option<f64> = None;
    let mut trials = 0;
    // Bracket: step down assuming the excess ∝ speed^p, p = 1 (a corner's
    // law, more cautious than the square) until the last two failures
    // measure it; where it hardly falls with the speed (or rises: another
    // corner takes over), by a fifth.
    let mut p: Option<f64> = Some(1.0);
    while passes.is_none() && trials < MAX_TRIALS {
        let (s, excess) = fails;
        let ratio = p.map_or(0.8, |p| (1.0 / excess).powf(1.0 / p).clamp(0.5, 0.99));
        let guess = s * ratio;
        let Some(trial) = decimal(guess).filter(|&t| t < s && t > 0.0) else {
            break;
        };
        trials += 1;
        match check(spec, unit, trial, None) {
            Verdict::Passes => passes = Some(trial),
            Verdict::Fails(at, _) => {
                let measured = (excess / at).ln() / (s / trial).ln();
                p = (measured.is_finite() && measured > 0.25).then(|| measured.min(2.0));
                fails = (trial, at);
            }
        }
    }
    let Some(mut lo) = passes else {
        return SpeedAdvice::NotFound {
            lowest_tried: unit.value(fails.0),
        };
    };
    // Bisect (geometrically) between the fastest pass and the slowest
    // failure.
    let mut hi = fails.0;
    while trials < MAX_TRIALS && hi / lo > PRECISION {
        let Some(m) = decimal((lo * hi).sqrt()).filter(|&m| m > lo && m < hi) else {
            break;
        };
        trials += 1;
        match check(spec, unit, m, None) {
            Verdict::Passes => lo = m,
            Verdict::Fails(..) => hi = m,
        }
    }
    // The servo at that speed: its lag, where the job gates it.
    let lag = following_limit(spec).and_then(|limit| match check(spec, unit, lo, Some(limit)) {
        Verdict::Fails(_, lag) => lag,
        Verdict::Passes => None,
    });
    SpeedAdvice::Found {
        passes: unit.value(lo),
        fails: unit.value(hi),
        lag,
    }
}

/// The following error (mm) the build's gate holds the job's servo to:
/// the `max_following_error` it states, else the default; none without
/// a servo model or under `accept: none`.
fn following_limit(spec: &SpiralSpec) -> Option<f64> {
    if spec.slow || spec.servo.is_none() {
        return None;
    }
    let head = &spec.head;
    head.accept.limit(
        Criterion::MaxFollowingError,
        spec.path_tolerance(),
        head.resolution,
        crate::job::holds(head.resolution, <SpiralSpec as Strategy>::LENGTH_AXES),
    )
}

/// Whether the job as written is refused by the planner (E0147) or by
/// the checks the build makes of the commands it writes (the lead's
/// acceleration, a move faster than the machine's feed: E0192), its lag
/// not gated: what the speed the advice names as refused must meet.
pub fn refused_as_written(spec: &SpiralSpec) -> bool {
    let unit = Unit::of(spec.spiral.speed);
    matches!(
        check(spec, unit, unit.shown(spec.spiral.speed), None),
        Verdict::Fails(..)
    )
}

enum Verdict {
    Passes,
    /// Refused: by how much (the acceleration or the lag over its limit;
    /// infinite for another refusal), and the lag where that was why.
    Fails(f64, Option<LagMissed>),
}

/// Plans the job at `speed` (in its own unit) up to its first refusal,
/// its servo (`lag_limit`, mm: where it is gated) simulated on the
/// commands as printed, led as the build leads it (`servo::following`).
fn check(spec: &SpiralSpec, unit: Unit, speed: f64, lag_limit: Option<f64>) -> Verdict {
    let speed = unit.speed(spec.spiral.speed, speed);
    let Ok(at) = spec.at_speed(speed, &|tape| evaluator(tape).0) else {
        return Verdict::Fails(f64::INFINITY, None);
    };
    let (trajectory, bounds) = match &at.trajectory {
        Some((t, b)) => (t, b.clone()),
        None => (&spec.trajectory, spec.bounds.clone()),
    };
    let kernel = evaluator(&trajectory.tape).0;
    let data_rate = 1.0 / at.spiral.min_interval;
    // The servo is simulated where its lag is gated, and wherever the
    // program leads it: the lead's own acceleration is checked at every
    // trial (the build refuses it, E0192), gated or not.
    let leads = super::servo::program_leads(spec);
    let mut following = (lag_limit.is_some() || leads)
        .then(|| super::servo::following(spec, &at.spiral, &bounds, data_rate))
        .flatten();
    let planner = Planner {
        spiral: &at.spiral,
        surface: kernel.as_ref(),
        less: None,
        nose_radius: spec.nose_radius,
        edge: spec.edge.as_ref().map(|(m, _)| &m.profile),
        bounds,
    };
    let resolution = spec.head.resolution;
    let mut commands = super::servo::Commands::of(spec, data_rate);
    // The commands are made where the servo is simulated or the moves
    // written are held to the machine's feed.
    let planned = match following.as_mut() {
        Some(sim) => planner.check_with(&spec.fast_axis, |pts| {
            commands.next(pts);
            commands.drive(sim, resolution);
        }),
        None if super::servo::writes_moves(spec) => {
            planner.check_with(&spec.fast_axis, |pts| commands.next(pts))
        }
        None => planner.check(&spec.fast_axis),
    };
    if planned.is_ok() {
        commands.finish();
        if let Some(sim) = following.as_mut() {
            commands.drive(sim, resolution);
        }
    }
    if let (Ok(_), Some((feed, _))) = (&planned, commands.over_max_feed(spec)) {
        return Verdict::Fails(feed / spec.max_feed, None);
    }
    if let (Ok(_), Some((v, _)), Some((_, most))) = (
        &planned,
        commands.over_servo_velocity(spec),
        spec.servo_axis,
    ) {
        return Verdict::Fails(v / most, None);
    }
    match planned {
        Ok(_) => match following {
            Some(sim) => {
                let f = sim.finish();
                let lag = f.max_error;
                let most = spec.fast_axis.max_acceleration;
                if leads && f.max_acceleration > most {
                    // The lead the program writes drives the servo too hard.
                    Verdict::Fails(f.max_acceleration / most, None)
                } else if let Some(limit) = lag_limit.filter(|&l| lag > l) {
                    Verdict::Fails(lag / limit, Some(LagMissed { lag, limit }))
                } else {
                    Verdict::Passes
                }
            }
            None => Verdict::Passes,
        },
        Err(FtsError::AccelerationExceeded {
            acceleration, max, ..
        }) => Verdict::Fails(acceleration / max, None),
        Err(_) => Verdict::Fails(f64::INFINITY, None),
    }
}

/// A following-error limit (nm) that accepts a lag of `lag` (mm): the lag
/// rounded up to two significant figures (the help's suggestion).
pub fn accepted_lag_nm(lag: f64) -> f64 {
    let nm = lag * 1e6;
    if !(nm.is_finite() && nm > 0.0) {
        return nm;
    }
    let step = 10f64.powi(nm.log10().floor() as i32 - 1);
    // A lag already of two figures stays itself, not the next step up.
    let figures = trim_num(nm / step).parse::<f64>().unwrap_or(nm / step);
    figures.ceil() * step
}

/// `v` rounded down to four significant figures, as the decimal the help
/// prints and a user would write.
fn decimal(v: f64) -> Option<f64> {
    if !(v.is_finite() && v > 0.0) {
        return None;
    }
    let step = 10f64.powi(v.log10().floor() as i32 - 3);
    let rounded = (v / step).floor() * step;
    trim_num(rounded).parse().ok().filter(|&d: &f64| d > 0.0)
}

/// The unit the job states its speed in: rpm, or m/min for a constant
/// surface speed.
#[derive(Clone, Copy)]
enum Unit {
    Rpm,
    MetresPerMinute,
}

impl Unit {
    fn of(speed: SpindleSpeed) -> Unit {
        match speed {
            SpindleSpeed::Constant(_) => Unit::Rpm,
            SpindleSpeed::SurfaceSpeed { .. } => Unit::MetresPerMinute,
        }
    }

    /// The factor from the unit to rad/s or mm/s, multiplied up as the
    /// checker does a written unit's parts.
    fn factor(self) -> f64 {
        let parts: &[(&str, i32)] = match self {
            Unit::Rpm => &[("rpm", 1)],
            Unit::MetresPerMinute => &[("m", 1), ("min", -1)],
        };
        parts.iter().fold(1.0, |f, &(name, power)| {
            f * units::lookup(name)
                .expect("a known unit")
                .factor
                .powi(power)
        })
    }

    /// A speed written in the unit, in rad/s or mm/s.
    fn value(self, written: f64) -> f64 {
        written * self.factor()
    }

    /// The job's speed in the unit.
    fn shown(self, speed: SpindleSpeed) -> f64 {
        speed.stated() / self.factor()
    }

    /// The job's speed with its value `written` in the unit (a surface
    /// speed keeps its spindle cap).
    fn speed(self, like: SpindleSpeed, written: f64) -> SpindleSpeed {
        match like {
            SpindleSpeed::Constant(_) => SpindleSpeed::Constant(self.value(written)),
            SpindleSpeed::SurfaceSpeed { max, .. } => SpindleSpeed::SurfaceSpeed {
                speed: self.value(written),
                max,
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_accepted_lag_is_rounded_up_to_two_figures() {
        assert_eq!(trim_num(accepted_lag_nm(1.2427e-3)), "1300");
        assert_eq!(trim_num(accepted_lag_nm(12.6e-6)), "13");
        assert_eq!(trim_num(accepted_lag_nm(1.3e-3)), "1300");
        assert_eq!(trim_num(accepted_lag_nm(0.4955e-3)), "500");
    }

    #[test]
    fn decimals_round_down_to_four_figures() {
        assert_eq!(decimal(198.987), Some(198.9));
        assert_eq!(decimal(4.56789), Some(4.567));
        assert_eq!(decimal(1000.0), Some(1000.0));
        assert_eq!(decimal(0.012345), Some(0.01234));
        assert_eq!(decimal(0.0), None);
        assert_eq!(decimal(f64::NAN), None);
    }

    #[test]
    fn units_convert_as_the_checker_does() {
        let rpm = Unit::Rpm.value(300.0);
        assert!((rpm - 300.0 * 2.0 * std::f64::consts::PI / 60.0).abs() < 1e-12);
        let v = Unit::MetresPerMinute.value(5.0);
        assert!((v - 5000.0 / 60.0).abs() < 1e-12);
        let back = Unit::Rpm.shown(SpindleSpeed::Constant(rpm));
        assert!((back - 300.0).abs() < 1e-9);
    }
}
