//! Spirals (fast and slow tool servo): planned points to a program, and
//! to a servo table where the controller takes one.

use crate::dialect::Dialect;
use crate::moves::{self, Position};
use crate::plan::optimise::{self};
use crate::post::format::{fixed_units, push_fixed};
use crate::post::writer::inverse_time_not_faster;
use crate::post::{ProgramError, ProgramWriter};
use std::f64::consts::PI;
use std::fmt::Write as _;

/// A LinuxCNC program for a spiral (fast or slow tool servo), written as
/// the planner hands over its points: X (radius, G8) and C (degrees,
/// counted on from the start) on the spiral, the nose-centre height on Z,
/// each move timed by inverse-time feed (G93: F = 1/minutes). A fast tool
/// servo's motion is programmed on Z (the form of a slow-tool-servo
/// program), or where the machine gives the servo an axis of its own
/// (`servo_on`: LinuxCNC's U, V or W, configured as a joint with its own
/// velocity limit) on that letter, the Z slide held at 0 and the tool tip
/// at Z plus the servo; controllers that take a servo table get it.
pub struct FtsProgram {
    writer: ProgramWriter,
    safe_w: f64,
    /// The servo is written on its own letter (`servo_on`).
    servo: bool,
    /// The last point written (None before the first).
    last: Option<crate::plan::spiral::SpiralPoint>,
    /// Where the fast axis goes when the dialect takes it as a table.
    table: Option<FtsTable>,
    /// The spindle's limit (rad/s) and C's printed decimals, once set.
    spindle: Option<SpindleHold>,
}

/// The spindle's limit every move's C is held under, as printed.
#[derive(Clone, Copy, Debug)]
pub struct SpindleHold {
    /// rad/s.
    pub max_speed: f64,
    /// Decimals of C (degrees) as the dialect prints it.
    pub c_decimals: u32,
}

impl SpindleHold {
    /// The time (s) of a move planned to take `t` that turns C from `c0`
    /// to `c1` (rad): `t`, or where C as printed (each end rounded to its
    /// decimals) would turn faster than the limit, the least time that
    /// holds it, F printed never faster.
    fn time(&self, t: f64, c0: f64, c1: f64) -> f64 {
        let printed = |c: f64| {
            let scale = 10f64.powi(self.c_decimals as i32);
            fixed_units(c.to_degrees(), self.c_decimals)
                .map_or(c.to_degrees(), |n| n as f64 / scale)
        };
        let turned = (printed(c1) - printed(c0)).abs().to_radians();
        let least = inverse_time_not_faster(turned / self.max_speed);
        if t >= least { t } else { least }
    }
}

/// The fast-tool-servo table written beside a program: one row per
/// spiral point, `C X W` (spindle angle in degrees counted on from the
/// start, the radius and the fast axis's nose-centre height, mm).
struct FtsTable {
    name: String,
    text: String,
    /// The last point the program itself moved to.
    programmed: Option<crate::plan::spiral::SpiralPoint>,
}

impl FtsProgram {
    /// Starts a program: the header comments and the modal line, the
    /// controller's blending held to its share of the path tolerance. With
    /// `table` (the table file's name), the fast axis's motion goes to that
    /// table and the program moves X and C one revolution a block, the
    /// servo following the table (the dialect's `fts_on` lines arm it).
    pub fn new(
        dialect: &Dialect,
        job: &str,
        header: &[String],
        resolution: f64,
        chord_tolerance: f64,
        safe_w: f64,
        table: Option<&str>,
    ) -> Result<FtsProgram, ProgramError> {
        let table = table.map(|name| {
            let mut text = String::new();
            let _ = writeln!(
                text,
                "# lensc {} fast-tool-servo table for job {job}",
                env!("CARGO_PKG_VERSION")
            );
            text.push_str(
                "# C spindle angle (deg, counted on from the start), X radius (mm), W nose-centre height (mm, +W out of the material)\n",
            );
            FtsTable {
                name: name.to_string(),
                text,
                programmed: None,
            }
        });
        Ok(FtsProgram {
            writer: super::xzc_lathe_writer(
                dialect,
                job,
                header,
                resolution,
                chord_tolerance * optimise::BLEND_SHARE,
            )?,
            safe_w,
            servo: false,
            last: None,
            table,
            spindle: None,
        })
    }

    /// Writes the servo's motion on its own axis `letter` (U, V or W),
    /// the Z slide held at 0: the tool tip is Z plus the servo.
    pub fn servo_on(&mut self, letter: char) {
        self.writer.servo_in_y(letter);
        self.servo = true;
    }

    /// Holds every move's C under the spindle's limit as printed (a spiral
    /// planned at the limit reads above it where C's rounding lengthens a
    /// step): such a move takes the least time that holds it.
    pub fn hold_spindle_under(&mut self, max_speed: f64) {
        self.spindle = Some(SpindleHold {
            max_speed,
            c_decimals: self.writer.dialect().c_decimals,
        });
    }

    /// The move stream of spiral points: the first is reached by rapids
    /// above the part and a one-second plunge.
    /// With `servo` the servo's motion goes on its own axis (in the
    /// stream's Y, `Position::xzc_servo`), Z held at 0.
    pub fn moves(
        last: Option<crate::plan::spiral::SpiralPoint>,
        safe_w: f64,
        points: &[crate::plan::spiral::SpiralPoint],
        spindle: Option<SpindleHold>,
        servo: bool,
    ) -> Vec<moves::Move> {
        let mut out = Vec::with_capacity(points.len() + 3);
        let mut last = last;
        let at = |p: &crate::plan::spiral::SpiralPoint| {
            if servo {
                Position::xzc_servo(p.x, 0.0, p.c, p.w)
            } else {
                Position::xzc(p.x, p.w, p.c)
            }
        };
        for p in points {
            match last {
                None if servo => {
                    // The plunge brings the slide to 0 and the servo to
                    // the first point together: the tip from above the
                    // part to it.
                    let [above, over, _] = approach(p, p.w, safe_w);
                    out.extend([
                        above,
                        over,
                        moves::Move::Linear {
                            to: at(p),
                            feed: Some(moves::Feed::InverseTime(1.0)),
                        },
                    ]);
                }
                None => out.extend(approach(p, p.w, safe_w)),
                Some(q) => out.push(moves::Move::Linear {
                    to: at(p),
                    feed: Some(moves::Feed::InverseTime(
                        spindle.map_or(p.t - q.t, |s| s.time(p.t - q.t, q.c, p.c)),
                    )),
                }),
            }
            last = Some(*p);
        }
        out
    }

    /// Calls the tool and sets the coolant (`ProgramWriter::call_tool`):
    /// once, before the first point.
    pub fn call_tool(&mut self, start: &moves::Start) -> Result<(), ProgramError> {
        self.writer.call_tool(start)
    }

    /// Appends points in spiral order.
    pub fn extend(
        &mut self,
        points: &[crate::plan::spiral::SpiralPoint],
    ) -> Result<(), ProgramError> {
        if self.table.is_some() {
            return self.extend_table(points);
        }
        let stream = Self::moves(self.last, self.safe_w, points, self.spindle, self.servo);
        if let Some(p) = points.last() {
            self.last = Some(*p);
        }
        self.writer.write_all(&stream)
    }

    /// Table mode: every point a row; the program moves to the first
    /// point, arms the servo, and then to the point that ends each whole
    /// revolution, X and C moving linearly as on the spiral.
    fn extend_table(
        &mut self,
        points: &[crate::plan::spiral::SpiralPoint],
    ) -> Result<(), ProgramError> {
        let decimals = self.writer.decimals();
        let c_decimals = self.writer.dialect().c_decimals;
        for p in points {
            let table = self.table.as_mut().expect("table mode");
            let row_start = table.text.len();
            let ok = push_fixed(&mut table.text, p.c.to_degrees(), c_decimals)
                && {
                    table.text.push(' ');
                    push_fixed(&mut table.text, p.x, decimals)
                }
                && {
                    table.text.push(' ');
                    push_fixed(&mut table.text, p.w, decimals)
                };
            if !ok {
                table.text.truncate(row_start);
                return Err(ProgramError::NotPrintable {
                    word: 'W',
                    value: p.w,
                });
            }
            table.text.push('\n');
            match table.programmed {
                None => {
                    let name = table.name.clone();
                    table.programmed = Some(*p);
                    // The slow Z holds the servo's zero at the part's
                    // vertex: the table's W is the whole height.
                    let [above, to_start, plunge] = approach(p, 0.0, self.safe_w);
                    self.writer.write_all(&[above, to_start])?;
                    for line in self.writer.dialect().fts_on.clone() {
                        self.writer.block_line(&line.replace("{table}", &name))?;
                    }
                    self.writer.write(&plunge)?;
                }
                Some(q) if p.c - q.c >= 2.0 * PI * (1.0 - 1e-12) => {
                    table.programmed = Some(*p);
                    self.writer.write(&revolution(&q, p, self.spindle))?;
                }
                Some(_) => {}
            }
            self.last = Some(*p);
        }
        Ok(())
    }

    /// The table text written since the last call (empty without a table).
    pub fn take_table_text(&mut self) -> String {
        self.table
            .as_mut()
            .map(|t| std::mem::take(&mut t.text))
            .unwrap_or_default()
    }

    /// The text written since the last call, for the caller to pass on
    /// (a program of millions of moves need not be held whole).
    pub fn take_text(&mut self) -> Result<String, ProgramError> {
        self.writer.take_text()
    }

    /// Retracts and ends the program; the text not yet taken.
    pub fn finish(mut self) -> Result<String, ProgramError> {
        if let Some(table) = &self.table {
            if let (Some(q), Some(p)) = (table.programmed, self.last)
                && q != p
            {
                self.writer.write(&revolution(&q, &p, self.spindle))?;
            }
            for line in self.writer.dialect().fts_off.clone() {
                self.writer
                    .block_line(&line.replace("{table}", &table.name))?;
            }
        }
        // The slide retracts; a servo on its own axis goes back to its
        // zero with it.
        self.writer.write(&moves::Move::Rapid(Position {
            z: self.safe_w,
            y: if self.servo { 0.0 } else { f64::NAN },
            ..Position::KEEP
        }))?;
        self.writer.finish()
    }
}

/// Rapids up to the safe height first, then over the spiral's first
/// point, then a one-second plunge of Z to `z`.
fn approach(p: &crate::plan::spiral::SpiralPoint, z: f64, safe_w: f64) -> [moves::Move; 3] {
    [
        moves::Move::Rapid(Position {
            z: safe_w,
            ..Position::KEEP
        }),
        moves::Move::Rapid(Position {
            x: p.x,
            c: p.c,
            ..Position::KEEP
        }),
        moves::Move::Linear {
            to: Position {
                z,
                ..Position::KEEP
            },
            feed: Some(moves::Feed::InverseTime(1.0)),
        },
    ]
}

/// X and C from spiral point `q` to `p` in the time the spiral takes.
fn revolution(
    q: &crate::plan::spiral::SpiralPoint,
    p: &crate::plan::spiral::SpiralPoint,
    spindle: Option<SpindleHold>,
) -> moves::Move {
    moves::Move::Linear {
        to: Position {
            x: p.x,
            c: p.c,
            ..Position::KEEP
        },
        feed: Some(moves::Feed::InverseTime(
            spindle.map_or(p.t - q.t, |s| s.time(p.t - q.t, q.c, p.c)),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The steps of a spiral near its centre at the spindle's limit: C
    /// printed to 5 decimals of a degree, each step's F as printed read
    /// back (the reader's rule: |ΔC| F / 360 ≤ the limit in rpm).
    #[test]
    fn no_step_turns_c_faster_than_the_spindle_limit_as_printed() {
        let hold = SpindleHold {
            max_speed: 1000.0 / 60.0 * 2.0 * PI,
            c_decimals: 5,
        };
        let printed = |c: f64| (c.to_degrees() * 1e5).round() / 1e5;
        let f_printed = |t: f64| (60.0 / t * 1e3).round() / 1e3;
        let mut slowed = 0;
        for k in 0..2000 {
            // Steps of 1° to 350° planned at exactly 1000 rpm.
            let c0 = 0.37 + k as f64 * 0.001;
            let c1 = c0 + (1.0 + k as f64 * 0.17).to_radians();
            let planned = (c1 - c0) / hold.max_speed;
            let t = hold.time(planned, c0, c1);
            assert!(t >= planned);
            slowed += usize::from(t > planned);
            let rpm = (printed(c1) - printed(c0)).abs() * f_printed(t) / 360.0;
            assert!(rpm <= 1000.0 * (1.0 + 1e-12), "{k}: {rpm}");
        }
        // Rounding lengthens about half the printed steps.
        assert!(slowed > 200, "{slowed}");
    }
}
