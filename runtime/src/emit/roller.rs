//! Roller helix turning: planned passes to a program.

use crate::dialect::Dialect;
use crate::moves::{self, Position};
use crate::post::{ProgramError, ProgramWriter};
use std::f64::consts::PI;

/// A LinuxCNC program for roller helix turning: X (the nose centre's
/// distance from the roller axis, G8), Z along the roller, C the spindle
/// angle in degrees counted on from the first pass; each pass starts on a
/// whole turn after the last, moves timed by inverse-time feed (G93).
pub struct RollerProgram {
    writer: ProgramWriter,
    safe_x: f64,
    spindle_speed: f64,
    /// C (rad) where the current pass started, and the last point.
    c_base: f64,
    last: Option<crate::plan::roller::RollerPoint>,
    pass: usize,
}

impl RollerProgram {
    /// The roller's points are the exact nose centres at each C step:
    /// blending is held to the machine's resolution.
    pub fn new(
        dialect: &Dialect,
        job: &str,
        header: &[String],
        resolution: f64,
        safe_x: f64,
        spindle_speed: f64,
    ) -> Result<Self, ProgramError> {
        Ok(RollerProgram {
            writer: super::xzc_lathe_writer(dialect, job, header, resolution, resolution)?,
            safe_x,
            spindle_speed,
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
                stream.push(moves::Move::Linear {
                    to: Position {
                        x: p.x,
                        ..Position::KEEP
                    },
                    feed: Some(moves::Feed::InverseTime(1.0)),
                });
            } else {
                let last = self.last.expect("a pass has begun");
                stream.push(moves::Move::Linear {
                    to: Position::xzc(p.x, p.z, self.c_base + p.c),
                    feed: Some(moves::Feed::InverseTime(
                        (p.c - last.c) / self.spindle_speed,
                    )),
                });
            }
            self.last = Some(*p);
        }
        self.writer.write_all(&stream)
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
