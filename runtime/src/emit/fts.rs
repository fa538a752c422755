//! Spirals (fast and slow tool servo): planned points to a program, and
//! to a servo table where the controller takes one.

use crate::dialect::Dialect;
use crate::moves::{self, Position};
use crate::plan::optimise::{self};
use crate::post::format::push_fixed;
use crate::post::{ProgramError, ProgramWriter};
use std::f64::consts::PI;
use std::fmt::Write as _;

/// A LinuxCNC program for a spiral (fast or slow tool servo), written as
/// the planner hands over its points: X (radius, G8) and C (degrees,
/// counted on from the start) on the spiral, the nose-centre height on Z,
/// each move timed by inverse-time feed (G93: F = 1/minutes). LinuxCNC has
/// no fast-axis word its interpreter accepts, so a fast tool servo's
/// motion is programmed on Z (the form of a slow-tool-servo program);
/// controllers with a W axis get their own dialect.
pub struct FtsProgram {
    writer: ProgramWriter,
    safe_w: f64,
    /// The last point written (None before the first).
    last: Option<crate::plan::fts::SpiralPoint>,
    /// Where the fast axis goes when the dialect takes it as a table.
    table: Option<FtsTable>,
}

/// The fast-tool-servo table written beside a program: one row per
/// spiral point, `C X W` (spindle angle in degrees counted on from the
/// start, the radius and the fast axis's nose-centre height, mm).
struct FtsTable {
    name: String,
    text: String,
    /// The last point the program itself moved to.
    programmed: Option<crate::plan::fts::SpiralPoint>,
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
            last: None,
            table,
        })
    }

    /// The move stream of spiral points: the first is reached by rapids
    /// above the part and a one-second plunge.
    pub fn moves(
        last: Option<crate::plan::fts::SpiralPoint>,
        safe_w: f64,
        points: &[crate::plan::fts::SpiralPoint],
    ) -> Vec<moves::Move> {
        let mut out = Vec::with_capacity(points.len() + 3);
        let mut last = last;
        for p in points {
            match last {
                None => out.extend(approach(p, p.w, safe_w)),
                Some(q) => out.push(moves::Move::Linear {
                    to: Position::xzc(p.x, p.w, p.c),
                    feed: Some(moves::Feed::InverseTime(p.t - q.t)),
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
    pub fn extend(&mut self, points: &[crate::plan::fts::SpiralPoint]) -> Result<(), ProgramError> {
        if self.table.is_some() {
            return self.extend_table(points);
        }
        let stream = Self::moves(self.last, self.safe_w, points);
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
        points: &[crate::plan::fts::SpiralPoint],
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
                    self.writer.write(&revolution(&q, p))?;
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
                self.writer.write(&revolution(&q, &p))?;
            }
            for line in self.writer.dialect().fts_off.clone() {
                self.writer
                    .block_line(&line.replace("{table}", &table.name))?;
            }
        }
        self.writer.write(&moves::Move::Rapid(Position {
            z: self.safe_w,
            ..Position::KEEP
        }))?;
        self.writer.finish()
    }
}

/// Rapids up to the safe height first, then over the spiral's first
/// point, then a one-second plunge of Z to `z`.
fn approach(p: &crate::plan::fts::SpiralPoint, z: f64, safe_w: f64) -> [moves::Move; 3] {
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
fn revolution(q: &crate::plan::fts::SpiralPoint, p: &crate::plan::fts::SpiralPoint) -> moves::Move {
    moves::Move::Linear {
        to: Position {
            x: p.x,
            c: p.c,
            ..Position::KEEP
        },
        feed: Some(moves::Feed::InverseTime(p.t - q.t)),
    }
}
