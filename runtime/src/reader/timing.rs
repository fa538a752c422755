//! How long the control takes over each line of a program, read from its
//! text by the controller's rules: the moves the line makes, at the feed
//! in force (per minute, per revolution at the spindle's speed, or in
//! inverse time). For the delivery check of the bytes a streamed program
//! needs each second, window by window (`lensc-build`'s `delivery`).
//!
//! Rapids take no time here (their speed is the machine's, not the
//! program's): a stretch of program with one in it is held to a higher
//! byte rate than it needs, never a lower. Acceleration is not modelled:
//! a move takes its length at the programmed feed.

use super::modal::{FeedMode, State};
use super::{Executed, MachineLimits, Path, Reader, pieces};
use crate::dialect::Dialect;
use crate::moves::Plane;

/// One line of a program: its bytes (with its line break), the seconds
/// the control takes over the moves it makes, and what moves they are.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LineTime {
    pub bytes: u32,
    pub seconds: f64,
    /// The line makes a rapid (the tool moves in the air).
    pub rapid: bool,
    /// The line makes a feed move (a line, an arc or a spline's piece).
    pub feed: bool,
}

/// Each line of `text` with the time its moves take, in order. A line
/// that moves nothing (a comment, a modal word, a spline's block before
/// its last, which the control reads before it moves) takes no time; a
/// spline's moves are timed on the line that completes it.
pub fn line_times(text: &str, dialect: &Dialect, machine: &MachineLimits) -> Vec<LineTime> {
    let mut r = Reader::new(dialect, machine);
    r.keep_moves();
    let mut out = Vec::new();
    for (start, line) in pieces(text) {
        r.line(line, start);
        let moves = r.take_moves();
        let seconds = moves.iter().map(|m| seconds(&r.state, m)).sum();
        out.push(LineTime {
            bytes: u32::try_from(line.len()).unwrap_or(u32::MAX),
            seconds,
            rapid: moves.iter().any(|m| m.path == Path::Rapid),
            feed: moves.iter().any(|m| m.path != Path::Rapid),
        });
    }
    out
}

/// The seconds `m` takes at the feed `s` holds after its line.
fn seconds(s: &State, m: &Executed) -> f64 {
    if m.path == Path::Rapid {
        return 0.0;
    }
    let d = |i: usize| match (m.from[i], m.to[i]) {
        (Some(a), Some(b)) => b - a,
        _ => 0.0,
    };
    let [dx, dy, dz, dc] = [d(0), d(1), d(2), d(3)];
    let length = match m.path {
        Path::Arc {
            plane,
            centre,
            turn,
            ..
        } => {
            // The start in the plane's order, and the axis off it.
            let at = |i: usize| m.from[i].unwrap_or(0.0);
            let (start, off) = match plane {
                Plane::Xy => ((at(0), at(1)), dz),
                Plane::Zx => ((at(2), at(0)), dy),
                Plane::Yz => ((at(1), at(2)), dx),
            };
            let radius = (start.0 - centre.0).hypot(start.1 - centre.1);
            (radius * turn).hypot(off)
        }
        _ => (dx * dx + dy * dy + dz * dz).sqrt(),
    };
    let unit = if s.metric == Some(false) { 25.4 } else { 1.0 };
    let Some(feed) = s.feed.filter(|f| f.is_finite() && *f > 0.0) else {
        return 0.0;
    };
    let t = match s.feed_mode {
        // F is the inverse of the move's minutes.
        Some(FeedMode::InverseTime) => 60.0 / feed,
        Some(FeedMode::PerRevolution) => {
            let radius = m.from[0].unwrap_or(0.0).abs();
            let rev_per_s = match s.css {
                Some(true) => {
                    // S in m/min (feet/min in inches) at the tool's radius,
                    // up to the cap.
                    let per = if s.metric == Some(false) {
                        304.8
                    } else {
                        1000.0
                    };
                    let surface = s.css_speed.unwrap_or(0.0) * per / 60.0;
                    let cap = s.cap.map_or(f64::INFINITY, |c| c / 60.0);
                    if radius > 0.0 {
                        (surface / (std::f64::consts::TAU * radius)).min(cap)
                    } else {
                        cap
                    }
                }
                _ => s.rpm.unwrap_or(0.0) / 60.0,
            };
            if rev_per_s.is_finite() && rev_per_s > 0.0 {
                length / (feed * unit * rev_per_s)
            } else {
                0.0
            }
        }
        _ if length > 0.0 => length / (feed * unit / 60.0),
        // A move of the rotary axis alone reads F in degrees a minute.
        _ => dc.abs() / (feed / 60.0),
    };
    if t.is_finite() { t } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lathe() -> MachineLimits {
        MachineLimits {
            lathe: true,
            travel: [None; 4],
            max_feed: None,
            max_spindle_rpm: None,
            servo: None,
        }
    }

    /// Each move's time by hand: 3 mm at 60 mm/min is 3 s; a quarter
    /// circle of radius 2 mm at 60 mm/min is π s; 0.5 mm at 0.01 mm/rev
    /// and 600 rpm is 5 s; G93 F30 is 2 s; a rapid and a line moving
    /// nothing take none.
    #[test]
    fn each_line_takes_its_moves_time_at_the_feed_in_force() {
        let program = "(a comment)\n\
            G18 G21 G90 G8 G40 G49 G80\n\
            T1 M6\n\
            G97 S600 M3\n\
            G0 X3 Z1\n\
            G94 G1 Z-2 F60\n\
            G2 X5 Z-4 I2 K0\n\
            G95 G1 X5.5 F0.01\n\
            G93 G1 X6 F30\n\
            M5\n\
            M2\n";
        let t = line_times(program, &Dialect::linuxcnc(), &lathe());
        let seconds: Vec<f64> = t.iter().map(|l| l.seconds).collect();
        let want = [
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            3.0,
            std::f64::consts::PI,
            5.0,
            2.0,
            0.0,
            0.0,
        ];
        assert_eq!(seconds.len(), want.len());
        for (i, (s, w)) in seconds.iter().zip(want).enumerate() {
            assert!((s - w).abs() < 1e-9, "line {}: {s} s, not {w}", i + 1);
        }
        assert_eq!(t[0].bytes, 12);
        assert!(t[4].rapid && !t[4].feed);
        assert!(t[5].feed && !t[5].rapid);
    }
}
