//! Splitting a program too large for its control into parts a main
//! program calls, at joins the dialect can make safely: where the tool is
//! clear of the part after a rapid (`part_joins: retract`, the control
//! stops between parts), or between any two moves where the control reads
//! through the call and the return without stopping the path
//! (`part_joins: continuous`). Each part opens with the dialect's part
//! lines and restates the modal words in force at its join; the main
//! program keeps the program's start, its header and its end, and calls
//! the parts in order in the control's own syntax (`PartCalls`).
//!
//! It works on the program's text as the writer wrote it (every move block
//! states its own motion word), imports only the dialect, and is read back
//! by `reader::parts`, which shares no code with it.

use crate::dialect::{CommentStyle, Dialect, PartCalls};

/// A program split into a main program and its parts.
#[derive(Clone, Debug, PartialEq)]
pub struct Split {
    /// The main program: start, header, one call per part, end.
    pub main: String,
    /// Each part's file name and text, in the order they are called.
    pub parts: Vec<(String, String)>,
}

/// Why a program could not be split within the limit.
#[derive(Clone, Debug, PartialEq)]
pub enum SplitError {
    /// The dialect calls no parts, or writes blocks a part cannot restate
    /// (numbered blocks, a block end, Klartext).
    NoPartCalls,
    /// A part's own lines (its opening and closing lines and the modal
    /// words it restates) with one block take `needed` bytes, more than
    /// the limit.
    HeaderOverLimit { needed: u64 },
    /// No join the dialect can make lies within the limit: the program's
    /// lines `from` to `to` (1-based) run `bytes` bytes with nowhere to end
    /// a part between them; a part holding them takes `needed` bytes.
    NoJoin {
        from: usize,
        to: usize,
        bytes: u64,
        needed: u64,
    },
}

/// Renders a part line: `{part}`, `{PART}`, `{number}`, `{k}`, `{job}`,
/// `{JOB}`.
pub fn part_line(template: &str, job: &str, k: usize, parts: &PartCalls, number: u32) -> String {
    let name = part_name(job, k, parts, number);
    template
        .replace("{part}", &name)
        .replace("{PART}", &name.to_uppercase())
        .replace("{number}", &(number as usize + k).to_string())
        .replace("{k}", &k.to_string())
        .replace("{job}", job)
        .replace("{JOB}", &job.to_uppercase())
}

/// Part `k`'s name (`part_name` rendered).
pub fn part_name(job: &str, k: usize, parts: &PartCalls, number: u32) -> String {
    parts
        .name
        .replace("{job}", job)
        .replace("{JOB}", &job.to_uppercase())
        .replace("{k}", &k.to_string())
        .replace("{number}", &(number as usize + k).to_string())
}

/// Splits `text` (job `job`'s whole program in `dialect`) into parts of
/// at most `limit` bytes each; `None` if it fits whole.
pub fn split(
    text: &str,
    dialect: &Dialect,
    job: &str,
    limit: u64,
) -> Result<Option<Split>, SplitError> {
    if text.len() as u64 <= limit {
        return Ok(None);
    }
    let calls = splittable(dialect).ok_or(SplitError::NoPartCalls)?;
    let lines: Vec<&str> = text.split_inclusive('\n').collect();
    let (head, tail) = frame(&lines, dialect);
    let body = &lines[head..tail];
    let mut cum = Vec::with_capacity(body.len() + 1);
    cum.push(0u64);
    for l in body {
        cum.push(cum.last().copied().unwrap_or(0) + l.len() as u64);
    }
    let number = dialect.program_number;
    // The bytes of part `k`'s own lines beside the body and its
    // restatement.
    let frame_bytes = |k: usize| -> u64 {
        let own = part_frame(dialect, calls, job, k, number);
        (own.0.len() + own.1.len()) as u64
    };
    let mut modal = Modal::default();
    // Each part: (first body line, restatement).
    let mut starts: Vec<(usize, String)> = vec![(0, String::new())];
    // The last join in the current part after a retract, and the last of
    // any kind: a part ends after a retract where one fits, mid-cut only
    // where none does.
    let mut best: Option<(usize, String)> = None;
    let mut best_retract: Option<(usize, String)> = None;
    let mut in_preamble = true;
    let mut previous_rapid = false;
    let mut previous_move = false;
    for (i, line) in body.iter().enumerate() {
        let words = words(line, dialect.comment);
        let motion = motion_of(&words);
        let is_move = motion.is_some();
        let join_here = !in_preamble
            && ((previous_rapid && is_move) || (calls.continuous && previous_move && is_move));
        if join_here {
            let join = (i, modal.restate(dialect.comment));
            if previous_rapid {
                best_retract = Some(join.clone());
            }
            best = Some(join);
        }
        modal.take(&words, line);
        if is_move {
            in_preamble = false;
        }
        previous_rapid = motion == Some(0);
        previous_move = is_move;
        // Does the part, with this line, still fit?
        loop {
            let k = starts.len();
            let (s, restated) = starts.last().cloned().unwrap_or_default();
            let size = frame_bytes(k) + restated.len() as u64 + cum[i + 1] - cum[s];
            if size <= limit {
                break;
            }
            let one_line = frame_bytes(k) + restated.len() as u64 + body[s].len() as u64;
            if i == s || one_line > limit {
                return Err(SplitError::HeaderOverLimit { needed: one_line });
            }
            let any = best.take();
            let chosen = match best_retract.take().filter(|(j, _)| *j > s) {
                Some(r) => {
                    // A later join of any kind may end the next part.
                    best = any.filter(|(b, _)| *b > r.0);
                    Some(r)
                }
                None => any,
            };
            match chosen {
                Some((j, r)) if j > s => starts.push((j, r)),
                _ => {
                    // With a limit this small, the part's own lines are
                    // what leave no room.
                    let longest = body[s..=i].iter().map(|l| l.len()).max().unwrap_or(0);
                    let needed = frame_bytes(k + 1)
                        + modal.restate(dialect.comment).len() as u64
                        + longest as u64;
                    if needed > limit {
                        return Err(SplitError::HeaderOverLimit { needed });
                    }
                    return Err(SplitError::NoJoin {
                        from: head + s + 1,
                        to: head + i + 1,
                        bytes: cum[i + 1] - cum[s],
                        needed: size,
                    });
                }
            }
        }
    }
    let n = starts.len();
    let mut parts = Vec::with_capacity(n);
    for (k0, (s, restated)) in starts.iter().enumerate() {
        let k = k0 + 1;
        let e = starts.get(k).map_or(body.len(), |(e, _)| *e);
        let (open, close) = part_frame(dialect, calls, job, k, number);
        let mut t = String::with_capacity((cum[e] - cum[*s]) as usize + 256);
        t.push_str(&open);
        t.push_str(restated);
        for l in &body[*s..e] {
            t.push_str(l);
        }
        t.push_str(&close);
        let name = format!("{}.{}", part_name(job, k, calls, number), calls.extension);
        parts.push((name, t));
    }
    let mut main = String::new();
    for l in &lines[..head] {
        main.push_str(l);
    }
    main.push_str(&comment(
        dialect.comment,
        &format!("delivered in {n} parts, each called in turn"),
    ));
    for k in 1..=n {
        main.push_str(&part_line(&calls.call, job, k, calls, number));
        main.push('\n');
    }
    for l in &lines[tail..] {
        main.push_str(l);
    }
    Ok(Some(Split { main, parts }))
}

/// The dialect's part calls, if its programs can be split: G-code blocks
/// with no block numbers and no block end (a part's restated blocks would
/// break the numbering).
pub fn splittable(dialect: &Dialect) -> Option<&PartCalls> {
    let plain = dialect.language == crate::dialect::Language::GCode
        && dialect.line_numbers.is_none()
        && dialect.block_end.is_empty();
    dialect.parts.as_ref().filter(|_| plain)
}

/// The lines that open and close part `k`, with its comment.
fn part_frame(
    dialect: &Dialect,
    calls: &PartCalls,
    job: &str,
    k: usize,
    number: u32,
) -> (String, String) {
    let render = |ls: &[String]| -> String {
        ls.iter()
            .map(|l| format!("{}\n", part_line(l, job, k, calls, number)))
            .collect()
    };
    let mut open = render(&calls.start);
    open.push_str(&comment(
        dialect.comment,
        &format!("{job}: part {k}, called by {job}.{}", dialect.extension),
    ));
    (open, render(&calls.end))
}

fn comment(style: CommentStyle, text: &str) -> String {
    match style {
        CommentStyle::Parentheses => format!("({text})\n"),
        CommentStyle::Semicolon => format!("; {text}\n"),
    }
}

/// The lines the main program keeps: before `head` (the dialect's start
/// lines and the header comments) and from `tail` (the program's last
/// end block, M30 or M2, and the trailer).
fn frame(lines: &[&str], dialect: &Dialect) -> (usize, usize) {
    let mut head = dialect.start.len().min(lines.len());
    while head < lines.len() && is_comment(lines[head], dialect.comment) {
        head += 1;
    }
    let tail = lines
        .len()
        .saturating_sub(dialect.trailer.len() + 1)
        .max(head);
    (head, tail)
}

fn is_comment(line: &str, style: CommentStyle) -> bool {
    let t = line.trim_start();
    match style {
        CommentStyle::Parentheses => t.starts_with('('),
        CommentStyle::Semicolon => t.starts_with(';'),
    }
}

/// The words of a line, comments taken out, upper case.
fn words(line: &str, style: CommentStyle) -> Vec<String> {
    let mut code = String::with_capacity(line.len());
    let mut depth = 0;
    for c in line.trim_end().chars() {
        match (style, c) {
            (CommentStyle::Semicolon, ';') => break,
            (CommentStyle::Parentheses, '(') => depth += 1,
            (CommentStyle::Parentheses, ')') if depth > 0 => depth -= 1,
            _ if depth == 0 => code.push(c),
            _ => {}
        }
    }
    code.split_whitespace().map(|w| w.to_uppercase()).collect()
}

/// A G word's number (`G01` is 1, `G05.1` is 5.1), if the word is one.
fn g_number(w: &str) -> Option<f64> {
    w.strip_prefix('G')?.parse().ok()
}

/// The motion word of a move block: 0 a rapid, 1 a line, 2 and 3 arcs.
fn motion_of(words: &[String]) -> Option<u8> {
    words.iter().find_map(|w| match g_number(w) {
        Some(0.0) => Some(0),
        Some(1.0) => Some(1),
        Some(2.0) => Some(2),
        Some(3.0) => Some(3),
        _ => None,
    })
}

/// The modal words in force, each group's last, with the order they were
/// last written in (replayed in that order, the state is the same on a
/// control that groups them otherwise: Sinumerik's G94 and G96 are one
/// group).
#[derive(Default)]
struct Modal {
    /// (group, the words that restate it, when last written).
    groups: Vec<(&'static str, String, usize)>,
    clock: usize,
}

impl Modal {
    /// Takes the modal words of a block.
    fn take(&mut self, words: &[String], line: &str) {
        let letter = |l: char| -> Option<&String> { words.iter().find(|w| w.starts_with(l)) };
        for w in words {
            let Some(g) = g_number(w) else {
                continue;
            };
            let group = match g {
                17.0 | 18.0 | 19.0 => "plane",
                20.0 | 21.0 | 70.0 | 71.0 => "units",
                90.0 | 91.0 => "distance",
                93.0 | 94.0 | 95.0 | 98.0 | 99.0 => "feed mode",
                96.0 | 97.0 => "spindle speed",
                61.0 | 64.0 => "path",
                5.1 => "look-ahead",
                _ => continue,
            };
            let restated = match group {
                // The speed with its mode, and LinuxCNC's cap D with G96.
                "spindle speed" => std::iter::once(w)
                    .chain(letter('D').filter(|_| g == 96.0))
                    .chain(letter('S'))
                    .cloned()
                    .collect::<Vec<_>>()
                    .join(" "),
                // The blending tolerance P with G64; Q with G05.1.
                "path" => std::iter::once(w)
                    .chain(letter('P').filter(|_| g == 64.0))
                    .cloned()
                    .collect::<Vec<_>>()
                    .join(" "),
                "look-ahead" => std::iter::once(w)
                    .chain(letter('Q'))
                    .cloned()
                    .collect::<Vec<_>>()
                    .join(" "),
                _ => w.clone(),
            };
            self.set(group, restated);
        }
        if let Some(f) = letter('F') {
            self.set("feed", f.clone());
        } else if words.iter().any(|w| w.starts_with('S'))
            && !words
                .iter()
                .any(|w| g_number(w).is_some_and(|g| g == 96.0 || g == 97.0))
        {
            // A speed without its mode word keeps the mode.
            let s = letter('S').cloned().unwrap_or_default();
            if let Some(e) = self.groups.iter_mut().find(|e| e.0 == "spindle speed") {
                let mode = e.1.split_whitespace().next().unwrap_or("").to_string();
                e.1 = format!("{mode} {s}");
            }
        }
        // Sinumerik's blending cycle, a call of its own.
        if line.trim_start().to_uppercase().starts_with("CYCLE832(") {
            self.set("blending cycle", line.trim().to_string());
        }
    }

    fn set(&mut self, group: &'static str, words: String) {
        self.clock += 1;
        match self.groups.iter_mut().find(|e| e.0 == group) {
            Some(e) => *e = (group, words, self.clock),
            None => self.groups.push((group, words, self.clock)),
        }
    }

    /// The blocks restating the state, one group a block, in the order
    /// they were last written. Under inverse time (G93) the feed is every
    /// move's own and is not restated.
    fn restate(&self, style: CommentStyle) -> String {
        let inverse = self
            .groups
            .iter()
            .any(|e| e.0 == "feed mode" && g_number(&e.1).is_some_and(|g| g == 93.0));
        let mut groups: Vec<_> = self
            .groups
            .iter()
            .filter(|e| !(inverse && e.0 == "feed"))
            .collect();
        if groups.is_empty() {
            return String::new();
        }
        groups.sort_by_key(|e| e.2);
        let mut out = comment(style, "the modal state at this join, restated");
        for e in groups {
            out.push_str(&e.1);
            out.push('\n');
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn linuxcnc(continuous: bool) -> Dialect {
        Dialect {
            parts: Some(PartCalls {
                call: "O<{part}> call".into(),
                name: "{job}_{k}".into(),
                extension: "ngc".into(),
                start: vec!["O<{part}> sub".into()],
                end: vec!["O<{part}> endsub".into(), "M2".into()],
                continuous,
            }),
            ..Dialect::linuxcnc()
        }
    }

    const PROGRAM: &str = "(lensc: job j)\n(units mm)\nG18 G21 G90 G8 G40 G49 G80 G94 G54\nG64 P0.0001\nT1 M6 G43\nG97 S1000 M3\nG0 Z1\nG0 X2\nG94 G1 Z0 F100.\nG1 X1 Z-0.1\nG1 X0 Z-0.2\nG0 Z1\nG0 X2\nG1 Z0\nG1 X1 Z-0.1\nG1 X0 Z-0.2\nG0 Z1\nG0 X2\nG1 Z0\nG1 X1 Z-0.1\nG1 X0 Z-0.2\nG0 Z1\nG0 X2\nG1 Z0\nG1 X1 Z-0.1\nG1 X0 Z-0.2\nG0 Z1\nM5\nG53 G0 Z0\nM2\n";

    #[test]
    fn a_program_that_fits_is_not_split() {
        assert_eq!(split(PROGRAM, &linuxcnc(false), "j", 1 << 20), Ok(None));
    }

    /// Joined after retracts only: each part is within the limit, starts
    /// after a rapid, restates plane, units, distance, feed mode, spindle
    /// speed, blending and feed, and the parts' bodies are the program's.
    #[test]
    fn parts_join_after_retracts_and_restate_the_modal_words() {
        let s = split(PROGRAM, &linuxcnc(false), "j", 250)
            .expect("splits")
            .expect("too large whole");
        assert!(s.parts.len() >= 2, "{s:?}");
        for (name, t) in &s.parts {
            assert!(t.len() <= 250, "{name}: {} bytes", t.len());
        }
        let second = &s.parts[1].1;
        assert!(second.starts_with("O<j_2> sub\n"), "{second}");
        for w in [
            "G18\n",
            "G21\n",
            "G90\n",
            "G97 S1000\n",
            "G64 P0.0001\n",
            "F100.\n",
            "G94\n",
        ] {
            assert!(second.contains(w), "{w:?} not restated in {second}");
        }
        assert!(second.ends_with("O<j_2> endsub\nM2\n"), "{second}");
        assert!(
            s.main.starts_with("(lensc: job j)\n(units mm)\n"),
            "{}",
            s.main
        );
        assert!(s.main.contains("O<j_1> call\nO<j_2> call\n"), "{}", s.main);
        assert!(s.main.ends_with("M2\n"));
        // Every move of the program is in exactly one part, in order.
        let moves = |t: &str| -> Vec<String> {
            t.lines()
                .filter(|l| l.starts_with("G0 ") || l.starts_with("G1 ") || l.contains(" G1 "))
                .map(String::from)
                .collect()
        };
        let all: Vec<String> = s.parts.iter().flat_map(|(_, t)| moves(t)).collect();
        assert_eq!(all, moves(PROGRAM));
        // Each part after the first begins at a move after a rapid.
        for (_, t) in &s.parts[1..] {
            let first = t
                .lines()
                .find(|l| l.starts_with("G0 ") || l.starts_with("G1 "))
                .expect("a move");
            assert!(first.starts_with("G0") || first.starts_with("G1 Z0"), "{t}");
        }
    }

    /// A pass longer than the limit cannot be cut where the control stops
    /// between parts; a dialect whose calls do not stop the path cuts it.
    #[test]
    fn a_long_cut_needs_continuous_joins() {
        let long: String = (0..60)
            .map(|i| format!("G1 X{} Z-0.1\n", 2.0 - i as f64 * 0.01))
            .collect();
        let text = PROGRAM.replacen("G1 X1 Z-0.1\n", &long, 1);
        match split(&text, &linuxcnc(false), "j", 400) {
            Err(SplitError::NoJoin {
                from, to, bytes, ..
            }) => {
                assert!(from < to && bytes > 200, "{from} {to} {bytes}")
            }
            other => panic!("{other:?}"),
        }
        let s = split(&text, &linuxcnc(true), "j", 400)
            .expect("splits")
            .expect("too large whole");
        assert!(s.parts.len() >= 3);
        assert!(s.parts.iter().all(|(_, t)| t.len() <= 400));
    }

    #[test]
    fn a_limit_below_a_part_header_is_refused() {
        assert!(matches!(
            split(PROGRAM, &linuxcnc(true), "j", 60),
            Err(SplitError::HeaderOverLimit { .. })
        ));
    }

    #[test]
    fn a_dialect_without_part_calls_cannot_split() {
        assert_eq!(
            split(PROGRAM, &Dialect::linuxcnc(), "j", 100),
            Err(SplitError::NoPartCalls)
        );
    }
}
