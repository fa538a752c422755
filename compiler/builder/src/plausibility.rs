//! Plausibility warnings on a built job, each with its number: a cutting
//! time over a day (W0030), a long approach at the cutting feed (W0031)
//! and a large share of the feed time spent in the air (W0032). None of
//! them stops a build: a job may mean it; they say what a slip of a unit
//! (`5 um/min` for `5 mm/min`) or a high retract costs before the machine
//! spends it.

use lensc_grammar::Diagnostic;
use lensc_lang::codes;
use lensc_runtime::moves::{Feed, Move, Position};

use crate::job::JobHead;
use crate::job::accept::Criterion;

/// The cutting time past which a job is implausible (s): a day. An
/// assumption, not a controller's rule: over a day of cutting, the
/// diamond's wear and the machine's thermal drift are no longer small
/// beside the form the job asks for, and a shop plans such a cut as
/// several jobs. A job that means it states `max_cutting_time`.
pub const PLAUSIBLE_CUTTING_TIME: f64 = 24.0 * 3600.0;

/// An approach at the cutting feed longer than this (s), half a minute, is
/// worth a word.
pub const LONG_APPROACH: f64 = 30.0;

/// Air cutting is worth a word when it is this share of the feed time…
pub const AIR_SHARE: f64 = 0.25;
/// …and at least this long (s).
pub const AIR_AT_LEAST: f64 = 60.0;

/// W0030 when the estimated cutting time is over a day, unless the job
/// states its own `max_cutting_time`.
pub fn cutting_time_warning(head: &JobHead, cutting_time: f64) -> Option<Diagnostic> {
    if cutting_time <= PLAUSIBLE_CUTTING_TIME
        || head.accept.stated(Criterion::MaxCuttingTime).is_some()
    {
        return None;
    }
    Some(
        warning(
            head,
            codes::CUTTING_TIME_IMPLAUSIBLE,
            format!(
                "the cut is estimated at {}, over a day",
                hours_minutes(cutting_time)
            ),
        )
        .with_help(
            "check the feed's unit (`um/min` for `mm/min`?) and the stepover or pitch; a job meant to run this long states `accept: { max_cutting_time: … }`",
        ),
    )
}

/// One approach: the feed moves from where a rapid left the tool to where
/// the cut begins, all of them in the air, along one line. A lathe's
/// approach may feed through the air fast and slow to the cutting feed
/// for its last part (`plan::approach`): the figures are those of its
/// last move, at the feed the cut begins with, and `air_time` the whole
/// approach's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Approach {
    /// The last move's length (mm).
    pub length: f64,
    /// Its path speed (mm/s).
    pub speed: f64,
    /// Its time (s).
    pub time: f64,
    /// The time (s) of every move of the approach.
    pub air_time: f64,
}

/// What a move stream spends at a cutting feed without cutting: every
/// approach (the feed moves straight after a rapid that carry on along
/// the first one's line), and the feed time of the whole stream (s).
pub fn feed_in_air(stream: &[Move]) -> (Vec<Approach>, f64) {
    let mut at = [f64::NAN; 4];
    let mut spindle = Spindle::Stopped;
    let mut feed: Option<Feed> = None;
    let mut after_rapid = false;
    // The open approach's direction, while its moves carry on along it.
    let mut heading: Option<[f64; 3]> = None;
    let mut approaches: Vec<Approach> = Vec::new();
    let mut feed_time = 0.0;
    for m in stream {
        match *m {
            Move::Rapid(to) => {
                at = merged(at, to);
                after_rapid = true;
                heading = None;
            }
            Move::Linear { to, feed: f } | Move::Arc { to, feed: f, .. } => {
                if f.is_some() {
                    feed = f;
                }
                let next = merged(at, to);
                let length = distance(at, next);
                let speed = feed.map_or(f64::NAN, |f| speed(f, spindle, at[0], length));
                let time = if speed > 0.0 { length / speed } else { 0.0 };
                let line = matches!(m, Move::Linear { .. });
                if time.is_finite() {
                    feed_time += time;
                    let d = direction(at, next);
                    let along = line && heading.is_some_and(|h| same_line(h, d));
                    if after_rapid && length > 0.0 {
                        approaches.push(Approach {
                            length,
                            speed,
                            time,
                            air_time: time,
                        });
                        heading = line.then_some(d);
                    } else if along
                        && length > 0.0
                        && let Some(a) = approaches.last_mut()
                    {
                        *a = Approach {
                            length,
                            speed,
                            time,
                            air_time: a.air_time + time,
                        };
                    } else {
                        heading = None;
                    }
                }
                after_rapid = false;
                at = next;
            }
            Move::SpindleOn(w) => spindle = Spindle::Constant(w),
            Move::SpindleSurfaceSpeed { surface_speed, cap } => {
                spindle = Spindle::SurfaceSpeed { surface_speed, cap }
            }
            Move::SpindleOff | Move::SpindleHeld => spindle = Spindle::Stopped,
        }
    }
    (approaches, feed_time)
}

/// The unit vector from `a` to `b` over X, Y and Z (axes not yet known
/// counted as not moving).
fn direction(a: [f64; 4], b: [f64; 4]) -> [f64; 3] {
    let l = distance(a, b);
    let mut d = [0.0; 3];
    for (i, v) in d.iter_mut().enumerate() {
        let s = b[i] - a[i];
        *v = if s.is_finite() && l > 0.0 { s / l } else { 0.0 };
    }
    d
}

/// Whether two unit vectors point the same way.
fn same_line(a: [f64; 3], b: [f64; 3]) -> bool {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] > 1.0 - 1e-9
}

/// W0031 for the longest approach over `LONG_APPROACH`, W0032 when the
/// approaches together are over `AIR_SHARE` of the feed time and
/// `AIR_AT_LEAST` (and not the one approach W0031 names).
pub fn air_warnings(head: &JobHead, stream: &[Move]) -> Vec<Diagnostic> {
    let (approaches, feed_time) = feed_in_air(stream);
    let mut out = Vec::new();
    let longest = approaches
        .iter()
        .copied()
        .max_by(|a, b| a.time.total_cmp(&b.time));
    let mut warned = 0.0;
    if let Some(a) = longest.filter(|a| a.time > LONG_APPROACH) {
        warned = a.air_time;
        out.push(
            warning(
                head,
                codes::LONG_APPROACH_AT_FEED,
                format!(
                    "the tool approaches the cut {} mm at its cutting feed of {} mm/min: {}",
                    round_to(a.length, 3),
                    round_to(a.speed * 60.0, 3),
                    seconds(a.time)
                ),
            )
            .with_help("lower the strategy's retract (or safe) height, or start the cut nearer the part: the approach runs from where the rapid stops"),
        );
    }
    let air: f64 = approaches.iter().map(|a| a.air_time).sum();
    if air > AIR_AT_LEAST && air > AIR_SHARE * feed_time && air - warned > AIR_AT_LEAST {
        out.push(
            warning(
                head,
                codes::AIR_CUTTING,
                format!(
                    "{} of the {} at feed is spent in the air, approaching the cut ({} approaches, {:.0} %)",
                    seconds(air),
                    seconds(feed_time),
                    approaches.len(),
                    100.0 * air / feed_time
                ),
            )
            .with_help("lower the retract height between passes: every approach runs at the cutting feed from where the rapid stops"),
        );
    }
    out
}

#[derive(Clone, Copy)]
enum Spindle {
    Stopped,
    Constant(f64),
    SurfaceSpeed { surface_speed: f64, cap: f64 },
}

/// The path speed (mm/s) of a move of `length` at `feed`, the spindle as
/// it is and the tool at radius `x` (a lathe's X).
fn speed(feed: Feed, spindle: Spindle, x: f64, length: f64) -> f64 {
    match feed {
        Feed::PerTime(v) => v,
        Feed::InverseTime(t) => length / t,
        Feed::PerRevolution(f) => {
            let w = match spindle {
                Spindle::Stopped => return f64::NAN,
                Spindle::Constant(w) => w,
                Spindle::SurfaceSpeed { surface_speed, cap } => {
                    let r = x.abs();
                    if r > 0.0 {
                        (surface_speed / r).min(cap)
                    } else {
                        cap
                    }
                }
            };
            f * w
        }
    }
}

/// `at` with the axes `to` moves (NaN keeps an axis).
fn merged(at: [f64; 4], to: Position) -> [f64; 4] {
    let mut out = at;
    for (o, t) in out.iter_mut().zip(to.axes()) {
        if !t.is_nan() {
            *o = t;
        }
    }
    out
}

/// The straight distance over X, Y and Z between two positions, axes not
/// yet known counted as not moving.
fn distance(a: [f64; 4], b: [f64; 4]) -> f64 {
    (0..3)
        .map(|i| {
            let d = b[i] - a[i];
            if d.is_finite() { d * d } else { 0.0 }
        })
        .sum::<f64>()
        .sqrt()
}

fn warning(head: &JobHead, code: &'static str, msg: String) -> Diagnostic {
    let (file, span) = head.site;
    Diagnostic::warning(code, msg, file, span).with_label("this job")
}

fn round_to(v: f64, digits: i32) -> f64 {
    let k = 10f64.powi(digits);
    (v * k).round() / k
}

/// `53 s`, `2 min 5 s`, `5 h 28 min`.
fn seconds(s: f64) -> String {
    if s >= 3600.0 {
        hours_minutes(s)
    } else if s < 60.0 {
        format!("{s:.0} s")
    } else {
        let m = (s / 60.0).floor();
        format!("{m} min {:.0} s", s - 60.0 * m)
    }
}

/// `59 h 46 min`.
fn hours_minutes(s: f64) -> String {
    let total = (s / 60.0).round();
    let h = (total / 60.0).floor();
    format!("{h} h {} min", total - 60.0 * h)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_approach_at_the_finish_feed_is_timed() {
        // A lathe's start: spindle at 1500 rpm, rapid to Z 5, X 3, then
        // 4.4 mm down at 2 um/rev (3 mm/min), then the cut.
        let w = 1500.0 * 2.0 * std::f64::consts::PI / 60.0;
        let f = 0.002 / (2.0 * std::f64::consts::PI);
        let stream = [
            Move::SpindleOn(w),
            Move::Rapid(Position::xz(f64::NAN, 5.0)),
            Move::Rapid(Position::xz(3.0, f64::NAN)),
            Move::Linear {
                to: Position::xz(3.0, 0.6),
                feed: Some(Feed::PerRevolution(f)),
            },
            Move::Linear {
                to: Position::xz(0.0, 0.0),
                feed: None,
            },
        ];
        let (approaches, feed_time) = feed_in_air(&stream);
        assert_eq!(approaches.len(), 1);
        let a = approaches[0];
        assert!((a.length - 4.4).abs() < 1e-12, "{a:?}");
        assert!((a.speed * 60.0 - 3.0).abs() < 1e-9, "{a:?}");
        assert!((a.time - 88.0).abs() < 1e-9, "{a:?}");
        let cut = (9.0f64 + 0.36).sqrt() / (3.0 / 60.0);
        assert!((feed_time - 88.0 - cut).abs() < 1e-9, "{feed_time}");
    }

    #[test]
    fn an_approach_through_air_then_at_feed_is_timed_by_its_last_move() {
        // A lathe's approach as `plan::approach` writes it: a rapid to
        // 0.1 mm over the top, 1.5 mm down at 100 mm/min, the last 0.1 mm
        // at 0.05 mm/min (two minutes), then the cut across.
        let stream = [
            Move::SpindleOn(100.0),
            Move::Rapid(Position::xz(3.0, 0.1)),
            Move::Linear {
                to: Position::xz(3.0, -1.4),
                feed: Some(Feed::PerTime(100.0 / 60.0)),
            },
            Move::Linear {
                to: Position::xz(3.0, -1.5),
                feed: Some(Feed::PerTime(0.05 / 60.0)),
            },
            Move::Linear {
                to: Position::xz(0.0, 0.0),
                feed: None,
            },
        ];
        let (approaches, _) = feed_in_air(&stream);
        assert_eq!(approaches.len(), 1);
        let a = approaches[0];
        assert!((a.length - 0.1).abs() < 1e-12, "{a:?}");
        assert!((a.time - 120.0).abs() < 1e-9, "{a:?}");
        assert!((a.air_time - 120.9).abs() < 1e-9, "{a:?}");
    }

    #[test]
    fn durations_are_said_in_hours_and_minutes() {
        assert_eq!(
            hours_minutes(59.0 * 3600.0 + 46.0 * 60.0 + 5.0),
            "59 h 46 min"
        );
        assert_eq!(seconds(53.2), "53 s");
        assert_eq!(seconds(125.0), "2 min 5 s");
    }
}
