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
    // text is folded at ", " into several comments, the line ending in
    // "," and the next starting with two spaces. A piece with no ", " in
    // it longer than a line is folded between words (the line ends
    // without ","), or by characters where a word is longer than a line.
    const WIDTH: usize = 120;
    let mut line = String::new();
    for (i, piece) in clean.split(", ").enumerate() {
        let whole = piece.chars().count();
        if i > 0 && line.chars().count() + whole + 2 > WIDTH {
            let _ = writeln!(out, "({line},)");
            line = String::from("  ");
        } else if i > 0 {
            line.push_str(", ");
        }
        let mut rest = piece;
        while line.chars().count() + rest.chars().count() > WIDTH {
            let room = WIDTH.saturating_sub(line.chars().count()).max(1);
            let cut = rest.char_indices().nth(room).map_or(rest.len(), |(b, _)| b);
            // The last space within the room, or (a word longer than a
            // line) the room's end.
            let at = match rest[..cut].rfind(' ') {
                Some(b) if b > 0 => b,
                _ => cut,
            };
            line.push_str(&rest[..at]);
            let _ = writeln!(out, "({line})");
            line = String::from("  ");
            rest = rest[at..].trim_start_matches(' ');
        }
        line.push_str(rest);
    }
    let _ = writeln!(out, "({line})");
}

/// A number as a header states it: Rust's shortest digits that read back
/// to the same f64, in plain notation while that takes at most 17
/// characters (sign aside) or is no longer than the other, else in
/// scientific notation (`-1.2e-17`, not 20 zeros); zero is `0`, never `-0`
/// (a signed zero states the same part).
pub fn exact(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let plain = format!("{v}");
    let scientific = format!("{v:e}");
    if plain.trim_start_matches('-').len() <= 17 || plain.len() <= scientific.len() {
        plain
    } else {
        scientific
    }
}

/// `v` (base units) stated in a unit of `size` base units, so that it reads
/// back to `v` exactly: the shortest decimal `d` with `d * size == v` (a
/// `.lens` file's `d unit` is `d × size`, and 10 nm is 9.999999999999999e-6
/// mm, not 1e-5). If no decimal of up to 17 significant digits reads back
/// (a product with `size` skips some f64), the nearest figure, `v / size`.
pub fn exact_in(v: f64, size: f64) -> String {
    if size == 1.0 || !v.is_finite() {
        return exact(v);
    }
    let shown = v / size;
    let reads_back = |d: f64| d * size == v;
    // The fewest significant digits first: `v / size` may read back and
    // still be longer than need be (0.00025 mm / 1e-6 is
    // 250.00000000000003 nm, and 250 nm reads back too).
    (0..17)
        .filter_map(|digits| format!("{shown:.digits$e}").parse::<f64>().ok())
        .find(|&d| reads_back(d))
        .map_or_else(|| exact(shown), exact)
}

/// A figure derived for people (a share of a tolerance, a measured
/// deviation) to 10 decimals (0.1 pm in mm), trailing zeros trimmed: no
/// exponent, and `1e-5` shows as `0.00001`, not `0.000009999…`. What the
/// job states is printed with [`exact`] or [`exact_in`].
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_long_piece_is_folded_between_words_never_inside_one() {
        // The spline header's last piece: 130 characters with no ", ".
        let piece = "largest deviation 0 nm (limit 2.4 nm); no spline written: runs without the control's spline interpolation option (BSPLINE)";
        let mut out = String::new();
        write_comment(&mut out, &format!("interpolation: B spline, {piece}"));
        let lines: Vec<&str> = out.lines().collect();
        assert!(lines.iter().all(|l| l.chars().count() <= 122), "{out}");
        // Every word whole: the text back from the lines, joined at their
        // folds, is the text written (brackets for parentheses).
        let words: Vec<&str> = lines
            .iter()
            .flat_map(|l| l.trim_matches(|c| c == '(' || c == ')').split_whitespace())
            .collect();
        let written = format!("interpolation: B spline, {piece}")
            .replace('(', "[")
            .replace(')', "]");
        assert_eq!(
            words.join(" "),
            written.split_whitespace().collect::<Vec<_>>().join(" "),
            "{out}"
        );
        assert!(out.contains("[BSPLINE]"), "{out}");
    }

    #[test]
    fn exact_reads_back_and_never_writes_minus_zero() {
        for v in [
            -1.2e-17,
            3.4e-19,
            1e-5,
            0.1,
            5.540000000000001,
            8.5,
            -0.62,
            1e300,
            -2.5e-12,
        ] {
            let s = exact(v);
            assert_eq!(s.parse::<f64>().map(f64::to_bits), Ok(v.to_bits()), "{s}");
        }
        assert_eq!(exact(-0.0), "0");
        assert_eq!(exact(-1.2e-17), "-1.2e-17");
        assert_eq!(exact(-0.0000034), "-0.0000034");
        assert_eq!(exact(5.540000000000001), "5.540000000000001");
        assert_eq!(exact(-2.7700000000000005), "-2.7700000000000005");
    }

    #[test]
    fn exact_in_a_unit_reads_back_through_that_units_size() {
        // 10 nm as a .lens file reads it, and the same in degrees.
        let nm = 1e-6;
        let t = 10.0 * nm;
        assert_ne!(t, 1e-5);
        assert_eq!(exact_in(t, nm), "10");
        let deg = std::f64::consts::PI / 180.0;
        for (written, size) in [
            (3.0, deg),
            (0.025, deg),
            (1.4999999999999998, nm),
            (4.0, 1e-3),
        ] {
            let v = written * size;
            let s = exact_in(v, size);
            let d: f64 = s.parse().expect("a number");
            assert_eq!((d * size).to_bits(), v.to_bits(), "{s}");
        }
        assert_eq!(exact_in(3.0 * deg, deg), "3");
    }

    #[test]
    fn exact_in_a_unit_is_the_fewest_digits_that_read_back() {
        // 0.5 um in nm: 0.0005 mm / 1e-6 is 500.00000000000006, which
        // reads back, but so does 500.
        let (nm, um) = (1e-6, 1e-3);
        for (written, size, unit, want) in [
            (0.5, um, nm, "500"),
            (0.25, um, nm, "250"),
            (0.37, um, nm, "370"),
            (10.0, nm, nm, "10"),
        ] {
            let v = written * size;
            let s = exact_in(v, unit);
            assert_eq!(s, want);
            assert_eq!(s.parse::<f64>().unwrap() * unit, v, "{s}");
        }
    }
}
