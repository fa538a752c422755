//! Post-processors: the dialect-independent move stream (`moves.rs`) to
//! program text, and each strategy's points to that stream. Every number
//! goes through the one formatter (`format.rs`: rounded to integer units,
//! printed from them); a program with a value that cannot be written is
//! refused whole.

use std::f64::consts::PI;
use std::fmt::Write as _;

use crate::format::{decimals_for, fixed_units, push_fixed, push_units_to};
use crate::job::Job;
use crate::machine::{CommentStyle, Dialect};
use crate::moves::{self, Plane, Position};
use crate::optimise::{self, optimise};
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

/// A program, the move stream it was written from, and what
/// optimisation did to that stream.
pub struct Emitted {
    pub text: String,
    pub stream: Vec<moves::Move>,
    pub optimised: optimise::Summary,
}

/// Writes a lathe program for a profile-turning path in the machine's
/// dialect, optimised (lines merged, arcs fitted) within the fitting share
/// of the strategy's tolerance.
pub fn emit(job: &Job, path: &Toolpath, prov: &Provenance) -> Result<Emitted, ProgramError> {
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
        format!(
            "units mm; X is {}, Z along the spindle axis, +Z out of the material",
            x_word(&job.machine.dialect)
        ),
        "coordinates are the centre of the tool nose; no cutter compensation".into(),
        format!("surface {}: {}", job.surface_name, job.surface.description),
        format!(
            "tool {}: round nose, nose radius {} mm{centre_height}",
            job.tool_name,
            num(job.tool.nose_radius)
        ),
        format!(
            "strategy {}: profile turning, {} points, {}{}{}",
            job.strategy_name,
            path.cut_points,
            tolerance_words(job.strategy.chord_tolerance),
            match job.strategy.surface_speed {
                Some(v) => format!(
                    ", constant surface speed {} m/min capped at {} rpm",
                    num(v * 0.06),
                    num((job.strategy.spindle_speed * 60.0 / (2.0 * PI)).floor())
                ),
                None => String::new(),
            },
            roughing_words(job, path)
        ),
        format!(
            "machine {}: {} lathe",
            job.machine_name, job.machine.dialect.name
        ),
        format!("estimated cutting time {}", duration(path.cutting_time())),
    ];
    let tolerance = job.strategy.chord_tolerance;
    let (stream, summary) = optimise(
        &turning_moves(job, path),
        tolerance * optimise::FIT_SHARE,
        &job.machine.dialect.arc_planes,
    );
    let mut header = header.to_vec();
    header.push(optimisation_words(&summary));
    let mut w = ProgramWriter::new(
        &job.machine.dialect,
        Setup::Lathe,
        &job.name,
        &header,
        "XZ",
        job.machine.resolution,
        tolerance * optimise::BLEND_SHARE,
    )?;
    w.write_all(&stream)?;
    Ok(Emitted {
        text: w.finish()?,
        stream,
        optimised: summary,
    })
}

/// How a path's tolerance T is stated in a header, with its shares.
pub fn tolerance_words(t: f64) -> String {
    format!(
        "path tolerance {} nm [chords {}, fitting {}, blending {} nm]",
        num(t * 1e6),
        num(t * optimise::CHORD_SHARE * 1e6),
        num(t * optimise::FIT_SHARE * 1e6),
        num(t * optimise::BLEND_SHARE * 1e6)
    )
}

/// What optimisation did, for a header.
pub fn optimisation_words(s: &optimise::Summary) -> String {
    format!(
        "optimised from {} to {} moves: {} arcs, {} merged lines, largest deviation {} nm",
        s.moves_before,
        s.moves_after,
        s.arcs,
        s.merged_lines,
        num((s.max_deviation * 1e9).round() / 1e3)
    )
}

/// What a lathe program's X word is in `dialect`, for its header.
pub fn x_word(dialect: &Dialect) -> &'static str {
    if dialect.lathe_x_diameter {
        "the diameter"
    } else {
        "the radius"
    }
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
    out.push(match job.strategy.surface_speed {
        Some(v) => moves::Move::SpindleSurfaceSpeed {
            surface_speed: v,
            cap: job.strategy.spindle_speed,
        },
        None => moves::Move::SpindleOn(Some(job.strategy.spindle_speed)),
    });
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
    writer: ProgramWriter,
    safe_w: f64,
    /// The last point written (None before the first).
    last: Option<crate::fts::SpiralPoint>,
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
    programmed: Option<crate::fts::SpiralPoint>,
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
            writer: ProgramWriter::new(
                dialect,
                Setup::Lathe,
                job,
                header,
                "XZC",
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
        last: Option<crate::fts::SpiralPoint>,
        safe_w: f64,
        points: &[crate::fts::SpiralPoint],
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

    /// Appends points in spiral order.
    pub fn extend(&mut self, points: &[crate::fts::SpiralPoint]) -> Result<(), ProgramError> {
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
    fn extend_table(&mut self, points: &[crate::fts::SpiralPoint]) -> Result<(), ProgramError> {
        let decimals = self.writer.decimals;
        let c_decimals = self.writer.dialect.c_decimals;
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
                    let [to_start, above, plunge] = approach(p, 0.0, self.safe_w);
                    self.writer.write_all(&[to_start, above])?;
                    for line in self.writer.dialect.fts_on.clone() {
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
            for line in self.writer.dialect.fts_off.clone() {
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

/// Rapids to a spiral's first point above the part, then a one-second
/// plunge of Z to `z`.
fn approach(p: &crate::fts::SpiralPoint, z: f64, safe_w: f64) -> [moves::Move; 3] {
    [
        moves::Move::Rapid(Position {
            x: p.x,
            c: p.c,
            ..Position::KEEP
        }),
        moves::Move::Rapid(Position {
            z: safe_w,
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
fn revolution(q: &crate::fts::SpiralPoint, p: &crate::fts::SpiralPoint) -> moves::Move {
    moves::Move::Linear {
        to: Position {
            x: p.x,
            c: p.c,
            ..Position::KEEP
        },
        feed: Some(moves::Feed::InverseTime(p.t - q.t)),
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

/// A program for a (optimised) move stream on a 3-axis mill, blending
/// held to the blending share of the path's tolerance `tolerance`.
pub fn emit_mill(
    dialect: &Dialect,
    job: &str,
    header: &[String],
    stream: &[moves::Move],
    resolution: f64,
    tolerance: f64,
) -> Result<String, ProgramError> {
    let mut w = ProgramWriter::new(
        dialect,
        Setup::Mill,
        job,
        header,
        "XYZ",
        resolution,
        tolerance * optimise::BLEND_SHARE,
    )?;
    w.write_all(stream)?;
    w.finish()
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

/// A program for a grinding pass: X and Z of the wheel centre.
pub fn emit_grinding(
    dialect: &Dialect,
    job: &str,
    header: &[String],
    path: &crate::grinding::GrindingPath,
    feed: f64,
    safe_z: f64,
    resolution: f64,
) -> Result<String, ProgramError> {
    // Wheel centres are exact at each interval: blending held to the
    // machine's resolution.
    let mut w = ProgramWriter::new(
        dialect,
        Setup::Lathe,
        job,
        header,
        "XZ",
        resolution,
        resolution,
    )?;
    w.write_all(&grinding_moves(path, feed, safe_z))?;
    w.finish()
}

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
    last: Option<crate::roller::RollerPoint>,
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
            writer: ProgramWriter::new(
                dialect,
                Setup::Lathe,
                job,
                header,
                "XZC",
                resolution,
                resolution,
            )?,
            safe_x,
            spindle_speed,
            c_base: 0.0,
            last: None,
            pass: usize::MAX,
        })
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

/// Which safe-start lines a program uses, and the arc plane they select.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Setup {
    /// `lathe_setup`, G18 (Z, X): X is the radius or the diameter.
    Lathe,
    /// `mill_setup`, G17 (X, Y).
    Mill,
}

/// The post-processor: a move stream to a program in a dialect given as
/// data. The start lines, header comments, setup and path-tolerance
/// lines, then the moves word by word: a word whose printed value has not
/// changed is left out (axes are modal); a feed is written when it or its
/// mode changes, and on every move in inverse time; a move that changes no
/// printed axis is left out whole. Every value goes through the one
/// fixed-point formatter (refused if not finite or too large) and the
/// dialect's digit limit, every block through its line-length limit;
/// numbers printed from integer units pass `check_numbers` by
/// construction (asserted in debug builds, held to it by the tests), and
/// every line taken from the dialect is checked with it as it is written.
pub struct ProgramWriter {
    /// Program text not yet taken (UTF-8: only `str`s and ASCII go in).
    text: Vec<u8>,
    dialect: Dialect,
    decimals: u32,
    /// Letters of the machine's axes among X, Y, Z, C (others are refused).
    letters: [Option<char>; 4],
    /// What goes before each axis's number: a space and its letter.
    axis_words: [Snippet; 4],
    /// Decimals of each axis: the resolution's, C's own for C.
    axis_decimals: [u32; 4],
    /// The motion words: rapid, linear, clockwise and counter-clockwise arc.
    motion_words: [Snippet; 4],
    /// The dialect's block end and the newline.
    line_end: Snippet,
    /// The dialect's digit limit (none: `usize::MAX`).
    max_digits: usize,
    /// The dialect's line-length limit (none: `usize::MAX`).
    max_line_length: usize,
    /// Factor from the move stream's X to the printed X (2 in diameter mode).
    x_scale: f64,
    /// The last value printed per axis, in units of its last decimal.
    last: [Option<i64>; 4],
    /// Where the axes are (mm, rad; the stream's values).
    at: [f64; 4],
    plane: Plane,
    mode: Option<FeedMode>,
    /// The last feed printed, in units of its last decimal.
    last_feed: Option<i64>,
    /// The next block number.
    block: u64,
    c_axis_on: bool,
    job: String,
    pub moves: usize,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum FeedMode {
    PerMinute,
    PerRevolution,
    InverseTime,
}

/// Decimals of feeds per minute and per revolution, and of inverse time.
const FEED_DECIMALS: u32 = 6;
const INVERSE_TIME_DECIMALS: u32 = 3;

impl ProgramWriter {
    /// Starts a program for job `job`: `axes` are the machine's axis
    /// letters among "XYZC"; `path_tolerance` (mm), the most the controller
    /// may blend corners away from the programmed path, is the strategy's
    /// own tolerance so the two never add up beyond it. Refused if the
    /// machine's resolution needs more decimals than the dialect writes.
    pub fn new(
        dialect: &Dialect,
        setup: Setup,
        job: &str,
        header: &[String],
        axes: &str,
        resolution: f64,
        path_tolerance: f64,
    ) -> Result<Self, ProgramError> {
        let decimals = decimals_for(resolution);
        if let Some(max) = dialect.max_decimals
            && decimals > max
        {
            return Err(ProgramError::Unsupported(format!(
                "the machine's resolution ({:.*} mm needs {decimals} decimals; {} writes at most {max})",
                decimals as usize, resolution, dialect.name
            )));
        }
        let setup_lines = match setup {
            Setup::Lathe => &dialect.lathe_setup,
            Setup::Mill => &dialect.mill_setup,
        };
        if setup_lines.is_empty() {
            return Err(ProgramError::Unsupported(format!(
                "{} programs ({} has no `{}_setup`)",
                match setup {
                    Setup::Lathe => "lathe",
                    Setup::Mill => "mill",
                },
                dialect.name,
                match setup {
                    Setup::Lathe => "lathe",
                    Setup::Mill => "mill",
                },
            )));
        }
        let has = |c: char| axes.contains(c).then_some(c);
        let letters = [
            has('X'),
            has('Y'),
            has('Z'),
            has('C').map(|_| dialect.c_letter),
        ];
        let mut w = ProgramWriter {
            text: Vec::new(),
            dialect: dialect.clone(),
            decimals,
            letters,
            axis_words: letters.map(|l| Snippet::new(&format!(" {}", l.unwrap_or(' ')))),
            axis_decimals: [decimals, decimals, decimals, dialect.c_decimals],
            motion_words: [
                &dialect.rapid,
                &dialect.linear,
                &dialect.arc_cw,
                &dialect.arc_ccw,
            ]
            .map(|w| Snippet::new(w)),
            line_end: Snippet::new(&format!("{}\n", dialect.block_end)),
            max_digits: dialect.max_digits.map_or(usize::MAX, |m| m as usize),
            max_line_length: dialect.max_line_length.unwrap_or(usize::MAX),
            x_scale: if setup == Setup::Lathe && dialect.lathe_x_diameter {
                2.0
            } else {
                1.0
            },
            last: [None; 4],
            at: [f64::NAN; 4],
            plane: match setup {
                Setup::Lathe => Plane::Zx,
                Setup::Mill => Plane::Xy,
            },
            // The first feed states its mode, whatever the setup says.
            mode: None,
            last_feed: None,
            block: dialect.line_numbers.unwrap_or(0),
            c_axis_on: false,
            job: job.to_string(),
            moves: 0,
        };
        // The dialect's own words, checked once: every number the writer
        // prints itself is well formed by construction (`number`), and
        // every line taken from the dialect is checked as it is written,
        // so no text leaves the writer unchecked.
        let words = [
            &dialect.rapid,
            &dialect.linear,
            &dialect.arc_cw,
            &dialect.arc_ccw,
            &dialect.spindle_on,
            &dialect.spindle_off,
            &dialect.block_end,
        ]
        .into_iter()
        .chain(dialect.per_minute.iter())
        .chain(dialect.per_revolution.iter())
        .chain(dialect.inverse_time.iter());
        for word in words {
            check_numbers(word, dialect.comment)?;
        }
        for line in &dialect.start {
            let l = w.fill(line, path_tolerance);
            check_numbers(&l, dialect.comment)?;
            w.text.extend_from_slice(l.as_bytes());
            w.text.push(b'\n');
        }
        for line in header {
            w.comment(line);
        }
        for line in setup_lines.iter().chain(&dialect.path_tolerance) {
            let l = w.fill(line, path_tolerance);
            w.block_line(&l)?;
        }
        Ok(w)
    }

    /// A line with its placeholders filled in.
    fn fill(&self, line: &str, tolerance: f64) -> String {
        // A tolerance is a bound: printed exactly if a few more decimals
        // do it (2.5 nm as 0.0000025), else rounded down, never up.
        let first = decimals_for(tolerance).max(self.decimals);
        let exact = (first..=9).find(|&d| {
            let scaled = tolerance * 10f64.powi(d as i32);
            (scaled - scaled.round()).abs() < 1e-6
        });
        let d = exact.unwrap_or(first);
        let shown = match exact {
            Some(_) => tolerance,
            None => (tolerance * 10f64.powi(d as i32)).floor() / 10f64.powi(d as i32),
        };
        let mut tol = String::new();
        if !push_fixed(&mut tol, shown, d) {
            tol.push('0');
        }
        line.replace("{job}", &self.job)
            .replace("{JOB}", &self.job.to_uppercase())
            .replace("{number}", &self.dialect.program_number.to_string())
            .replace("{tolerance}", &tol)
    }

    /// Starts a block: its number, if the dialect numbers blocks.
    #[inline]
    fn begin_block(&mut self) {
        if self.dialect.line_numbers.is_some() {
            self.text.push(b'N');
            self.text
                .extend_from_slice(itoa::Buffer::new().format(self.block).as_bytes());
            self.text.push(b' ');
        }
    }

    /// Ends the block begun at byte `start`: the dialect's block end, the
    /// line-length limit, the next block number.
    #[inline(always)]
    fn end_block(&mut self, start: usize) -> Result<(), ProgramError> {
        // The line's length is where the text ends now: nothing rescanned.
        if self.text.len() - start + self.dialect.block_end.len() > self.max_line_length {
            return Err(self.line_too_long(start));
        }
        self.line_end.push_to(&mut self.text);
        if let Some(step) = self.dialect.line_numbers {
            self.block += step;
            if self.dialect.max_line_number.is_some_and(|m| self.block > m) {
                self.block = step;
            }
        }
        Ok(())
    }

    /// Refuses the block begun at byte `start` for its length.
    #[cold]
    fn line_too_long(&mut self, start: usize) -> ProgramError {
        let mut line = String::from_utf8_lossy(&self.text[start..]).into_owned();
        line.push_str(&self.dialect.block_end);
        self.text.truncate(start);
        ProgramError::Unsupported(format!(
            "a line of {} characters ({} reads at most {}): {line}",
            line.len(),
            self.dialect.name,
            self.max_line_length
        ))
    }

    fn block_line(&mut self, words: &str) -> Result<(), ProgramError> {
        check_numbers(words, self.dialect.comment)?;
        let start = self.text.len();
        self.begin_block();
        self.text.extend_from_slice(words.as_bytes());
        self.end_block(start)
    }

    /// Writes `text` as comments in the dialect's syntax: no nested
    /// parentheses or control characters, long text folded at ", ".
    pub fn comment(&mut self, text: &str) {
        let mut lines = String::new();
        write_comment(&mut lines, text);
        for line in lines.lines() {
            let body = &line[1..line.len() - 1];
            let start = self.text.len();
            self.begin_block();
            match self.dialect.comment {
                CommentStyle::Parentheses => {
                    self.text.push(b'(');
                    self.text.extend_from_slice(body.as_bytes());
                    self.text.push(b')');
                }
                CommentStyle::Semicolon => {
                    self.text.extend_from_slice(b"; ");
                    self.text.extend_from_slice(body.as_bytes());
                }
            }
            // Comments are folded to 120 characters: within every limit.
            let _ = self.end_block(start);
        }
    }

    /// Appends a value's digits (`push_units_to`), refused if more than
    /// the dialect's limit (the caller cuts the block off). The digits
    /// come from an integer count of units, so they cannot spell an
    /// exponent, NaN or `-0`: `check_number` holds of them by construction
    /// (the format module's tests hold the printer to that), and is
    /// asserted again in debug builds.
    #[inline(always)]
    fn number(&mut self, letter: char, v: f64, n: i64, d: u32) -> Result<(), ProgramError> {
        let at = self.text.len();
        let digits = push_units_to(&mut self.text, n, d);
        debug_assert!(check_number(&self.text[at..]).is_ok());
        if digits > self.max_digits {
            return Err(self.too_many_digits(letter, v, digits));
        }
        Ok(())
    }

    #[cold]
    fn too_many_digits(&self, letter: char, v: f64, digits: usize) -> ProgramError {
        ProgramError::Unsupported(format!(
            "{letter}{v} in {digits} digits ({} takes at most {})",
            self.dialect.name, self.max_digits
        ))
    }

    /// Appends a value's digits, refusing more than the dialect's limit.
    fn value(&mut self, letter: char, v: f64, n: i64, d: u32) -> Result<(), ProgramError> {
        self.number(letter, v, n, d)
    }

    /// Writes one move, straight into the text (no allocation per move:
    /// a move that changes no printed axis is written and then cut off).
    pub fn write(&mut self, m: &crate::moves::Move) -> Result<(), ProgramError> {
        use crate::moves::Move as M;
        let (word, to, feed, arc) = match *m {
            M::Rapid(to) => (Word::Rapid, to, None, None),
            M::Linear { to, feed } => (Word::Linear, to, feed, None),
            M::Arc {
                to,
                centre,
                plane,
                ccw,
                feed,
            } => {
                let w = if ccw { Word::ArcCcw } else { Word::ArcCw };
                (w, to, feed, Some((plane, centre)))
            }
            _ => return self.write_spindle(m),
        };
        let start = self.text.len();
        let r = self.motion(word, to, feed, arc);
        if r.is_err() {
            self.text.truncate(start);
        }
        r
    }

    /// Writes a move that is not a motion: the spindle's.
    fn write_spindle(&mut self, m: &crate::moves::Move) -> Result<(), ProgramError> {
        use crate::moves::Move as M;
        let start = self.text.len();
        let r = match *m {
            M::Rapid(_) | M::Linear { .. } | M::Arc { .. } => self.write(m),
            M::SpindleOn(speed) => {
                self.begin_block();
                if let Some(w) = speed {
                    let rpm = w * 60.0 / (2.0 * PI);
                    self.text.push(b'S');
                    match fixed_units(rpm, 3) {
                        Some(n) => self.value('S', rpm, n, 3)?,
                        None => {
                            return Err(ProgramError::NotPrintable {
                                word: 'S',
                                value: rpm,
                            });
                        }
                    }
                    self.text.push(b' ');
                }
                let on = self.dialect.spindle_on.clone();
                self.text.extend_from_slice(on.as_bytes());
                self.end_block(start)
            }
            M::SpindleSurfaceSpeed { surface_speed, cap } => {
                let lines = self.dialect.surface_speed.clone();
                if lines.is_empty() {
                    return Err(ProgramError::Unsupported(format!(
                        "constant surface speed ({} has no `surface_speed` lines)",
                        self.dialect.name
                    )));
                }
                let mut speed = String::new();
                let mut rpm = String::new();
                let m_per_min = surface_speed * 60.0 / 1000.0;
                let cap_rpm = cap * 60.0 / (2.0 * PI);
                if !(push_fixed(&mut speed, m_per_min, 3)
                    && push_fixed(&mut rpm, cap_rpm.floor(), 0))
                {
                    return Err(ProgramError::NotPrintable {
                        word: 'S',
                        value: m_per_min,
                    });
                }
                for line in lines {
                    let l = line.replace("{speed}", &speed).replace("{cap}", &rpm);
                    self.block_line(&l)?;
                }
                let on = self.dialect.spindle_on.clone();
                self.block_line(&on)
            }
            M::SpindleOff => {
                let off = self.dialect.spindle_off.clone();
                self.block_line(&off)
            }
        };
        if r.is_err() {
            self.text.truncate(start);
        }
        r
    }

    /// A motion block.
    #[inline(always)]
    fn motion(
        &mut self,
        word: Word,
        to: Position,
        feed: Option<crate::moves::Feed>,
        arc: Option<(Plane, Position)>,
    ) -> Result<(), ProgramError> {
        self.motion_words_into_text(word, to, feed, arc)
    }

    /// A motion block: its words straight into the text, each a copy of
    /// fixed size (a snippet's room, a number's room) cut back to length.
    /// The values printed are kept word by word and become the last
    /// printed values only when the block is written (a block refused
    /// leaves them as they were).
    #[inline(always)]
    fn motion_words_into_text(
        &mut self,
        word: Word,
        to: Position,
        feed: Option<crate::moves::Feed>,
        arc: Option<(Plane, Position)>,
    ) -> Result<(), ProgramError> {
        use crate::moves::Feed as F;
        if !to.c.is_nan() && !self.c_axis_on && self.letters[3].is_some() {
            self.c_axis_on_lines()?;
        }
        let start = self.text.len();
        self.begin_block();
        let mode = feed.map(|f| match f {
            F::PerTime(v) => (FeedMode::PerMinute, v * 60.0, FEED_DECIMALS),
            F::PerRevolution(v) => (FeedMode::PerRevolution, v * 2.0 * PI, FEED_DECIMALS),
            F::InverseTime(t) => (FeedMode::InverseTime, 60.0 / t, INVERSE_TIME_DECIMALS),
        });
        let mode_changes = mode.is_some_and(|(m, _, _)| self.mode != Some(m));
        if let Some((m, _, _)) = mode
            && mode_changes
        {
            let w = self.feed_mode_word(m)?.to_string();
            self.text.extend_from_slice(w.as_bytes());
            self.text.push(b' ');
        }
        if let Some((plane, _)) = arc {
            if !self.dialect.arc_planes.contains(&plane) {
                return Err(ProgramError::Unsupported(format!(
                    "arcs in the {} plane",
                    plane.name()
                )));
            }
            if plane != self.plane {
                self.text.extend_from_slice(match plane {
                    Plane::Xy => b"G17 ",
                    Plane::Zx => b"G18 ",
                    Plane::Yz => b"G19 ",
                });
                self.plane = plane;
            }
        }
        self.motion_words[word as usize].push_to(&mut self.text);
        let mut printed = [0i64; 4];
        let mut changed = 0u8;
        let axes = to.axes();
        for i in 0..4 {
            let v = axes[i];
            if v.is_nan() {
                continue;
            }
            let value = match i {
                0 => v * self.x_scale,
                3 => v.to_degrees(),
                _ => v,
            };
            let d = self.axis_decimals[i];
            let (Some(letter), Some(n)) = (self.letters[i], fixed_units(value, d)) else {
                return Err(self.not_printable(i, v));
            };
            // Modal: a word whose printed value has not changed is left out.
            if self.last[i] == Some(n) {
                continue;
            }
            self.axis_words[i].push_to(&mut self.text);
            self.number(letter, value, n, d)?;
            printed[i] = n;
            changed |= 1 << i;
        }
        if changed == 0 {
            self.text.truncate(start);
            return Ok(());
        }
        if let Some((plane, centre)) = arc {
            self.arc_centre(plane, to, centre)?;
        }
        if let Some((m, value, d)) = mode {
            let Some(n) = fixed_units(value, d) else {
                return Err(ProgramError::NotPrintable { word: 'F', value });
            };
            if mode_changes || m == FeedMode::InverseTime || self.last_feed != Some(n) {
                self.text.extend_from_slice(b" F");
                self.number('F', value, n, d)?;
            }
            self.last_feed = Some(n);
            self.mode = Some(m);
        }
        self.end_block(start)?;
        for (i, n) in printed.into_iter().enumerate() {
            if changed & 1 << i != 0 {
                self.last[i] = Some(n);
            }
        }
        for (at, v) in self.at.iter_mut().zip(axes) {
            if !v.is_nan() {
                *at = v;
            }
        }
        self.moves += 1;
        Ok(())
    }

    /// The dialect's lines that switch the C axis on, before its first move.
    #[cold]
    fn c_axis_on_lines(&mut self) -> Result<(), ProgramError> {
        self.c_axis_on = true;
        for line in self.dialect.c_axis_on.clone() {
            self.block_line(&line)?;
        }
        Ok(())
    }

    /// The word that switches the controller to feed mode `m`.
    #[cold]
    fn feed_mode_word(&self, m: FeedMode) -> Result<&str, ProgramError> {
        let w = match m {
            FeedMode::PerMinute => &self.dialect.per_minute,
            FeedMode::PerRevolution => &self.dialect.per_revolution,
            FeedMode::InverseTime => &self.dialect.inverse_time,
        };
        w.as_deref().ok_or_else(|| {
            ProgramError::Unsupported(format!(
                "feeds {} ({} has no word for them)",
                match m {
                    FeedMode::PerMinute => "per minute",
                    FeedMode::PerRevolution => "per revolution",
                    FeedMode::InverseTime => "in inverse time",
                },
                self.dialect.name
            ))
        })
    }

    /// Axis `i` has no letter on this machine, or `v` cannot be printed.
    #[cold]
    fn not_printable(&self, i: usize, v: f64) -> ProgramError {
        ProgramError::NotPrintable {
            word: self.letters[i].unwrap_or("XYZC".as_bytes()[i] as char),
            value: v,
        }
    }

    /// An arc's centre words, once its radii are checked as the
    /// controller checks them.
    #[inline(never)]
    fn arc_centre(
        &mut self,
        plane: Plane,
        to: Position,
        centre: Position,
    ) -> Result<(), ProgramError> {
        // The controller measures the radius from the rounded centre
        // to the rounded start and end, and refuses a mismatch.
        let (a, b) = plane.axes();
        let scale = 10f64.powi(self.decimals as i32);
        let round = |v: f64| (v * scale).round() / scale;
        let end = to.axes();
        let radius = |p: [f64; 4]| {
            (round(p[a]) - round(centre.axes()[a])).hypot(round(p[b]) - round(centre.axes()[b]))
        };
        let mut end_at = self.at;
        for (e, v) in end_at.iter_mut().zip(end) {
            if !v.is_nan() {
                *e = v;
            }
        }
        let mismatch = (radius(self.at) - radius(end_at)).abs();
        if mismatch.is_nan() || mismatch > self.dialect.arc_radius_tolerance {
            return Err(ProgramError::Unsupported(format!(
                "an arc whose end radius differs from its start radius by {} mm (it allows {} mm)",
                num(mismatch),
                num(self.dialect.arc_radius_tolerance)
            )));
        }
        // I J K in that order, whatever the plane's orientation.
        for i in [a.min(b), a.max(b)] {
            let c = centre.axes()[i];
            let from = if self.dialect.arc_centre_absolute {
                0.0
            } else {
                self.at[i]
            };
            let (Some(cu), Some(fu)) = (
                fixed_units(c, self.decimals),
                fixed_units(from, self.decimals),
            ) else {
                return Err(ProgramError::NotPrintable {
                    word: ['I', 'J', 'K'][i],
                    value: c,
                });
            };
            let letter = ['I', 'J', 'K'][i];
            self.text.extend_from_slice(&[b' ', letter as u8]);
            self.number(letter, c - from, cu - fu, self.decimals)?;
        }
        Ok(())
    }

    /// Writes every move of a stream.
    pub fn write_all<'a>(
        &mut self,
        moves: impl IntoIterator<Item = &'a crate::moves::Move>,
    ) -> Result<(), ProgramError> {
        moves.into_iter().try_for_each(|m| self.write(m))
    }

    /// The text written since the last call (for streaming to a file),
    /// every number and dialect line in it checked as it was written (see
    /// `ProgramWriter`); the
    /// next chunk starts with room for as much again.
    pub fn take_text(&mut self) -> Result<String, ProgramError> {
        let room = self.text.len();
        utf8(std::mem::replace(&mut self.text, Vec::with_capacity(room)))
    }

    /// Ends the program; the text not yet taken, checked.
    pub fn finish(mut self) -> Result<String, ProgramError> {
        if self.c_axis_on {
            for line in self.dialect.c_axis_off.clone() {
                self.block_line(&line)?;
            }
        }
        for line in self.dialect.end.clone() {
            let l = self.fill(&line, 0.0);
            self.block_line(&l)?;
        }
        for line in self.dialect.trailer.clone() {
            let l = self.fill(&line, 0.0);
            check_numbers(&l, self.dialect.comment)?;
            self.text.extend_from_slice(l.as_bytes());
            self.text.push(b'\n');
        }
        utf8(self.text)
    }
}

/// The writer's text as a `String`: it only ever appends `str`s and
/// ASCII, so this holds; were it ever not so, the text is refused, not
/// handed out.
fn utf8(text: Vec<u8>) -> Result<String, ProgramError> {
    String::from_utf8(text)
        .map_err(|_| ProgramError::Unsupported("program text that is not UTF-8".into()))
}

/// A short piece of program text (a word's letter, a motion word, a
/// block end), kept in a fixed array so appending it is a copy of fixed
/// size and a cut back (no call to `memcpy`); longer pieces as they are.
struct Snippet {
    room: [u8; SNIPPET_ROOM],
    len: usize,
    long: Box<[u8]>,
}

const SNIPPET_ROOM: usize = 16;

impl Snippet {
    fn new(text: &str) -> Snippet {
        let b = text.as_bytes();
        let mut room = [0; SNIPPET_ROOM];
        if b.len() <= SNIPPET_ROOM {
            room[..b.len()].copy_from_slice(b);
        }
        Snippet {
            room,
            len: b.len(),
            long: if b.len() > SNIPPET_ROOM {
                b.into()
            } else {
                Box::default()
            },
        }
    }

    #[inline]
    fn push_to(&self, text: &mut Vec<u8>) {
        if self.len <= SNIPPET_ROOM {
            let at = text.len();
            text.extend_from_slice(&self.room);
            text.truncate(at + self.len);
        } else {
            text.extend_from_slice(&self.long);
        }
    }
}

#[derive(Clone, Copy)]
enum Word {
    Rapid,
    Linear,
    ArcCw,
    ArcCcw,
}

/// The final check on program text: outside comments, no word's number
/// is `-0`, has an exponent, or is not finite (`NaN`, `inf`), and no
/// digit runs straight into a letter. The writer cannot produce these; this
/// check makes sure no path around it does.
pub fn check_numbers(text: &str, comments: CommentStyle) -> Result<(), ProgramError> {
    let opens = match comments {
        CommentStyle::Parentheses => b'(',
        CommentStyle::Semicolon => b';',
    };
    for line in text.split('\n') {
        let b = line.as_bytes();
        let code = &b[..b.iter().position(|&c| c == opens).unwrap_or(b.len())];
        let mut j = 0;
        while j < code.len() {
            if code[j].is_ascii_whitespace() {
                j += 1;
                continue;
            }
            let start = j;
            while j < code.len() && !code[j].is_ascii_whitespace() {
                j += 1;
            }
            if let Err(why) = check_word(&code[start..j]) {
                return Err(ProgramError::Unsupported(format!(
                    "the word `{}` ({why}) in the line `{line}`",
                    &line[start..j]
                )));
            }
        }
    }
    Ok(())
}

/// One word of code: a letter and a number (digits and points, perhaps a
/// leading minus that is not on a zero) or a word that spells no
/// non-finite number.
fn check_word(w: &[u8]) -> Result<(), &'static str> {
    let numeric =
        w.len() >= 2 && w[0].is_ascii_alphabetic() && matches!(w[1], b'0'..=b'9' | b'-' | b'.');
    if !numeric {
        let spells = |s: &[u8]| w.windows(3).any(|x| x.eq_ignore_ascii_case(s));
        return if spells(b"nan") || spells(b"inf") {
            Err("not a finite number")
        } else {
            Ok(())
        };
    }
    check_number(&w[1..])
}

/// A printed number: digits and points after an optional minus, and not
/// a minus zero.
pub(crate) fn check_number(num: &[u8]) -> Result<(), &'static str> {
    let digits = num.strip_prefix(b"-").unwrap_or(num);
    if !digits.iter().all(|&c| c.is_ascii_digit() || c == b'.') {
        // `G05.1`-style words are digits and points only; anything else
        // after a number is an exponent or a run-on word.
        return Err("a number with letters in it");
    }
    if digits.len() < num.len() && digits.iter().all(|&c| c == b'0' || c == b'.') {
        return Err("minus zero");
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::moves::{Feed as F, Move as M, Position as P};

    fn written(axes: &str, stream: &[M]) -> Result<String, ProgramError> {
        written_in(&Dialect::linuxcnc(), Setup::Mill, axes, stream)
    }

    fn written_in(
        d: &Dialect,
        setup: Setup,
        axes: &str,
        stream: &[M],
    ) -> Result<String, ProgramError> {
        let mut w = ProgramWriter::new(d, setup, "t1", &["t".into()], axes, 1e-3, 1e-3)?;
        w.write_all(stream)?;
        w.finish()
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
            "(t)\nG17 G21 G90 G40 G49 G80\nG64 P0.001\nG0 X1. Y2. Z5.\nG94 G1 Z0.5 F60.\nG1 X1.5\nG1 Y2.5 F120.\nM2\n"
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
            "(t)\nG17 G21 G90 G40 G49 G80\nG64 P0.001\nG93 G1 X1. Z0. C90. F120.\nG1 X0.9 C180. F120.\nG95 G1 X0.8 Z0.1 F0.006283\nM2\n"
        );
    }

    #[test]
    fn a_dialect_given_as_data_shapes_every_line() {
        let mut d = Dialect::linuxcnc();
        d.name = "heidenhain_like".into();
        d.comment = CommentStyle::Semicolon;
        d.start = vec!["%{JOB} G71 *".into()];
        d.mill_setup = vec!["G17 G90".into()];
        d.path_tolerance = Vec::new();
        d.end = vec!["M30".into()];
        d.trailer = vec!["N99999999 %{JOB} G71 *".into()];
        d.line_numbers = Some(1);
        d.block_end = " *".into();
        d.arc_centre_absolute = true;
        let text = written_in(
            &d,
            Setup::Mill,
            "XYZ",
            &[
                M::Rapid(P::xyz(1.0, 0.0, 0.0)),
                M::Arc {
                    to: P::xyz(0.0, 1.0, 0.0),
                    centre: P::xyz(0.0, 0.0, f64::NAN),
                    plane: Plane::Xy,
                    ccw: true,
                    feed: Some(F::PerTime(1.0)),
                },
            ],
        )
        .expect("writes");
        assert_eq!(
            text,
            "%T1 G71 *\nN1 ; t *\nN2 G17 G90 *\nN3 G0 X1. Y0. Z0. *\nN4 G94 G3 X0. Y1. I0. J0. F60. *\nN5 M30 *\nN99999999 %T1 G71 *\n"
        );
    }

    #[test]
    fn long_words_and_letters_beyond_ascii_are_written_whole() {
        // Words longer than a snippet's fixed room, and a C letter of two
        // bytes, take the writer's other paths.
        let mut d = Dialect::linuxcnc();
        d.linear = "G1 G90 G94 G17 G21 G40".into();
        d.block_end = " ; the end of a long block".into();
        d.c_letter = 'Ç';
        // The longest line is 77 bytes (the limit counts bytes, as before).
        d.max_line_length = Some(77);
        let text = written_in(
            &d,
            Setup::Lathe,
            "XZC",
            &[
                M::Linear {
                    to: P::xzc(1.5, -0.25, std::f64::consts::PI),
                    feed: Some(F::InverseTime(0.5)),
                },
                M::Linear {
                    to: P::xzc(1.5, -0.25, std::f64::consts::FRAC_PI_2),
                    feed: Some(F::InverseTime(0.25)),
                },
            ],
        )
        .expect("writes");
        assert!(
            text.contains(
                "G93 G1 G90 G94 G17 G21 G40 X1.5 Z-0.25 Ç180. F120. ; the end of a long block\n\
                 G1 G90 G94 G17 G21 G40 Ç90. F240. ; the end of a long block\n"
            ),
            "{text}"
        );
        // One byte over the limit, the block end counted.
        d.max_line_length = Some(76);
        let Err(ProgramError::Unsupported(why)) = written_in(
            &d,
            Setup::Lathe,
            "XZC",
            &[M::Linear {
                to: P::xzc(1.5, -0.25, std::f64::consts::PI),
                feed: Some(F::InverseTime(0.5)),
            }],
        ) else {
            panic!("a line over the limit written")
        };
        assert!(why.contains("a line of 77 characters"), "{why}");
    }

    #[test]
    fn arcs_have_incremental_centres_and_select_their_plane() {
        let text = written(
            "XYZ",
            &[
                M::Rapid(P::xyz(1.0, 0.0, 2.0)),
                M::Arc {
                    to: P::xyz(3.0, 0.0, 2.0),
                    centre: P::xyz(2.0, f64::NAN, 2.0),
                    plane: Plane::Zx,
                    ccw: false,
                    feed: Some(F::PerTime(1.0)),
                },
            ],
        )
        .expect("writes");
        assert!(text.contains("G94 G18 G2 X3. I1. K0. F60.\n"), "{text}");
    }

    #[test]
    fn an_arc_whose_radii_disagree_after_rounding_is_refused() {
        let arc = |end_x: f64| {
            written(
                "XZ",
                &[
                    M::Rapid(P::xz(1.0, 0.0)),
                    M::Arc {
                        to: P::xz(end_x, 0.0),
                        centre: P::xz(0.0, 0.0),
                        plane: Plane::Zx,
                        ccw: true,
                        feed: Some(F::PerTime(1.0)),
                    },
                ],
            )
        };
        assert!(arc(-1.0005).is_ok());
        let Err(ProgramError::Unsupported(why)) = arc(-1.002) else {
            panic!("a 2 um mismatch written")
        };
        assert!(why.contains("0.002 mm"), "{why}");
    }

    #[test]
    fn diameter_mode_doubles_x_and_limits_are_enforced() {
        let mut d = Dialect::linuxcnc();
        d.lathe_x_diameter = true;
        d.max_digits = Some(4);
        let text =
            written_in(&d, Setup::Lathe, "XZ", &[M::Rapid(P::xz(1.25, 0.0))]).expect("writes");
        assert!(text.contains("G0 X2.5 Z0.\n"), "{text}");
        assert!(matches!(
            written_in(&d, Setup::Lathe, "XZ", &[M::Rapid(P::xz(12.3455, 0.0))]),
            Err(ProgramError::Unsupported(_))
        ));
        d.per_revolution = None;
        assert!(matches!(
            written_in(
                &d,
                Setup::Lathe,
                "XZ",
                &[M::Linear {
                    to: P::xz(1.0, 0.0),
                    feed: Some(F::PerRevolution(0.001))
                }]
            ),
            Err(ProgramError::Unsupported(_))
        ));
        d.max_decimals = Some(2);
        assert!(written_in(&d, Setup::Lathe, "XZ", &[]).is_err());
        assert!(written_in(&Dialect::linuxcnc(), Setup::Lathe, "XZ", &[]).is_ok());
    }

    #[test]
    fn the_final_check_refuses_bad_numbers_outside_comments() {
        let ok = "(X-0. in a comment, 1e5 too)\nG1 X-0.5 Z0. F60.\nG05.1 Q1\n";
        assert!(check_numbers(ok, CommentStyle::Parentheses).is_ok());
        for bad in [
            "G1 X-0.",
            "G1 X-0.000",
            "G1 X1.5e-3",
            "G1 XNaN",
            "G1 Z-inf",
            "G1 X1.0Y2.",
        ] {
            assert!(
                check_numbers(bad, CommentStyle::Parentheses).is_err(),
                "{bad} passed"
            );
        }
        assert!(check_numbers("; X-0. here", CommentStyle::Semicolon).is_ok());
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

    /// `{:.N}` of `n` units of 10^−N, trailing zeros trimmed, the point
    /// kept: the reference every printed word is held to.
    fn std_word(n: i64, d: u32) -> String {
        let s = format!("{:.*}", d as usize, n as f64 / 10f64.powi(d as i32));
        if d == 0 {
            s + "."
        } else {
            s.trim_end_matches('0').to_string()
        }
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(300))]

        /// A spiral-like stream through the writer against a model of it
        /// built from `f64::round` and `{:.N}`: the same lines, word for
        /// word, unchanged words left out, a feed on every block, no block
        /// for a move that changes no printed axis.
        #[test]
        fn the_writer_prints_what_a_plain_model_of_it_prints(
            resolution in proptest::sample::select(vec![1e-3, 1e-4, 1e-6]),
            moves in proptest::collection::vec(
                (-100.0f64..100.0, -50.0f64..50.0, -1000.0f64..1000.0, 1e-5f64..1.0, 0u8..4),
                1..200,
            ),
        ) {
            let d = decimals_for(resolution);
            let mut stream = Vec::new();
            let mut at = (0.0, 0.0, 0.0);
            for &(x, z, c, t, keep) in &moves {
                // Some moves repeat a coordinate, or come within a unit of it.
                let x = if keep & 1 == 1 { at.0 + resolution * 0.3 } else { x };
                let z = if keep & 2 == 2 { at.1 } else { z };
                at = (x, z, c);
                stream.push(M::Linear { to: P::xzc(x, z, c), feed: Some(F::InverseTime(t)) });
            }
            let dialect = Dialect::linuxcnc();
            let mut w = ProgramWriter::new(&dialect, Setup::Lathe, "t", &[], "XZC", resolution, 1e-5)
                .expect("a lathe program");
            w.write_all(&stream).expect("printable");
            let text = w.finish().expect("checked");
            proptest::prop_assert!(check_numbers(&text, CommentStyle::Parentheses).is_ok());
            let units = |v: f64, d: u32| (v * 10f64.powi(d as i32)).round() as i64;
            let mut last: [Option<i64>; 3] = [None; 3];
            let mut expected = Vec::new();
            for m in &stream {
                let M::Linear { to, feed: Some(F::InverseTime(t)) } = m else { unreachable!() };
                let mut line = String::from(if expected.is_empty() { "G93 G1" } else { "G1" });
                let mut any = false;
                for (k, (letter, v, dk)) in
                    [('X', to.x, d), ('Z', to.z, d), ('C', to.c.to_degrees(), 5)].into_iter().enumerate()
                {
                    let n = units(v, dk);
                    if last[k] != Some(n) {
                        line += &format!(" {letter}{}", std_word(n, dk));
                        last[k] = Some(n);
                        any = true;
                    }
                }
                if any {
                    line += &format!(" F{}", std_word(units(60.0 / t, 3), 3));
                    expected.push(line);
                }
            }
            let written: Vec<&str> = text
                .lines()
                .skip_while(|l| !l.starts_with("G93"))
                .take_while(|l| *l != "M2")
                .collect();
            proptest::prop_assert_eq!(written, expected);
            proptest::prop_assert!(text.lines().all(|l| l.len() <= 255));
        }
    }
}
