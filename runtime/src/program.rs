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
    let comment = |out: &mut String, text: &str| {
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
    };
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
            "tool {}: round nose, nose radius {} mm",
            job.tool_name,
            num(job.tool.nose_radius)
        ),
    );
    comment(
        &mut out,
        &format!(
            "strategy {}: profile turning, {} points, chord tolerance {} nm",
            job.strategy_name,
            path.cut_points,
            num(job.strategy.chord_tolerance * 1e6)
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
