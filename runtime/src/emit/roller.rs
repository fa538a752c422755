//! Roller helix turning: planned passes to a program.

use crate::dialect::Dialect;
use crate::moves::{self, Position};
use crate::post::writer::inverse_time_not_faster;
use crate::post::{ProgramError, ProgramWriter};
use std::f64::consts::PI;

/// A LinuxCNC program for roller helix turning: X (the nose centre's
/// distance from the roller axis, G8), Z along the roller, C the spindle
/// angle in degrees counted on from the first pass; each pass starts on a
/// whole turn after the last, moves timed by inverse-time feed (G93):
/// each at the spindle's pace over its C step, or slower where X and Z
/// together would feed above the machine's limit.
pub struct RollerProgram {
    writer: ProgramWriter,
    safe_x: f64,
    spindle_speed: f64,
    /// The machine's feed limit (mm/s) and resolution (mm).
    max_feed: f64,
    resolution: f64,
    /// The moves of each pass the feed limit slowed.
    limited: Vec<FeedLimited>,
    /// C (rad) where the current pass started, and the last point.
    c_base: f64,
    last: Option<crate::plan::roller::RollerPoint>,
    pass: usize,
}

/// The moves of one pass that the machine's feed limit slowed below the
/// spindle's pace, and the time (s) that added to the pass.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FeedLimited {
    pub moves: usize,
    pub added_time: f64,
}

/// Where the machine's limits leave a roller program's moves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RollerLimits {
    /// The machine's resolution (mm): the points are printed to it.
    pub resolution: f64,
    /// The machine's feed limit (mm/s) along the X–Z path.
    pub max_feed: f64,
}

impl RollerProgram {
    /// The roller's points are the exact nose centres at each C step:
    /// blending is held to the machine's resolution.
    pub fn new(
        dialect: &Dialect,
        job: &str,
        header: &[String],
        limits: RollerLimits,
        safe_x: f64,
        spindle_speed: f64,
    ) -> Result<Self, ProgramError> {
        let resolution = limits.resolution;
        Ok(RollerProgram {
            writer: super::xzc_lathe_writer(dialect, job, header, resolution, resolution)?,
            safe_x,
            spindle_speed,
            max_feed: limits.max_feed,
            resolution,
            limited: Vec::new(),
            c_base: 0.0,
            last: None,
            pass: usize::MAX,
        })
    }

    /// Calls the tool and sets the coolant (`ProgramWriter::call_tool`),
    /// then rapids X out to the safe radius before any other move: once,
    /// before the first pass.
    pub fn call_tool(&mut self, start: &moves::Start) -> Result<(), ProgramError> {
        self.writer.call_tool(start)?;
        self.writer.write(&moves::Move::Rapid(Position {
            x: self.safe_x,
            ..Position::KEEP
        }))
    }

    /// Appends points of pass `pass`; a new pass retracts X, moves to its
    /// start on the next whole turn of C, and plunges in one second.
    pub fn extend(
        &mut self,
        pass: usize,
        points: &[crate::plan::roller::RollerPoint],
    ) -> Result<(), ProgramError> {
        let tau = 2.0 * PI;
        let mut stream = Vec::with_capacity(points.len() + 3);
        for p in points {
            if pass != self.pass {
                if let Some(last) = self.last {
                    let c_end = self.c_base + last.c;
                    self.c_base = ((c_end / tau).floor() + 1.0) * tau;
                    stream.push(moves::Move::Rapid(Position {
                        x: self.safe_x,
                        ..Position::KEEP
                    }));
                }
                self.pass = pass;
                stream.push(moves::Move::Rapid(Position::xzc(
                    self.safe_x,
                    p.z,
                    self.c_base + p.c,
                )));
                let (time, _) = self.move_time(1.0, p.x - self.safe_x, 0.0);
                stream.push(moves::Move::Linear {
                    to: Position {
                        x: p.x,
                        ..Position::KEEP
                    },
                    feed: Some(moves::Feed::InverseTime(time)),
                });
            } else {
                let last = self.last.expect("a pass has begun");
                let pace = (p.c - last.c) / self.spindle_speed;
                let (time, slowed) = self.move_time(pace, p.x - last.x, p.z - last.z);
                if slowed {
                    if self.limited.len() <= pass {
                        self.limited.resize(pass + 1, FeedLimited::default());
                    }
                    self.limited[pass].moves += 1;
                    self.limited[pass].added_time += time - pace;
                }
                stream.push(moves::Move::Linear {
                    to: Position::xzc(p.x, p.z, self.c_base + p.c),
                    feed: Some(moves::Feed::InverseTime(time)),
                });
            }
            self.last = Some(*p);
        }
        self.writer.write_all(&stream)
    }

    /// The time (s) of a move of `dx`, `dz` (mm) planned to take `pace`:
    /// `pace`, or — where X and Z together would feed above the machine's
    /// limit — the least time that holds it, and true. The limit is held
    /// on the chord as printed (each coordinate may stray half a
    /// resolution step, so each axis' travel is taken one step longer)
    /// and by the F word as printed (rounded never faster).
    fn move_time(&self, pace: f64, dx: f64, dz: f64) -> (f64, bool) {
        let r = self.resolution;
        let chord = (dx.abs() + r).hypot(dz.abs() + r);
        let least = inverse_time_not_faster(chord / self.max_feed);
        if pace >= least {
            (pace, false)
        } else {
            (least, true)
        }
    }

    /// The moves of each pass the machine's feed limit slowed (a pass
    /// with none may be missing from the end).
    pub fn feed_limited(&self) -> &[FeedLimited] {
        &self.limited
    }

    /// The text written since the last call.
    pub fn take_text(&mut self) -> Result<String, ProgramError> {
        self.writer.take_text()
    }

    /// Retracts and ends the program; the text not yet taken.
    pub fn finish(mut self) -> Result<String, ProgramError> {
        self.writer.write(&moves::Move::Rapid(Position {
            x: self.safe_x,
            ..Position::KEEP
        }))?;
        self.writer.finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::roller::RollerPoint;
    use crate::reader::{self, MachineLimits, Rule};

    /// 0.025° steps at 60 rpm (69.4 µs each) on a 1 nm machine feeding at
    /// most 1500 mm/min; X steps 10 µm on the third step (8.6 m/min at the
    /// spindle's pace) and 1 nm on the others.
    fn program(max_feed_mm_min: f64, x_diameter: bool) -> (String, Vec<FeedLimited>) {
        let dialect = dialect(x_diameter);
        let limits = RollerLimits {
            resolution: 1e-6,
            max_feed: max_feed_mm_min / 60.0,
        };
        let mut p = RollerProgram::new(&dialect, "t", &[], limits, 5.0, TAU_RAD_S).expect("writer");
        p.call_tool(&moves::Start::default()).expect("tool");
        let step = 0.025f64.to_radians();
        let points: Vec<RollerPoint> = (0..6)
            .map(|k| RollerPoint {
                c: k as f64 * step,
                z: k as f64 * 1e-6,
                x: 3.0 + if k >= 3 { 0.01 } else { 0.0 } + k as f64 * 1e-6,
            })
            .collect();
        p.extend(0, &points).expect("moves");
        let limited = p.feed_limited().to_vec();
        (p.finish().expect("end"), limited)
    }

    const TAU_RAD_S: f64 = std::f64::consts::TAU;

    /// LinuxCNC with X a radius (G8) or a diameter (G7).
    fn dialect(x_diameter: bool) -> Dialect {
        let mut d = Dialect::linuxcnc();
        if x_diameter {
            d.lathe_x_diameter = true;
            d.lathe_setup = vec!["G18 G21 G90 G7 G40 G49 G80".into()];
        }
        d
    }

    fn feed_findings(text: &str, dialect: &Dialect) -> Vec<Rule> {
        let machine = MachineLimits {
            lathe: true,
            travel: [None; 4],
            max_feed: Some(1500.0),
            max_spindle_rpm: Some(3000.0),
            servo: None,
        };
        reader::read(text, dialect, &machine)
            .into_iter()
            .map(|f| f.rule)
            .filter(|r| matches!(r, Rule::FeedTooHigh | Rule::SpindleTooFast))
            .collect()
    }

    fn feeds(text: &str) -> Vec<f64> {
        text.lines()
            .filter(|l| l.contains(" C"))
            .filter_map(|l| l.split(" F").nth(1))
            .map(|f| f.trim().parse().expect("F"))
            .collect()
    }

    #[test]
    fn a_step_the_spindle_would_take_too_fast_is_slowed_to_the_feed_limit() {
        for diameter in [false, true] {
            let (text, limited) = program(1500.0, diameter);
            assert_eq!(feed_findings(&text, &dialect(diameter)), [], "{text}");
            // The spindle's pace: 60 / 69.444 µs = 864 000 per minute.
            let pace = 60.0 / (0.025f64.to_radians() / TAU_RAD_S);
            let f = feeds(&text);
            assert_eq!(f.len(), 5, "{text}");
            for (i, &fi) in f.iter().enumerate() {
                if i == 2 {
                    // 10.001 µm of X, 1 µm of Z, at 1500 mm/min, held on
                    // the chord one resolution step longer per axis.
                    let least = 1500.0 / (10.002e-3f64).hypot(2e-6);
                    assert!(fi <= least && fi > least * (1.0 - 1e-6), "{fi} {least}");
                } else {
                    assert!((fi - pace).abs() < 1e-3, "{i}: {fi}");
                }
            }
            assert_eq!(limited.len(), 1);
            assert_eq!(limited[0].moves, 1);
            let added = 60.0 / f[2] - 60.0 / pace;
            assert!((limited[0].added_time - added).abs() < 1e-9);
        }
    }

    #[test]
    fn without_the_limit_the_reader_finds_the_step_too_fast() {
        let (text, limited) = program(1e9, false);
        assert!(limited.is_empty());
        assert_eq!(
            feed_findings(&text, &Dialect::linuxcnc()),
            [Rule::FeedTooHigh]
        );
    }

    #[test]
    fn inverse_time_is_never_printed_faster_than_asked() {
        for t in [69.4e-6, 1e-4, 0.37, 1.0, 7.0, 123.456] {
            let u = crate::post::writer::inverse_time_not_faster(t);
            assert!(u >= t);
            let f = 60.0 / u;
            assert_eq!((f * 1e3).round() / 1e3, f);
            assert!(f <= 60.0 / t * (1.0 + 1e-12) && f > 60.0 / t - 1e-3);
        }
        // A time that is already a whole number of units is kept.
        for f in [1000.0, 864_000.0, 0.001, 59.999] {
            assert_eq!(
                60.0 / crate::post::writer::inverse_time_not_faster(60.0 / f),
                f
            );
        }
    }
}
