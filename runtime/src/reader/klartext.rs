//! One Heidenhain Klartext block to the reader's words, as a TNC reads it
//! (TNC 640 / 620 conversational programming): the block number (bare, in
//! sequence from 0), `BEGIN PGM NAME MM|INCH` (units; Klartext is
//! absolute, feeds in mm/min), `END PGM NAME MM`, `BLK FORM`, `CYCL DEF
//! 32.x` (tolerance), `TOOL CALL [n] Z [S…]`, `L` (a line, or a rapid
//! with `FMAX`; `R0`), `CC X… Y…` (the circle centre, modal), `C X… Y…
//! DR±` (an arc about it), M functions alone, and `;` comments. Each is
//! given to the modal reader as the words a G-code block of the same
//! meaning holds (`L … FMAX` as G0, `C … DR-` as G2 with the centre as
//! absolute I J, `R0` as G40, `BEGIN PGM … MM` as G71 G90 G94, `TOOL
//! CALL 1 Z S1000` as T1 G17 S1000), each with the span of the text it
//! reads, so every rule of the modal reader holds of Klartext too. Its
//! own rules: block numbers in sequence, an arc after its circle centre,
//! and the program framed by `BEGIN PGM` and `END PGM` of one name.

use super::Rule;
use super::lexer::{Block, Found, Lexer, Word, number};
use crate::moves::Plane;

/// What the Klartext reader keeps from block to block.
#[derive(Default)]
pub(crate) struct Klartext {
    /// The block number the next block must carry.
    next: u64,
    /// The circle centre `CC` in force: the plane its two axes name, and
    /// its two coordinates as written (in X, Y, Z order).
    centre: Option<CircleCentre>,
    /// The name of `BEGIN PGM`, once read.
    name: Option<String>,
    /// Blocks read so far (a `BEGIN PGM` must be the first).
    blocks: usize,
    /// `END PGM` read.
    ended: bool,
    /// The frame rule already reported for a missing `BEGIN PGM`.
    no_begin_told: bool,
}

/// A circle centre: the plane its two axes name, and each axis's letter
/// and coordinate as written (in X, Y, Z order).
type CircleCentre = (Plane, (char, f64), (char, f64));

/// A word the modal reader takes, standing for Klartext text at `span`.
fn word(letter: char, value: f64, span: (usize, usize)) -> Word {
    Word {
        letter,
        value,
        span,
        point: false,
        decimals: 0,
    }
}

/// A word of the line split at whitespace: its text and span.
type Token<'a> = (&'a str, (usize, usize));

impl Klartext {
    /// Reads one line (without its line break) into a block.
    pub fn block(&mut self, lex: &Lexer, line: &str, out: &mut Vec<Found>) -> Block {
        let mut b = Block::default();
        lex.line_length(line, out);
        let code = match line.find(';') {
            Some(i) => {
                b.comments.push(line[i + 1..].trim().to_string());
                &line[..i]
            }
            None => line,
        };
        let mut tokens: Vec<Token> = code
            .split_whitespace()
            .map(|t| {
                let s = t.as_ptr() as usize - code.as_ptr() as usize;
                (t, (s, s + t.len()))
            })
            .collect();
        if tokens.is_empty() && b.comments.is_empty() {
            return b;
        }
        if let Some(&(t, span)) = tokens.first()
            && t.bytes().all(|c| c.is_ascii_digit())
        {
            let n = t.parse::<f64>().unwrap_or(f64::MAX);
            b.number = Some(word('N', n, span));
            if n != self.next as f64 {
                out.push((
                    Rule::BlockSequence,
                    span,
                    format!(
                        "block number {t} where the TNC expects {}: Klartext numbers its blocks from 0 in steps of 1",
                        self.next
                    ),
                    Some("renumber the program's blocks in order".into()),
                ));
            }
            self.next = (n as u64).saturating_add(1);
            tokens.remove(0);
        } else {
            self.next += 1;
        }
        if tokens.is_empty() {
            return b;
        }
        self.frame(&tokens, line, &mut b, out);
        self.blocks += 1;
        if b.percent {
            return b;
        }
        let (head, _) = tokens[0];
        match head {
            "BEGIN" | "END" => {}
            "BLK" if tokens.get(1).is_some_and(|t| t.0 == "FORM") => {}
            "CYCL" => cycle(&tokens, &mut b, out),
            "TOOL" => tool(&tokens, lex, line, &mut b, out),
            "L" => self.path(&tokens, false, lex, line, &mut b, out),
            "CC" => self.circle_centre(&tokens, lex, line, out),
            "C" => self.path(&tokens, true, lex, line, &mut b, out),
            "STOP" => b.words.push(word('M', 0.0, tokens[0].1)),
            _ if head.starts_with('M') => {
                for &t in &tokens {
                    address(t, lex, line, &mut b, out, "M");
                }
            }
            _ => out.push(unknown(tokens[0].1, head)),
        }
        b
    }

    /// `BEGIN PGM` first, `END PGM` last, of one name and unit.
    fn frame(&mut self, tokens: &[Token], line: &str, b: &mut Block, out: &mut Vec<Found>) {
        let head = tokens[0].0;
        let framed = |what: String, span, out: &mut Vec<Found>| {
            out.push((
                Rule::ProgramFrame,
                span,
                what,
                Some("open the program with `0 BEGIN PGM NAME MM` and close it with `END PGM NAME MM`".into()),
            ))
        };
        if self.ended {
            framed(
                "a block after END PGM: the TNC reads nothing past it".into(),
                (0, line.len()),
                out,
            );
            return;
        }
        let whole = (tokens[0].1.0, tokens[tokens.len() - 1].1.1);
        match head {
            "BEGIN" | "END" => {
                let pgm = tokens.get(1).is_some_and(|t| t.0 == "PGM");
                let (Some(name), Some(unit), true, 4) =
                    (tokens.get(2), tokens.get(3), pgm, tokens.len())
                else {
                    framed(
                        format!("`{}` is not `{head} PGM NAME MM`", &line[whole.0..whole.1]),
                        whole,
                        out,
                    );
                    return;
                };
                let metric = match unit.0 {
                    "MM" => true,
                    "INCH" => false,
                    _ => {
                        framed(format!("`{}`: the unit is MM or INCH", unit.0), unit.1, out);
                        return;
                    }
                };
                if head == "BEGIN" {
                    if self.blocks > 0 {
                        framed(
                            "BEGIN PGM after the program's first block".into(),
                            whole,
                            out,
                        );
                    }
                    self.name = Some(name.0.to_string());
                    b.words
                        .push(word('G', if metric { 71.0 } else { 70.0 }, unit.1));
                    b.words.push(word('G', 90.0, tokens[0].1));
                    b.words.push(word('G', 94.0, tokens[0].1));
                } else {
                    if self.name.as_deref().is_some_and(|n| n != name.0) {
                        framed(
                            format!(
                                "END PGM {} closes a program that began as {}",
                                name.0,
                                self.name.as_deref().unwrap_or("")
                            ),
                            name.1,
                            out,
                        );
                    }
                    self.ended = true;
                    b.percent = true;
                }
            }
            _ if self.name.is_none() && !self.no_begin_told => {
                self.no_begin_told = true;
                framed(
                    "a block before BEGIN PGM: the TNC reads a program from its BEGIN PGM block"
                        .into(),
                    whole,
                    out,
                );
            }
            _ => {}
        }
    }

    /// What is wrong once the whole program is read.
    pub fn finish(&self, out: &mut Vec<Found>) {
        if !self.ended {
            out.push((
                Rule::ProgramFrame,
                (0, 0),
                "the program is not closed by END PGM".into(),
                Some("close it with `END PGM NAME MM`, the name of its BEGIN PGM".into()),
            ));
        }
    }

    /// An `L` block (a line; a rapid with `FMAX`) or a `C` block (an arc
    /// about the circle centre in force, `DR-` clockwise).
    fn path(
        &mut self,
        tokens: &[Token],
        arc: bool,
        lex: &Lexer,
        line: &str,
        b: &mut Block,
        out: &mut Vec<Found>,
    ) {
        let head = tokens[0].1;
        let mut motion = if arc { None } else { Some(1.0) };
        for &(t, span) in &tokens[1..] {
            match t {
                "FMAX" if !arc => motion = Some(0.0),
                "R0" => b.words.push(word('G', 40.0, span)),
                "DR-" if arc => motion = Some(2.0),
                "DR+" if arc => motion = Some(3.0),
                "RL" | "RR" => out.push((
                    Rule::UnknownWord,
                    span,
                    format!("`{t}`: radius compensation; lensc programs the tool centre (R0)"),
                    None,
                )),
                _ => address((t, span), lex, line, b, out, "XYZFM"),
            }
        }
        let Some(g) = motion else {
            out.push((
                Rule::ArcWords,
                head,
                "an arc (C) with no direction: DR- (clockwise) or DR+".into(),
                None,
            ));
            return;
        };
        b.words.insert(0, word('G', g, head));
        if arc {
            match self.centre {
                Some((plane, (l1, v1), (l2, v2))) => {
                    // The arc's plane is its centre's: as G17/G18/G19
                    // with the centre as absolute I, J, K.
                    let g = match plane {
                        Plane::Xy => 17.0,
                        Plane::Zx => 18.0,
                        Plane::Yz => 19.0,
                    };
                    let ijk = |l: char| match l {
                        'X' => 'I',
                        'Y' => 'J',
                        _ => 'K',
                    };
                    b.words.insert(0, word('G', g, head));
                    b.words.push(word(ijk(l1), v1, head));
                    b.words.push(word(ijk(l2), v2, head));
                }
                None => {
                    out.push((
                        Rule::NoCircleCentre,
                        head,
                        "an arc before any circle centre (CC): the TNC refuses it".into(),
                        Some("state the centre first: `CC X… Y…`".into()),
                    ));
                    // The TNC refuses the block: no move is read from it.
                    b.words.clear();
                }
            }
        }
    }

    /// `CC X… Y…`, `CC X… Z…` or `CC Y… Z…`: the centre of the arcs that
    /// follow, in the plane its two axes name (TNC 620 conversational
    /// manual: a circle may lie in a plane other than the working plane;
    /// see docs/controllers/heidenhain.md).
    fn circle_centre(&mut self, tokens: &[Token], lex: &Lexer, line: &str, out: &mut Vec<Found>) {
        let mut b = Block::default();
        for &t in &tokens[1..] {
            address(t, lex, line, &mut b, out, "XYZ");
        }
        let at = |l: char| b.words.iter().find(|w| w.letter == l).map(|w| (l, w.value));
        let plane = match (at('X'), at('Y'), at('Z')) {
            (Some(x), Some(y), None) => Some((Plane::Xy, x, y)),
            (Some(x), None, Some(z)) => Some((Plane::Zx, x, z)),
            (None, Some(y), Some(z)) => Some((Plane::Yz, y, z)),
            _ => None,
        };
        match plane {
            Some(c) => self.centre = Some(c),
            None => out.push((
                Rule::ArcWords,
                tokens[0].1,
                "a circle centre needs two axes of one plane: X and Y, X and Z, or Y and Z".into(),
                None,
            )),
        }
    }
}

/// `CYCL DEF 32.0 TOLERANCE`, `32.1 T…`, `32.2 …` (the path tolerance)
/// and `CYCL DEF 13.0 ORIENTATION`, `13.1 ANGLE …` (the spindle stopped
/// and held at an angle, read as M19 is elsewhere): the cycles lensc
/// writes; others are not read.
fn cycle(tokens: &[Token], b: &mut Block, out: &mut Vec<Found>) {
    let number = tokens
        .get(2)
        .filter(|_| tokens.get(1).is_some_and(|t| t.0 == "DEF"));
    match number.map(|t| t.0) {
        Some(n) if n.starts_with("32.") => {}
        Some("13.0") => b.words.push(word('M', 19.0, tokens[0].1)),
        Some(n) if n.starts_with("13.") => {}
        _ => {
            let span = (tokens[0].1.0, tokens[tokens.len() - 1].1.1);
            out.push((
                Rule::UnknownWord,
                span,
                "a cycle other than 32 (TOLERANCE) and 13 (ORIENTATION), which this reader does not follow".into(),
                None,
            ));
        }
    }
}

/// `TOOL CALL [n] [Z] [S…]` (`TOOL DEF n` preselects and is passed over).
fn tool(tokens: &[Token], lex: &Lexer, line: &str, b: &mut Block, out: &mut Vec<Found>) {
    match tokens.get(1).map(|t| t.0) {
        Some("DEF") => return,
        Some("CALL") => {}
        _ => {
            out.push(unknown(tokens[0].1, tokens[0].0));
            return;
        }
    }
    for &(t, span) in &tokens[2..] {
        if t.bytes().all(|c| c.is_ascii_digit()) {
            b.words.push(word('T', t.parse().unwrap_or(0.0), span));
        } else if t == "Z" {
            b.words.push(word('G', 17.0, span));
        } else if t == "X" || t == "Y" {
            out.push((
                Rule::UnknownWord,
                span,
                format!("tool axis {t}: this reader follows programs with the tool along Z"),
                None,
            ));
        } else {
            address((t, span), lex, line, b, out, "SF");
        }
    }
}

/// An address word of one of `letters` (`X+1.5`, `F300`, `M3`), its
/// number checked against the dialect's format.
fn address(
    (t, span): Token,
    lex: &Lexer,
    line: &str,
    b: &mut Block,
    out: &mut Vec<Found>,
    letters: &str,
) {
    let letter = t.chars().next().unwrap_or(' ');
    if !letters.contains(letter) || t.len() < 2 {
        out.push(unknown(span, t));
        return;
    }
    let (n, end) = number(t, 1);
    let Some((value, point, decimals)) = n.filter(|_| end == t.len()) else {
        out.push((
            Rule::MalformedNumber,
            span,
            format!("`{t}` is not a letter and a number"),
            None,
        ));
        return;
    };
    let w = Word {
        letter,
        value,
        span,
        point,
        decimals,
    };
    lex.number_format(&w, line, out);
    b.words.push(w);
}

fn unknown(span: (usize, usize), t: &str) -> Found {
    (
        Rule::UnknownWord,
        span,
        format!("`{t}` is not a Klartext block or word this reader knows"),
        None,
    )
}

#[cfg(test)]
mod tests {
    use crate::dialect::{CommentStyle, Dialect, Language};
    use crate::reader::{MachineLimits, Rule, read};

    fn klartext() -> Dialect {
        Dialect {
            language: Language::Klartext,
            comment: CommentStyle::Semicolon,
            line_numbers: Some(1),
            arc_centre_absolute: true,
            ..Dialect::linuxcnc()
        }
    }

    const MILL: MachineLimits = MachineLimits {
        lathe: false,
        travel: [None; 4],
        max_feed: None,
        max_spindle_rpm: None,
        servo: None,
    };

    #[test]
    fn any_line_is_read_without_a_panic() {
        let lines = [
            "",
            "5",
            "5 ;",
            ";",
            "BEGIN",
            "END PGM",
            "BEGIN PGM X CM",
            "C",
            "CC X",
            "CC X+1",
            "L X+",
            "L X+1e5",
            "L Xé",
            "é",
            "TOOL",
            "TOOL CALL",
            "TOOL CALL Y",
            "CYCL",
            "L DR-",
            "C X+1 DR",
            "99999999999999999999999 L X+1",
            "L ++1",
            "M",
            "M3.5",
            "STOP",
            "BLK",
            "L X+1 X+2 R0 F0",
            "C X+1 Y+1 DR+ DR-",
        ];
        for l in lines {
            let text = format!("0 BEGIN PGM T MM\n1 {l}\n{l}\n3 END PGM T MM\n");
            let _ = read(&text, &klartext(), &MILL);
        }
    }

    #[test]
    fn units_come_from_begin_pgm() {
        let rules = |text: &str| -> Vec<Rule> {
            read(text, &klartext(), &MILL)
                .into_iter()
                .map(|f| f.rule)
                .collect()
        };
        let inch = "0 BEGIN PGM T INCH\n1 L X+1 R0 FMAX\n2 M30\n3 END PGM T INCH\n";
        assert!(rules(inch).is_empty(), "{:?}", rules(inch));
        let none = "0 L X+1 R0 FMAX\n1 M30\n2 END PGM T MM\n";
        let found = rules(none);
        assert!(found.contains(&Rule::ProgramFrame), "{found:?}");
        assert!(found.contains(&Rule::ModalStateUnstated), "{found:?}");
        let after = "0 BEGIN PGM T MM\n1 M30\n2 END PGM T MM\n3 L X+1 R0 FMAX\n";
        assert!(rules(after).contains(&Rule::ProgramFrame));
    }
}
