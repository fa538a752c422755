//! Every program is complete, read back from its text by rules written
//! from the controllers' manuals (not from the writer): a tool call before
//! the first move; the spindle started (at a stated S, its mode G96/G97
//! stated where the controller has constant surface speed), held still
//! for a knife (M19; Heidenhain ISO's G36, cycle 13), or turned as a C
//! axis before any feed move; S, T, M, H
//! and D written as integers, without a decimal point; and at the program
//! end the spindle stopped. Run over every example's program in its
//! machine's own dialect here, and in every other dialect it offers by
//! `dialects.rs`.

use crate::common::{Written, built_examples};

/// Dialects whose controllers have constant surface speed (G96), so a
/// constant-rpm start must say G97.
const HAS_G96: &[&str] = &[
    "linuxcnc",
    "fanuc_0i_lathe",
    "siemens_840d_lathe",
    "siemens_840d_mill",
    "ultra_precision_lathe_gcode",
];

#[derive(Clone, Copy, PartialEq, Debug)]
enum Spindle {
    Stopped,
    Turning,
    Held,
    CAxis,
}

/// The code of one line: comments, block numbers, block ends and
/// program-name lines taken away.
fn code(line: &str) -> Option<String> {
    let line = line.split(';').next().unwrap_or("");
    let mut out = String::new();
    let mut depth = 0;
    for c in line.chars() {
        match c {
            '(' => depth += 1,
            ')' => depth -= 1,
            _ if depth == 0 => out.push(c),
            _ => {}
        }
    }
    let out = out.trim().trim_end_matches('*').trim();
    let out = match out.strip_prefix('N') {
        Some(rest) if rest.starts_with(|c: char| c.is_ascii_digit()) => {
            rest.trim_start_matches(|c: char| c.is_ascii_digit()).trim()
        }
        _ => out,
    };
    let skip =
        out.is_empty() || out.starts_with('%') || out.starts_with('O') || out.starts_with('…');
    (!skip).then(|| out.to_string())
}

/// The number of a word (`S1000` → `1000`), if it has one.
fn number(w: &str) -> Option<&str> {
    let n = w.get(1..)?;
    (!n.is_empty()
        && n.trim_start_matches('-')
            .bytes()
            .all(|b| b.is_ascii_digit() || b == b'.'))
    .then_some(n)
}

/// A Klartext block as the G-code words of the same meaning, for the
/// rules above (TNC conversational programming): `TOOL CALL 1 Z S1000` →
/// `T1 S1000`, `L … FMAX` → `G0 …`, `L … F…` → `G1 …`, `C … DR-` →
/// `G2 …`, `DR+` → `G3`, `CYCL DEF 13.0 ORIENTATION` → `M19`; the block
/// number, `BEGIN`/`END PGM`, `BLK FORM` and other cycles left out.
fn klartext_as_words(line: &str) -> String {
    let rest = line
        .trim_start_matches(|c: char| c.is_ascii_digit())
        .trim_start();
    let rest = rest.split(';').next().unwrap_or("").trim();
    let words: Vec<&str> = rest.split_whitespace().collect();
    match words.first().copied() {
        // Cycle 13 orients the spindle and holds it, as M19 does.
        Some("CYCL") if words.get(2) == Some(&"13.0") => "M19".to_string(),
        Some("BEGIN" | "END" | "CYCL" | "BLK") | None => String::new(),
        Some("TOOL") => words[2..]
            .iter()
            .map(|w| {
                if w.bytes().all(|b| b.is_ascii_digit()) {
                    format!("T{w}")
                } else {
                    w.to_string()
                }
            })
            .filter(|w| w != "Z")
            .collect::<Vec<_>>()
            .join(" "),
        Some("L") => {
            let g = if words.contains(&"FMAX") { "G0" } else { "G1" };
            std::iter::once(g)
                .chain(
                    words[1..]
                        .iter()
                        .copied()
                        .filter(|w| *w != "FMAX" && *w != "R0"),
                )
                .collect::<Vec<_>>()
                .join(" ")
        }
        Some("C") => {
            let g = if words.contains(&"DR-") { "G2" } else { "G3" };
            std::iter::once(g)
                .chain(words[1..].iter().copied().filter(|w| !w.starts_with("DR")))
                .collect::<Vec<_>>()
                .join(" ")
        }
        Some("CC") => String::new(),
        Some(_) => rest.to_string(),
    }
}

/// The rules above, or the first line that breaks one.
pub fn complete(dialect: &str, program: &str) -> Result<(), String> {
    if dialect == "heidenhain_tnc_klartext" {
        let words: String = program
            .lines()
            .map(|l| klartext_as_words(l) + "\n")
            .collect();
        return complete("klartext as words", &words);
    }
    let mut tool = false;
    let mut spindle = Spindle::Stopped;
    let mut s_given = false;
    let mut mode_given = false;
    let mut ended = false;
    for line in program.lines() {
        let Some(code) = code(line) else { continue };
        let words: Vec<&str> = code.split_whitespace().collect();
        for w in &words {
            let letter = w.chars().next().unwrap_or(' ');
            let Some(n) = number(w) else {
                if w.starts_with("SPOS") || w.starts_with("SPCON") {
                    spindle = Spindle::Held;
                }
                continue;
            };
            if "STMHD".contains(letter) && n.contains('.') {
                return Err(format!("a decimal point in an integer word {w}: {line}"));
            }
            match (letter, n) {
                ('T', _) => tool = true,
                ('S', _) => s_given = true,
                ('G', "96" | "97") => mode_given = true,
                ('C', _) if spindle != Spindle::Turning => spindle = Spindle::CAxis,
                ('M', "19") => spindle = Spindle::Held,
                // Heidenhain ISO: G36 is cycle 13 ORIENTATION (S the angle).
                ('G', "36") if dialect == "heidenhain_iso" => spindle = Spindle::Held,
                ('M', "5") => spindle = Spindle::Stopped,
                ('M', "2" | "30") => ended = true,
                _ => {}
            }
        }
        // Spindle starts are read after the block's S and G96/G97.
        if words
            .iter()
            .any(|w| matches!(*w, "M3" | "M4" | "M03" | "M04"))
        {
            if !s_given {
                return Err(format!("the spindle starts with no S stated: {line}"));
            }
            if HAS_G96.contains(&dialect) && !mode_given {
                return Err(format!(
                    "a spindle start with no G96 or G97 before it: {line}"
                ));
            }
            spindle = Spindle::Turning;
        }
        let moves = |set: &[&str]| words.iter().any(|w| set.contains(w));
        let rapid = moves(&["G0", "G00"]);
        let feed = moves(&["G1", "G2", "G3", "G01", "G02", "G03"]);
        if (rapid || feed) && !tool {
            return Err(format!("a move before the tool call: {line}"));
        }
        if feed && spindle == Spindle::Stopped {
            return Err(format!("a feed move with the spindle stopped: {line}"));
        }
        if ended && matches!(spindle, Spindle::Turning | Spindle::Held) {
            return Err(format!("the program ends with the spindle on: {line}"));
        }
    }
    if !tool {
        return Err("no tool call".into());
    }
    if !ended {
        return Err("no program end (M2 or M30)".into());
    }
    Ok(())
}

#[test]
fn every_example_program_is_complete_in_its_own_dialect() {
    let mut read = 0;
    for built in built_examples() {
        for (name, file) in &built.files {
            if !crate::common::is_program(name) {
                continue;
            }
            let text = match file {
                Written::Whole(bytes) => String::from_utf8(bytes.clone()).expect("utf-8"),
                Written::Abridged(text) => text.clone(),
            };
            let dialect = text
                .lines()
                .find_map(|l| {
                    l.trim_start_matches(['(', ';', ' '])
                        .strip_prefix("machine ")
                })
                .and_then(|m| m.split_whitespace().nth(1))
                .unwrap_or("linuxcnc")
                .to_string();
            complete(&dialect, &text).unwrap_or_else(|e| panic!("{name} ({dialect}): {e}"));
            read += 1;
        }
    }
    assert!(read >= 20, "only {read} programs read");
}

#[test]
fn the_rules_catch_each_defect_they_are_for() {
    let good = "G18 G21 G90 G8 G40 G49 G80 G94\nT1 M6 G43\nG97 S1000 M3\nG0 Z1.\nG95 G1 Z0. F0.001\nG0 Z1.\nM5\nM2\n";
    complete("linuxcnc", good).expect("a complete program");
    let broken = [
        (good.replace("T1 M6 G43\n", ""), "move before the tool call"),
        (good.replace("G97 S1000 M3\n", ""), "spindle stopped"),
        (good.replace("G97 S1000", "G97 S1000."), "decimal point"),
        (good.replace("G97 S1000 M3", "S1000 M3"), "no G96 or G97"),
        (good.replace("M5\n", ""), "spindle on"),
        // A raster that never starts its spindle (the original defect).
        (
            "G17 G21 G90 G94\nT1 M6 G43 H1\nG0 Z1.\nG94 G1 Z0. F100.\nM2\n".to_string(),
            "spindle stopped",
        ),
    ];
    for (program, why) in broken {
        let e = complete("linuxcnc", &program).expect_err(why);
        assert!(e.contains(why), "{e}");
    }
    // A Fanuc lathe's T word carries tool and offset, and S no point.
    let fanuc = "%\nO1 (X)\nG18 G21 G40 G80 G90 G94\nT0101\nG97 S1000. M3\nG0 Z1.\nM5\nM30\n%\n";
    assert!(complete("fanuc_0i_lathe", fanuc).is_err());
    assert!(complete("fanuc_0i_lathe", &fanuc.replace("S1000.", "S1000")).is_ok());
}
