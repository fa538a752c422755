//! Post-processors: the dialect-independent move stream (`moves.rs`) to
//! program text, and each strategy's points to that stream. Every number
//! goes through `format::push_fixed`; a program with a value that cannot
//! be written is refused whole.

use std::f64::consts::PI;
use std::fmt::Write as _;

use crate::format::{decimals_for, fixed_units, push_fixed, push_units};
use crate::job::Job;
use crate::machine::Dialect;
use crate::moves::{self, Position};
use crate::toolpath::{Feed, Move, Toolpath};

/// What the program header states about where the job came from.
#[derive(Clone, Debug, PartialEq)]
pub struct Provenance {
    /// The source file as the user named it.
    pub source: String,
    /// FNV-1a 64 of the source text and every file it uses, in load order.
    pub source_hash: u64,
    pub lensc_version: String,
}

/// A program could not be written.
#[derive(Clone, Debug, PartialEq)]
pub enum ProgramError {
    /// A coordinate or feed is NaN, infinite or too large to print.
    NotPrintable { word: char, value: f64 },
    /// The dialect cannot express this move.
    Unsupported(String),
}

impl ProgramError {
    /// What is wrong, in plain words.
    pub fn message(&self) -> String {
        match self {
            ProgramError::NotPrintable { word, value } => {
                format!("the program would contain {word}{value}, which no controller accepts")
            }
            ProgramError::Unsupported(what) => {
                format!("the machine's dialect cannot express {what}")
            }
        }
    }
}

/// Writes a LinuxCNC (RS274NGC) lathe program for a profile-turning path.
pub fn emit(job: &Job, path: &Toolpath, prov: &Provenance) -> Result<String, ProgramError> {
    match job.machine.dialect {
        Dialect::LinuxCnc => emit_linuxcnc_lathe(job, path, prov),
    }
}

fn emit_linuxcnc_lathe(
    job: &Job,
    path: &Toolpath,
    prov: &Provenance,
) -> Result<String, ProgramError> {
    let centre_height = if job.tool.centre_height == 0.0 {
        String::new()
    } else {
        format!(
            ", edge {} mm off the spindle axis: X = sqrt[r² − h²] of the nose-centre radius r",
            num(job.tool.centre_height)
        )
    };
    let header = [
        format!("lensc {}: job {}", prov.lensc_version, job.name),
        format!("source {} fnv1a64 {:016x}", prov.source, prov.source_hash),
        "units mm; X is the radius [G8], Z along the spindle axis, +Z out of the material".into(),
        "coordinates are the centre of the tool nose; no cutter compensation".into(),
        format!("surface {}: {}", job.surface_name, job.surface.description),
        format!(
            "tool {}: round nose, nose radius {} mm{centre_height}",
            job.tool_name,
            num(job.tool.nose_radius)
        ),
        format!(
            "strategy {}: profile turning, {} points, chord tolerance {} nm{}",
            job.strategy_name,
            path.cut_points,
            num(job.strategy.chord_tolerance * 1e6),
            roughing_words(job, path)
        ),
        format!(
            "machine {}: {} lathe",
            job.machine_name,
            job.machine.dialect.name()
        ),
        format!("estimated cutting time {}", duration(path.cutting_time())),
    ];
    let mut w = LinuxCncWriter::new(
        &header,
        "G18 G21 G90 G8 G40 G49 G80 G94",
        "XZ",
        job.machine.resolution,
        job.strategy.chord_tolerance,
    );
    w.write_all(&turning_moves(job, path))?;
    Ok(w.finish())
}

/// The move stream of a profile-turning path: spindle on, the planner's
/// moves (X corrected for an edge set off centre), spindle off.
pub fn turning_moves(job: &Job, path: &Toolpath) -> Vec<moves::Move> {
    let feed = match job.strategy.feed {
        Feed::PerRevolution(f) => moves::Feed::PerRevolution(f),
        Feed::PerTime(v) => moves::Feed::PerTime(v),
    };
    // An edge set h off the axis cuts radius sqrt(X² + h²).
    let h = job.tool.centre_height;
    let corrected = |x: f64| {
        if h == 0.0 {
            x
        } else {
            x.signum() * (x * x - h * h).max(0.0).sqrt()
        }
    };
    let mut out = Vec::with_capacity(path.moves.len() + 2);
    out.push(moves::Move::SpindleOn(Some(job.strategy.spindle_speed)));
    out.extend(path.moves.iter().map(|m| match *m {
        Move::Rapid { x, z } => moves::Move::Rapid(Position::xz(corrected(x), z)),
        Move::Feed { x, z } => moves::Move::Linear {
            to: Position::xz(corrected(x), z),
            feed: Some(feed),
        },
    }));
    out.push(moves::Move::SpindleOff);
    out
}

/// Writes `text` as RS274NGC comments: no nested parentheses or control
/// characters, long text folded into several lines.
pub fn write_comment(out: &mut String, text: &str) {
    // RS274NGC comments cannot nest parentheses.
    let clean: String = text
        .chars()
        .map(|c| match c {
            '(' => '[',
            ')' => ']',
            c if c.is_control() => ' ',
            c => c,
        })
        .collect();
    // RS274NGC lines are limited (LinuxCNC: 256 characters): long
    // text is folded at ", " into several comments.
    const WIDTH: usize = 120;
    let mut line = String::new();
    let pieces = clean.split(", ").flat_map(|p| {
        // A piece with no ", " in it longer than a line: cut by characters.
        let chars: Vec<char> = p.chars().collect();
        chars
            .chunks(WIDTH)
            .map(|c| c.iter().collect::<String>())
            .collect::<Vec<_>>()
    });
    for (i, piece) in pieces.enumerate() {
        if i > 0 && line.chars().count() + piece.chars().count() + 2 > WIDTH {
            let _ = writeln!(out, "({line},)");
            line = String::from("  ");
        } else if i > 0 {
            line.push_str(", ");
        }
        line.push_str(&piece);
    }
    let _ = writeln!(out, "({line})");
}

/// ", after N roughing passes from …" for a job with stock, else "".
fn roughing_words(job: &Job, path: &Toolpath) -> String {
    use crate::toolpath::Stock;
    let Some(r) = job.strategy.roughing else {
        return String::new();
    };
    let stock = match r.stock {
        Stock::Flat { top } => format!("flat stock at Z{}", num(top)),
        Stock::Offset { allowance } => format!("stock {} mm over the surface", num(allowance)),
    };
    format!(
        ", after {} roughing passes from {stock}, at most {} mm each, {} mm left for the finish",
        path.roughing_passes,
        num(r.depth_of_cut),
        num(r.finish_allowance)
    )
}

fn word(out: &mut String, letter: char, value: f64, decimals: u32) -> Result<(), ProgramError> {
    if push_fixed(out, value, decimals) {
        Ok(())
    } else {
        Err(ProgramError::NotPrintable {
            word: letter,
            value,
        })
    }
}

/// A header figure to 10 decimals (0.1 pm in mm), trailing zeros trimmed:
/// no exponent, and `1e-5` shows as `0.00001`, not `0.000009999…`.
fn num(v: f64) -> String {
    let s = format!("{v:.10}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.to_string() }
}

fn duration(secs: f64) -> String {
    let total = secs.round() as u64;
    let (h, m, s) = (total / 3600, total / 60 % 60, total % 60);
    if h > 0 {
        format!("{h} h {m} min {s} s")
    } else if m > 0 {
        format!("{m} min {s} s")
    } else {
        format!("{s} s")
    }
}

/// A LinuxCNC program for a spiral (fast or slow tool servo), written as
/// the planner hands over its points: X (radius, G8) and C (degrees,
/// counted on from the start) on the spiral, the nose-centre height on Z,
/// each move timed by inverse-time feed (G93: F = 1/minutes). LinuxCNC has
/// no fast-axis word its interpreter accepts, so a fast tool servo's
/// motion is programmed on Z (the form of a slow-tool-servo program);
/// controllers with a W axis get their own dialect.
pub struct FtsProgram {
    writer: LinuxCncWriter,
    safe_w: f64,
    /// The last point written (None before the first).
    last: Option<crate::fts::SpiralPoint>,
}

/// Decimals of C in degrees: 1e-5° is 4 nm of arc at 25 mm.
const C_DECIMALS: u32 = 5;

impl FtsProgram {
    /// Starts a program: the header comments and the modal line, the
    /// controller's blending held to the chord tolerance.
    pub fn new(
        header: &[String],
        resolution: f64,
        chord_tolerance: f64,
        safe_w: f64,
    ) -> FtsProgram {
        FtsProgram {
            writer: LinuxCncWriter::new(
                header,
                "G18 G21 G90 G8 G40 G49 G80 G93",
                "XZC",
                resolution,
                chord_tolerance,
            ),
            safe_w,
            last: None,
        }
    }

    /// The move stream of spiral points: the first is reached by rapids
    /// above the part and a one-second plunge.
    pub fn moves(
        last: Option<crate::fts::SpiralPoint>,
        safe_w: f64,
        points: &[crate::fts::SpiralPoint],
    ) -> Vec<moves::Move> {
        let mut out = Vec::with_capacity(points.len() + 3);
        let mut last = last;
        for p in points {
            match last {
                None => {
                    out.push(moves::Move::Rapid(Position {
                        x: p.x,
                        c: p.c,
                        ..Position::KEEP
                    }));
                    out.push(moves::Move::Rapid(Position {
                        z: safe_w,
                        ..Position::KEEP
                    }));
                    out.push(moves::Move::Linear {
                        to: Position {
                            z: p.w,
                            ..Position::KEEP
                        },
                        feed: Some(moves::Feed::InverseTime(1.0)),
                    });
                }
                Some(q) => out.push(moves::Move::Linear {
                    to: Position::xzc(p.x, p.w, p.c),
                    feed: Some(moves::Feed::InverseTime(p.t - q.t)),
                }),
            }
            last = Some(*p);
        }
        out
    }

    /// Appends points in spiral order.
    pub fn extend(&mut self, points: &[crate::fts::SpiralPoint]) -> Result<(), ProgramError> {
        let stream = Self::moves(self.last, self.safe_w, points);
        if let Some(p) = points.last() {
            self.last = Some(*p);
        }
        self.writer.write_all(&stream)
    }

    /// The text written since the last call, for the caller to pass on
    /// (a program of millions of moves need not be held whole).
    pub fn take_text(&mut self) -> String {
        self.writer.take_text()
    }

    /// Retracts and ends the program; the text not yet taken.
    pub fn finish(mut self) -> Result<String, ProgramError> {
        self.writer.write(&moves::Move::Rapid(Position {
            z: self.safe_w,
            ..Position::KEEP
        }))?;
        Ok(self.writer.finish())
    }
}

/// The move stream of a raster: each pass reached by rapids at the safe
/// height, a plunge at the feed, the cut, a retract.
pub fn raster_moves(path: &crate::raster::RasterPath, feed: f64) -> Vec<moves::Move> {
    let safe = Position {
        z: path.safe_z,
        ..Position::KEEP
    };
    let mut out = vec![moves::Move::Rapid(safe)];
    for pass in &path.passes {
        let Some(first) = pass.first() else { continue };
        out.push(moves::Move::Rapid(Position {
            x: first[0],
            y: first[1],
            ..Position::KEEP
        }));
        out.push(moves::Move::Linear {
            to: Position {
                z: first[2],
                ..Position::KEEP
            },
            feed: Some(moves::Feed::PerTime(feed)),
        });
        out.extend(pass[1..].iter().map(|p| moves::Move::Linear {
            to: Position::xyz(p[0], p[1], p[2]),
            feed: None,
        }));
        out.push(moves::Move::Rapid(safe));
    }
    out
}

/// A LinuxCNC program for a raster on a 3-axis mill.
pub fn emit_mill_raster(
    header: &[String],
    path: &crate::raster::RasterPath,
    feed: f64,
    resolution: f64,
    chord_tolerance: f64,
) -> Result<String, ProgramError> {
    let mut w = LinuxCncWriter::new(
        header,
        "G17 G21 G90 G40 G49 G80 G94",
        "XYZ",
        resolution,
        chord_tolerance,
    );
    w.write_all(&raster_moves(path, feed))?;
    Ok(w.finish())
}

/// The move stream of a grinding pass: the wheel centre's X and Z, each
/// interval at the feed that moves the contact point at v_f (the interval
/// takes its contact-x length over v_f).
pub fn grinding_moves(
    path: &crate::grinding::GrindingPath,
    feed: f64,
    safe_z: f64,
) -> Vec<moves::Move> {
    let Some(first) = path.points.first() else {
        return Vec::new();
    };
    let mut out = vec![
        moves::Move::SpindleOn(None),
        moves::Move::Rapid(Position::xz(first.x, safe_z)),
        moves::Move::Linear {
            to: Position::xz(first.x, first.z),
            feed: Some(moves::Feed::PerTime(feed)),
        },
    ];
    for pair in path.points.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        let step = ((b.x - a.x).powi(2) + (b.z - a.z).powi(2)).sqrt();
        let dt = (b.contact_x - a.contact_x).abs() / feed;
        out.push(moves::Move::Linear {
            to: Position::xz(b.x, b.z),
            feed: Some(moves::Feed::PerTime(step / dt)),
        });
    }
    out.push(moves::Move::Rapid(Position {
        z: safe_z,
        ..Position::KEEP
    }));
    out.push(moves::Move::SpindleOff);
    out
}

/// A LinuxCNC program for a grinding pass: X (radius, G8) and Z of the
/// wheel centre.
pub fn emit_grinding(
    header: &[String],
    path: &crate::grinding::GrindingPath,
    feed: f64,
    safe_z: f64,
    resolution: f64,
) -> Result<String, ProgramError> {
    // Wheel centres are exact at each interval: blending held to the
    // machine's resolution.
    let mut w = LinuxCncWriter::new(
        header,
        "G18 G21 G90 G8 G40 G49 G80 G94",
        "XZ",
        resolution,
        resolution,
    );
    w.write_all(&grinding_moves(path, feed, safe_z))?;
    Ok(w.finish())
}

/// A LinuxCNC program for roller helix turning: X (the nose centre's
/// distance from the roller axis, G8), Z along the roller, C the spindle
/// angle in degrees counted on from the first pass; each pass starts on a
/// whole turn after the last, moves timed by inverse-time feed (G93).
pub struct RollerProgram {
    writer: LinuxCncWriter,
    safe_x: f64,
    spindle_speed: f64,
    /// C (rad) where the current pass started, and the last point.
    c_base: f64,
    last: Option<crate::roller::RollerPoint>,
    pass: usize,
}

impl RollerProgram {
    /// The roller's points are the exact nose centres at each C step:
    /// blending is held to the machine's resolution.
    pub fn new(header: &[String], resolution: f64, safe_x: f64, spindle_speed: f64) -> Self {
        RollerProgram {
            writer: LinuxCncWriter::new(
                header,
                "G18 G21 G90 G8 G40 G49 G80 G93",
                "XZC",
                resolution,
                resolution,
            ),
            safe_x,
            spindle_speed,
            c_base: 0.0,
            last: None,
            pass: usize::MAX,
        }
    }

    /// Appends points of pass `pass`; a new pass retracts X, moves to its
    /// start on the next whole turn of C, and plunges in one second.
    pub fn extend(
        &mut self,
        pass: usize,
        points: &[crate::roller::RollerPoint],
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
    pub fn take_text(&mut self) -> String {
        self.writer.take_text()
    }

    /// Retracts and ends the program; the text not yet taken.
    pub fn finish(mut self) -> Result<String, ProgramError> {
        self.writer.write(&moves::Move::Rapid(Position {
            x: self.safe_x,
            ..Position::KEEP
        }))?;
        Ok(self.writer.finish())
    }
}

/// The LinuxCNC (RS274NGC) post-processor: header comments, a modal line,
/// then the move stream, word by word. A word whose printed value has not
/// changed is left out (axes are modal); a feed is written when it or its
/// mode changes, and on every move in inverse time (G93 requires it); a
/// move that changes no printed axis is left out whole.
pub struct LinuxCncWriter {
    text: String,
    decimals: u32,
    /// Letters of the machine's axes among X, Y, Z, C (others are refused).
    letters: [Option<char>; 4],
    /// The last value printed per axis, in units of its last decimal.
    last: [Option<i64>; 4],
    mode: Option<FeedMode>,
    /// The last feed printed, in units of its last decimal.
    last_feed: Option<i64>,
    pub moves: usize,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum FeedMode {
    PerMinute,
    PerRevolution,
    InverseTime,
}

impl LinuxCncWriter {
    /// `modal` is the program's line of G words after the header; `axes`
    /// the machine's axis letters among "XYZC"; `path_tolerance` (mm), the
    /// most the controller may blend corners away from the programmed path
    /// (`G64 P`), is the strategy's own tolerance so the two never add up
    /// beyond it.
    pub fn new(
        header: &[String],
        modal: &str,
        axes: &str,
        resolution: f64,
        path_tolerance: f64,
    ) -> Self {
        let mut text = String::new();
        for line in header {
            write_comment(&mut text, line);
        }
        text.push_str(modal);
        text.push_str(" G64 P");
        let d = decimals_for(path_tolerance).max(decimals_for(resolution));
        if !push_fixed(&mut text, path_tolerance, d) {
            text.push('0');
        }
        text.push('\n');
        let has = |c: char| axes.contains(c).then_some(c);
        LinuxCncWriter {
            text,
            decimals: decimals_for(resolution),
            letters: [has('X'), has('Y'), has('Z'), has('C')],
            last: [None; 4],
            // The first feed states its mode, whatever the modal line says.
            mode: None,
            last_feed: None,
            moves: 0,
        }
    }

    /// Writes one move, straight into the text (no allocation per move:
    /// a move that changes no printed axis is written and then cut off).
    pub fn write(&mut self, m: &crate::moves::Move) -> Result<(), ProgramError> {
        use crate::moves::{Feed as F, Move as M};
        let (g, to, feed) = match *m {
            M::Rapid(to) => ("G0", to, None),
            M::Linear { to, feed } => ("G1", to, feed),
            M::SpindleOn(Some(w)) => {
                self.text.push('S');
                word(&mut self.text, 'S', w * 60.0 / (2.0 * PI), 3)?;
                self.text.push_str(" M3\n");
                return Ok(());
            }
            M::Arc { .. } => return Err(ProgramError::Unsupported("arcs".into())),
            M::SpindleOn(None) => {
                self.text.push_str("M3\n");
                return Ok(());
            }
            M::SpindleOff => {
                self.text.push_str("M5\n");
                return Ok(());
            }
        };
        let start = self.text.len();
        let mode = feed.map(|f| match f {
            F::PerTime(v) => (FeedMode::PerMinute, v * 60.0, 6),
            F::PerRevolution(v) => (FeedMode::PerRevolution, v * 2.0 * PI, 6),
            F::InverseTime(t) => (FeedMode::InverseTime, 60.0 / t, 3),
        });
        let mode_changes = mode.is_some_and(|(m, _, _)| self.mode != Some(m));
        if let Some((m, _, _)) = mode
            && mode_changes
        {
            self.text.push_str(match m {
                FeedMode::PerMinute => "G94 ",
                FeedMode::PerRevolution => "G95 ",
                FeedMode::InverseTime => "G93 ",
            });
        }
        self.text.push_str(g);
        let mut printed = self.last;
        let mut any = false;
        for (i, v) in to.axes().into_iter().enumerate() {
            if v.is_nan() {
                continue;
            }
            let letter = self.letters[i];
            let (value, d) = if letter == Some('C') {
                (v.to_degrees(), C_DECIMALS)
            } else {
                (v, self.decimals)
            };
            let (Some(letter), Some(n)) = (letter, fixed_units(value, d)) else {
                self.text.truncate(start);
                return Err(ProgramError::NotPrintable {
                    word: self.letters[i].unwrap_or("XYZC".as_bytes()[i] as char),
                    value: v,
                });
            };
            // Modal: a word whose printed value has not changed is left out.
            if printed[i] == Some(n) {
                continue;
            }
            self.text.push(' ');
            self.text.push(letter);
            push_units(&mut self.text, n, d);
            printed[i] = Some(n);
            any = true;
        }
        if !any {
            self.text.truncate(start);
            return Ok(());
        }
        if let Some((m, value, d)) = mode {
            let Some(n) = fixed_units(value, d) else {
                self.text.truncate(start);
                return Err(ProgramError::NotPrintable { word: 'F', value });
            };
            if mode_changes || m == FeedMode::InverseTime || self.last_feed != Some(n) {
                self.text.push_str(" F");
                push_units(&mut self.text, n, d);
            }
            self.last_feed = Some(n);
            self.mode = Some(m);
        }
        self.text.push('\n');
        self.last = printed;
        self.moves += 1;
        Ok(())
    }

    /// Writes every move of a stream.
    pub fn write_all<'a>(
        &mut self,
        moves: impl IntoIterator<Item = &'a crate::moves::Move>,
    ) -> Result<(), ProgramError> {
        moves.into_iter().try_for_each(|m| self.write(m))
    }

    /// The text written since the last call (for streaming to a file); the
    /// next chunk starts with room for as much again.
    pub fn take_text(&mut self) -> String {
        let room = self.text.len();
        std::mem::replace(&mut self.text, String::with_capacity(room))
    }

    /// Ends the program; the text not yet taken.
    pub fn finish(mut self) -> String {
        self.text.push_str("M2\n");
        self.text
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::moves::{Feed as F, Move as M, Position as P};

    fn written(axes: &str, stream: &[M]) -> Result<String, ProgramError> {
        let mut w = LinuxCncWriter::new(&["t".into()], "G17", axes, 1e-3, 1e-3);
        w.write_all(stream)?;
        Ok(w.finish())
    }

    #[test]
    fn unchanged_words_and_feeds_are_left_out() {
        let text = written(
            "XYZ",
            &[
                M::Rapid(P::xyz(1.0, 2.0, 5.0)),
                M::Linear {
                    to: P::xyz(1.0, 2.0, 0.5),
                    feed: Some(F::PerTime(1.0)),
                },
                M::Linear {
                    to: P::xyz(1.5, 2.0, 0.5),
                    feed: Some(F::PerTime(1.0)),
                },
                // Rounds to the same printed position: no line at all.
                M::Linear {
                    to: P::xyz(1.5001, 2.0, 0.5),
                    feed: None,
                },
                M::Linear {
                    to: P::xyz(1.5, 2.5, 0.5),
                    feed: Some(F::PerTime(2.0)),
                },
            ],
        )
        .expect("writes");
        assert_eq!(
            text,
            "(t)\nG17 G64 P0.001\nG0 X1. Y2. Z5.\nG94 G1 Z0.5 F60.\nG1 X1.5\nG1 Y2.5 F120.\nM2\n"
        );
    }

    #[test]
    fn inverse_time_writes_a_feed_on_every_move_and_c_in_degrees() {
        let text = written(
            "XZC",
            &[
                M::Linear {
                    to: P::xzc(1.0, 0.0, std::f64::consts::FRAC_PI_2),
                    feed: Some(F::InverseTime(0.5)),
                },
                M::Linear {
                    to: P::xzc(0.9, 0.0, std::f64::consts::PI),
                    feed: Some(F::InverseTime(0.5)),
                },
                M::Linear {
                    to: P::xz(0.8, 0.1),
                    feed: Some(F::PerRevolution(0.001)),
                },
            ],
        )
        .expect("writes");
        assert_eq!(
            text,
            "(t)\nG17 G64 P0.001\nG93 G1 X1. Z0. C90. F120.\nG1 X0.9 C180. F120.\nG95 G1 X0.8 Z0.1 F0.006283\nM2\n"
        );
    }

    #[test]
    fn axes_the_machine_lacks_and_values_that_cannot_print_are_refused() {
        assert!(matches!(
            written("XZ", &[M::Rapid(P::xyz(1.0, 2.0, 3.0))]),
            Err(ProgramError::NotPrintable { word: 'Y', .. })
        ));
        assert!(matches!(
            written("XZ", &[M::Rapid(P::xz(f64::INFINITY, 0.0))]),
            Err(ProgramError::NotPrintable { word: 'X', .. })
        ));
    }
}
