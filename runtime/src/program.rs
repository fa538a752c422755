//! Dialect emitters: the dialect-independent move stream to program text.
//! Every number goes through `format::push_fixed`; a program with a value
//! that cannot be written is refused whole.

use std::f64::consts::PI;
use std::fmt::Write as _;

use crate::format::{decimals_for, push_fixed};
use crate::job::Job;
use crate::machine::Dialect;
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
    let d = decimals_for(job.machine.resolution);
    let mut out = String::with_capacity(64 * path.moves.len() + 1024);
    let comment = write_comment;
    comment(
        &mut out,
        &format!("lensc {}: job {}", prov.lensc_version, job.name),
    );
    comment(
        &mut out,
        &format!("source {} fnv1a64 {:016x}", prov.source, prov.source_hash),
    );
    comment(
        &mut out,
        "units mm; X is the radius [G8], Z along the spindle axis, +Z out of the material",
    );
    comment(
        &mut out,
        "coordinates are the centre of the tool nose; no cutter compensation",
    );
    let surf = format!("surface {}: {}", job.surface_name, job.surface.description);
    comment(&mut out, &surf);
    comment(
        &mut out,
        &format!(
            "tool {}: round nose, nose radius {} mm{}",
            job.tool_name,
            num(job.tool.nose_radius),
            if job.tool.centre_height == 0.0 {
                String::new()
            } else {
                format!(
                    ", edge {} mm off the spindle axis: X = sqrt[r² − h²] of the nose-centre radius r",
                    num(job.tool.centre_height)
                )
            }
        ),
    );
    comment(
        &mut out,
        &format!(
            "strategy {}: profile turning, {} points, chord tolerance {} nm{}",
            job.strategy_name,
            path.cut_points,
            num(job.strategy.chord_tolerance * 1e6),
            roughing_words(job, path)
        ),
    );
    comment(
        &mut out,
        &format!(
            "machine {}: {} lathe",
            job.machine_name,
            job.machine.dialect.name()
        ),
    );
    comment(
        &mut out,
        &format!("estimated cutting time {}", duration(path.cutting_time())),
    );
    out.push_str("G18 G21 G90 G8 G40 G49 G80 G94\n");

    let rpm = job.strategy.spindle_speed * 60.0 / (2.0 * PI);
    out.push('S');
    word(&mut out, 'S', rpm, 3)?;
    out.push_str(" M3\n");

    let (feed_mode, feed_value) = match job.strategy.feed {
        Feed::PerRevolution(f) => ("G95", f * 2.0 * PI),
        Feed::PerTime(v) => ("G94", v * 60.0),
    };
    let (mut cx, mut cz) = (f64::NAN, f64::NAN);
    let mut feed_set = false;
    for m in &path.moves {
        let (g, x, z) = match *m {
            Move::Rapid { x, z } => ("G0", x, z),
            Move::Feed { x, z } => ("G1", x, z),
        };
        // An edge set h off the axis cuts radius sqrt(X² + h²).
        let h = job.tool.centre_height;
        let x = if h == 0.0 {
            x
        } else {
            x.signum() * (x * x - h * h).max(0.0).sqrt()
        };
        let mut line = String::with_capacity(40);
        if g == "G1" && !feed_set {
            line.push_str(feed_mode);
            line.push(' ');
        }
        line.push_str(g);
        let before = line.len();
        let mut xs = String::new();
        word(&mut xs, 'X', x, d)?;
        let mut zs = String::new();
        word(&mut zs, 'Z', z, d)?;
        // Words whose printed value has not changed are left out.
        if !rounded_eq(cx, x, d) {
            line.push_str(" X");
            line.push_str(&xs);
        }
        if !rounded_eq(cz, z, d) {
            line.push_str(" Z");
            line.push_str(&zs);
        }
        if line.len() == before {
            continue;
        }
        if g == "G1" && !feed_set {
            line.push_str(" F");
            word(&mut line, 'F', feed_value, 6)?;
            feed_set = true;
        }
        cx = x;
        cz = z;
        out.push_str(&line);
        out.push('\n');
    }
    out.push_str("M5\nM2\n");
    Ok(out)
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

fn rounded_eq(a: f64, b: f64, d: u32) -> bool {
    let s = 10f64.powi(d as i32);
    a.is_finite() && (a * s).round() == (b * s).round()
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

/// A LinuxCNC program for a fast-tool-servo spiral, written as the planner
/// hands over its points: X (radius, G8) and C (degrees, counted on from
/// the start) on the spiral, the nose-centre height on Z, each move timed
/// by inverse-time feed (G93: F = 1/minutes). LinuxCNC has no fast-axis
/// word its interpreter accepts, so the fast tool servo's motion is
/// programmed on Z (the form of a slow-tool-servo program); controllers
/// with a W axis get their own dialect.
pub struct FtsProgram {
    text: String,
    decimals: u32,
    safe_w: f64,
    /// The last point written (NaN before the first).
    last: crate::fts::SpiralPoint,
    pub moves: usize,
}

/// Decimals of C in degrees: 1e-5° is 4 nm of arc at 25 mm.
const C_DECIMALS: u32 = 5;

impl FtsProgram {
    /// Starts a program: the header comments and the modal line.
    pub fn new(header: &[String], resolution: f64, safe_w: f64) -> FtsProgram {
        let mut text = String::new();
        for line in header {
            write_comment(&mut text, line);
        }
        text.push_str("G18 G21 G90 G8 G40 G49 G80 G93\n");
        FtsProgram {
            text,
            decimals: decimals_for(resolution),
            safe_w,
            last: crate::fts::SpiralPoint {
                x: f64::NAN,
                c: f64::NAN,
                w: f64::NAN,
                t: f64::NAN,
            },
            moves: 0,
        }
    }

    /// Appends points in spiral order; the first is reached by rapids
    /// above the part and a plunge.
    pub fn extend(&mut self, points: &[crate::fts::SpiralPoint]) -> Result<(), ProgramError> {
        let d = self.decimals;
        for p in points {
            let line = &mut self.text;
            if self.last.x.is_nan() {
                line.push_str("G0 X");
                word(line, 'X', p.x, d)?;
                line.push_str(" C");
                word(line, 'C', p.c.to_degrees(), C_DECIMALS)?;
                line.push_str("\nG0 Z");
                word(line, 'Z', self.safe_w, d)?;
                // The plunge: one second at inverse-time F60.
                line.push_str("\nG1 Z");
                word(line, 'Z', p.w, d)?;
                line.push_str(" F60.\n");
                self.moves += 3;
                self.last = *p;
                continue;
            }
            let dt = p.t - self.last.t;
            line.push_str("G1 X");
            word(line, 'X', p.x, d)?;
            line.push_str(" C");
            word(line, 'C', p.c.to_degrees(), C_DECIMALS)?;
            line.push_str(" Z");
            word(line, 'Z', p.w, d)?;
            line.push_str(" F");
            word(line, 'F', 60.0 / dt, 3)?;
            line.push('\n');
            self.moves += 1;
            self.last = *p;
        }
        Ok(())
    }

    /// The text written since the last call, for the caller to pass on
    /// (a program of millions of moves need not be held whole).
    pub fn take_text(&mut self) -> String {
        std::mem::take(&mut self.text)
    }

    /// Retracts and ends the program; the text not yet taken.
    pub fn finish(mut self) -> Result<String, ProgramError> {
        self.text.push_str("G0 Z");
        word(&mut self.text, 'Z', self.safe_w, self.decimals)?;
        self.text.push_str("\nM2\n");
        Ok(self.text)
    }
}

/// Writes moves word by word, leaving out words whose printed value has
/// not changed (modal axes), refusing any value that cannot be printed.
pub struct MoveWriter {
    pub text: String,
    decimals: u32,
    /// The last value printed per axis letter, by index in `axes`.
    last: Vec<f64>,
    axes: &'static [char],
    pub moves: usize,
}

impl MoveWriter {
    /// A writer for `axes` (e.g. `['X', 'Y', 'Z']`) at the machine's
    /// resolution, after the header comments and the modal line.
    pub fn new(header: &[String], modal: &str, axes: &'static [char], resolution: f64) -> Self {
        let mut text = String::new();
        for line in header {
            write_comment(&mut text, line);
        }
        text.push_str(modal);
        text.push('\n');
        MoveWriter {
            text,
            decimals: decimals_for(resolution),
            last: vec![f64::NAN; axes.len()],
            axes,
            moves: 0,
        }
    }

    /// One move: `G0` or `G1`, a value per axis (NaN: leave the axis
    /// where it is), and a feed word if given.
    pub fn motion(
        &mut self,
        g: &str,
        at: &[f64],
        feed: Option<(f64, u32)>,
    ) -> Result<(), ProgramError> {
        let d = self.decimals;
        let mut line = String::from(g);
        let before = line.len();
        for (i, (&v, &letter)) in at.iter().zip(self.axes).enumerate() {
            if v.is_nan() || rounded_eq(self.last[i], v, d) {
                continue;
            }
            line.push(' ');
            line.push(letter);
            word(&mut line, letter, v, d)?;
            self.last[i] = v;
        }
        if line.len() == before {
            return Ok(());
        }
        if let Some((f, decimals)) = feed {
            line.push_str(" F");
            word(&mut line, 'F', f, decimals)?;
        }
        line.push('\n');
        self.text.push_str(&line);
        self.moves += 1;
        Ok(())
    }

    /// A line as it is (spindle, modal changes).
    pub fn raw(&mut self, line: &str) {
        self.text.push_str(line);
        self.text.push('\n');
    }

    pub fn finish(mut self) -> String {
        self.text.push_str("M2\n");
        self.text
    }
}

/// A LinuxCNC program for a raster on a 3-axis mill: each pass reached by
/// rapids at the safe height, a plunge, the cut, a retract.
pub fn emit_mill_raster(
    header: &[String],
    path: &crate::raster::RasterPath,
    feed: f64,
    resolution: f64,
) -> Result<String, ProgramError> {
    let mut w = MoveWriter::new(
        header,
        "G17 G21 G90 G40 G49 G80 G94",
        &['X', 'Y', 'Z'],
        resolution,
    );
    let f = Some((feed * 60.0, 3));
    let nan = f64::NAN;
    w.motion("G0", &[nan, nan, path.safe_z], None)?;
    for pass in &path.passes {
        let Some(first) = pass.first() else { continue };
        w.motion("G0", &[first[0], first[1], nan], None)?;
        w.motion("G1", &[nan, nan, first[2]], f)?;
        for p in &pass[1..] {
            w.motion("G1", p, None)?;
        }
        w.motion("G0", &[nan, nan, path.safe_z], None)?;
    }
    Ok(w.finish())
}

/// A LinuxCNC program for a grinding pass: X (radius, G8) and Z of the
/// wheel centre, each interval at its own feed so that the contact point
/// advances at v_f (the interval takes δ/v_f).
pub fn emit_grinding(
    header: &[String],
    path: &crate::grinding::GrindingPath,
    feed: f64,
    safe_z: f64,
    resolution: f64,
) -> Result<String, ProgramError> {
    let mut w = MoveWriter::new(
        header,
        "G18 G21 G90 G8 G40 G49 G80 G94",
        &['X', 'Z'],
        resolution,
    );
    let Some(first) = path.points.first() else {
        return Ok(w.finish());
    };
    w.raw("M3");
    w.motion("G0", &[first.x, safe_z], None)?;
    // The approach at the grinding feed.
    w.motion("G1", &[first.x, first.z], Some((feed * 60.0, 6)))?;
    for pair in path.points.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        let step = ((b.x - a.x).powi(2) + (b.z - a.z).powi(2)).sqrt();
        // The interval's time: its contact-x length at v_f.
        let dt = (b.contact_x - a.contact_x).abs() / feed;
        w.motion("G1", &[b.x, b.z], Some((step / dt * 60.0, 6)))?;
    }
    w.motion("G0", &[f64::NAN, safe_z], None)?;
    w.raw("M5");
    Ok(w.finish())
}

/// A LinuxCNC program for roller helix turning: X (the nose centre's
/// distance from the roller axis, G8), Z along the roller, C the spindle
/// angle in degrees counted on from the first pass; each pass starts on a
/// whole turn after the last, moves timed by inverse-time feed (G93).
pub struct RollerProgram {
    text: String,
    decimals: u32,
    safe_x: f64,
    spindle_speed: f64,
    /// C (degrees) where the current pass started, and the last point.
    c_base: f64,
    last: Option<crate::roller::RollerPoint>,
    pass: usize,
    pub moves: usize,
}

impl RollerProgram {
    pub fn new(header: &[String], resolution: f64, safe_x: f64, spindle_speed: f64) -> Self {
        let mut text = String::new();
        for line in header {
            write_comment(&mut text, line);
        }
        text.push_str("G18 G21 G90 G8 G40 G49 G80 G93\n");
        RollerProgram {
            text,
            decimals: decimals_for(resolution),
            safe_x,
            spindle_speed,
            c_base: 0.0,
            last: None,
            pass: usize::MAX,
            moves: 0,
        }
    }

    /// Appends points of pass `pass`; a new pass retracts X, moves to its
    /// start on the next whole turn of C, and plunges.
    pub fn extend(
        &mut self,
        pass: usize,
        points: &[crate::roller::RollerPoint],
    ) -> Result<(), ProgramError> {
        let d = self.decimals;
        for p in points {
            let line = &mut self.text;
            if pass != self.pass {
                if let Some(last) = self.last {
                    let c_end = self.c_base + last.c.to_degrees();
                    self.c_base = (c_end / 360.0).floor() * 360.0 + 360.0;
                    line.push_str("G0 X");
                    word(line, 'X', self.safe_x, d)?;
                    line.push('\n');
                }
                self.pass = pass;
                line.push_str("G0 X");
                word(line, 'X', self.safe_x, d)?;
                line.push_str(" Z");
                word(line, 'Z', p.z, d)?;
                line.push_str(" C");
                word(line, 'C', self.c_base + p.c.to_degrees(), C_DECIMALS)?;
                // The plunge: one second.
                line.push_str("\nG1 X");
                word(line, 'X', p.x, d)?;
                line.push_str(" F60.\n");
                self.moves += 2;
                self.last = Some(*p);
                continue;
            }
            let last = self.last.expect("a pass has begun");
            let dt = (p.c - last.c) / self.spindle_speed;
            line.push_str("G1 X");
            word(line, 'X', p.x, d)?;
            line.push_str(" Z");
            word(line, 'Z', p.z, d)?;
            line.push_str(" C");
            word(line, 'C', self.c_base + p.c.to_degrees(), C_DECIMALS)?;
            line.push_str(" F");
            word(line, 'F', 60.0 / dt, 3)?;
            line.push('\n');
            self.moves += 1;
            self.last = Some(*p);
        }
        Ok(())
    }

    /// The text written since the last call.
    pub fn take_text(&mut self) -> String {
        std::mem::take(&mut self.text)
    }

    /// Retracts and ends the program; the text not yet taken.
    pub fn finish(mut self) -> Result<String, ProgramError> {
        self.text.push_str("G0 X");
        word(&mut self.text, 'X', self.safe_x, self.decimals)?;
        self.text.push_str("\nM2\n");
        Ok(self.text)
    }
}
