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
use crate::job::estimate::MAX_SERVO_SAMPLES;
use crate::strategy::Strategy;

/// Most plans a search makes: failing ones stop early, passing ones run
/// the whole spiral.
const MAX_TRIALS: usize = 14;

/// The slowdown over which an excess that has not fallen ends the search
/// (`flat`), and the least power of the speed it must fall by.
const FLAT_SPAN: f64 = 16.0;
const FLAT_POWER: f64 = 0.25;

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
    let job = fails;
    let mut budget = Budget::of(spec, job.0);
    let mut spent = false;
    while passes.is_none() && trials < MAX_TRIALS {
        let (s, excess) = fails;
        let ratio = p.map_or(0.8, |p| (1.0 / excess).powf(1.0 / p).clamp(0.5, 0.99));
        let guess = s * ratio;
        let Some(trial) = decimal(guess).filter(|&t| t < s && t > 0.0) else {
            break;
        };
        if !budget.affords(trial) {
            spent = true;
            break;
        }
        trials += 1;
        match check(spec, unit, trial, None) {
            Verdict::Passes => {
                budget.spend(trial);
                passes = Some(trial);
            }
            Verdict::Fails(at, _) => {
                let measured = (excess / at).ln() / (s / trial).ln();
                p = (measured.is_finite() && measured > 0.25).then(|| measured.min(2.0));
                fails = (trial, at);
                if flat(job, fails) {
                    break;
                }
            }
        }
    }
    let Some(mut lo) = passes else {
        return SpeedAdvice::NotFound {
            lowest_tried: unit.value(fails.0),
            budget: spent,
        };
    };
    // Bisect (geometrically) between the fastest pass and the slowest
    // failure.
    let mut hi = fails.0;
    while trials < MAX_TRIALS && hi / lo > PRECISION {
        let Some(m) = decimal((lo * hi).sqrt()).filter(|&m| m > lo && m < hi) else {
            break;
        };
        if !budget.affords(m) {
            break;
        }
        trials += 1;
        match check(spec, unit, m, None) {
            Verdict::Passes => {
                budget.spend(m);
                lo = m;
            }
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

/// The servo samples a search may simulate in all, at least: a tenth of
/// what one build may (`MAX_SERVO_SAMPLES`), some nine seconds.
const SEARCH_SAMPLES: f64 = MAX_SERVO_SAMPLES as f64 / 10.0;

/// What is left of the search's servo simulation. A trial that plans is
/// simulated over its whole cut, whose samples grow as the speed falls
/// (the cutting time at the servo's data rate): the job's own estimate
/// scaled by the job's speed over the trial's, which bounds it (a surface
/// speed's capped spindle grows it less). A search may simulate
/// `SEARCH_SAMPLES`, or four times the job's own where that is more (a
/// refused job is advised at about the cost of a few builds of it), so
/// the advice stops at a speed whose simulation it cannot afford, rather
/// than at one that takes hours.
struct Budget {
    /// The job's own servo samples (0 where no trial simulates its servo)
    /// and speed (in its unit).
    job: (f64, f64),
    left: f64,
}

impl Budget {
    fn of(spec: &SpiralSpec, speed: f64) -> Budget {
        let simulated = following_limit(spec).is_some() || super::servo::program_leads(spec);
        let samples = if simulated {
            // The build's own estimate, made before planning (or made
            // here, where the search is called on a job not estimated).
            Strategy::estimate(spec, &|tape| evaluator(tape).0).servo_samples
        } else {
            0.0
        };
        Budget {
            job: (samples, speed),
            left: SEARCH_SAMPLES.max(4.0 * samples),
        }
    }

    /// The samples a trial at `speed` simulates, at most.
    fn cost(&self, speed: f64) -> f64 {
        let (samples, job_speed) = self.job;
        if samples == 0.0 {
            0.0
        } else {
            samples * job_speed / speed
        }
    }

    fn affords(&self, speed: f64) -> bool {
        self.cost(speed) <= self.left
    }

    fn spend(&mut self, speed: f64) {
        self.left -= self.cost(speed);
    }
}

/// Whether the excess has not fallen with the speed over a span wide
/// enough to say so: from the job's own speed and excess to a trial's,
/// the speed down `FLAT_SPAN` times or more, the excess fell slower than
/// the speed to the power `FLAT_POWER` (or rose). A smooth path's
/// acceleration falls with the square of the speed and a corner's with
/// the speed itself; one that holds over a sixteenfold slower spindle is
/// the path's own (a step at the servo's data period), or a spindle cap,
/// and slower trials only cost more (each plans a longer cut).
fn flat(job: (f64, f64), trial: (f64, f64)) -> bool {
    let span = job.0 / trial.0;
    let fell = job.1 / trial.1;
    // (A NaN power, an excess infinitely over at both, is flat too.)
    use std::cmp::Ordering::{Equal, Greater};
    let power = fell.ln() / span.ln();
    span >= FLAT_SPAN && !matches!(power.partial_cmp(&FLAT_POWER), Some(Greater | Equal))
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
///
/// The plan comes first, alone: a trial the planner refuses (or whose
/// moves as written are too fast) is refused without simulating the
/// servo, which steps at its data rate through the cut so far, so costs
/// in proportion to the cutting time: at a crawling trial speed millions
/// of samples for the same few thousand points (two fuzzed hex arrays
/// spent 10 s there, `tests/fuzz_crashes/build_fts_*`). Only a trial
/// that plans is planned again with its servo simulated.
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
    let planner = Planner {
        spiral: &at.spiral,
        surface: kernel.as_ref(),
        less: None,
        nose_radius: spec.nose_radius,
        edge: spec.edge.as_ref().map(|(m, _)| &m.profile),
        bounds: bounds.clone(),
    };
    // The commands are made where the moves written are held to the
    // machine's feed (or the servo's letter to its velocity).
    let mut commands = super::servo::Commands::of(spec, data_rate);
    let planned = if super::servo::writes_moves(spec) {
        planner.check_with(&spec.fast_axis, |pts| commands.next(pts))
    } else {
        planner.check(&spec.fast_axis)
    };
    match planned {
        Ok(_) => commands.finish(),
        Err(FtsError::AccelerationExceeded {
            acceleration, max, ..
        }) => return Verdict::Fails(acceleration / max, None),
        Err(_) => return Verdict::Fails(f64::INFINITY, None),
    }
    if let Some((feed, _)) = commands.over_max_feed(spec) {
        return Verdict::Fails(feed / spec.max_feed, None);
    }
    if let (Some((v, _)), Some((_, most))) = (commands.over_servo_velocity(spec), spec.servo_axis) {
        return Verdict::Fails(v / most, None);
    }
    // The servo is simulated where its lag is gated, and wherever the
    // program leads it: the lead's own acceleration is checked at every
    // trial (the build refuses it, E0192), gated or not.
    let leads = super::servo::program_leads(spec);
    let Some(mut sim) = (lag_limit.is_some() || leads)
        .then(|| super::servo::following(spec, &at.spiral, &bounds, data_rate))
        .flatten()
    else {
        return Verdict::Passes;
    };
    let resolution = spec.head.resolution;
    let mut commands = super::servo::Commands::of(spec, data_rate);
    let planned = planner.check_with(&spec.fast_axis, |pts| {
        commands.next(pts);
        commands.drive(&mut sim, resolution);
    });
    if planned.is_err() {
        // The same plan again (the planner is deterministic): not met.
        return Verdict::Fails(f64::INFINITY, None);
    }
    commands.finish();
    commands.drive(&mut sim, resolution);
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
    fn an_excess_that_holds_over_a_sixteenfold_slowdown_is_flat() {
        // The fuzzed grid: 9.5x over at 52 rpm, 17.2x at 2.662.
        assert!(flat((52.0, 9.536), (2.662, 17.17)));
        // Not yet a span wide enough to say.
        assert!(!flat((52.0, 9.536), (3.328, 15.0)));
        // A corner's law (the excess in proportion to the speed) and a
        // slow fall (power 0.3) go on; a power of 0.2 is flat.
        assert!(!flat((52.0, 20.0), (2.6, 1.0)));
        assert!(!flat((32.0, 10.0), (1.0, 10.0 / 32f64.powf(0.3))));
        assert!(flat((32.0, 10.0), (1.0, 10.0 / 32f64.powf(0.2))));
        // A trial refused for another reason (infinitely over).
        assert!(flat((32.0, 2.0), (1.0, f64::INFINITY)));
    }

    #[test]
    fn a_trial_costs_the_jobs_samples_scaled_by_the_slowdown() {
        // A job of 100 M samples at 100 rpm: a budget of four times that.
        let mut b = Budget {
            job: (1e8, 100.0),
            left: SEARCH_SAMPLES.max(4e8),
        };
        assert_eq!(b.cost(50.0), 2e8);
        assert!(b.affords(25.0) && !b.affords(24.9));
        b.spend(50.0);
        assert!(b.affords(50.0) && !b.affords(49.9));
        // No trial simulates the servo: every speed is affordable.
        let free = Budget {
            job: (0.0, 100.0),
            left: SEARCH_SAMPLES,
        };
        assert!(free.affords(1e-9));
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
