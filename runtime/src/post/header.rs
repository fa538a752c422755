//! What every program header says: where the job came from, comments as
//! the dialect writes them, and figures printed for people.

use std::fmt::Write as _;

/// What the program header states about where the job came from.
#[derive(Clone, Debug, PartialEq)]
pub struct Provenance {
    /// The source file as the user named it.
    pub source: String,
    /// FNV-1a 64 of the source text and every file it uses, in load order.
    pub source_hash: u64,
    pub lensc_version: String,
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

/// A header figure to 10 decimals (0.1 pm in mm), trailing zeros trimmed:
/// no exponent, and `1e-5` shows as `0.00001`, not `0.000009999…`.
pub fn num(v: f64) -> String {
    let s = format!("{v:.10}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.to_string() }
}

pub fn duration(secs: f64) -> String {
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
