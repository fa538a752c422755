//! Reading a program back as its controller reads it, from the text alone:
//! the words of each line (`lexer`), the modal state block by block and
//! the rules a controller (or a careful machinist) refuses a block for
//! (`modal`), and what the header says (`header`). It is written from the
//! controllers' programming rules — LinuxCNC's RS274NGC interpreter, the
//! Fanuc 0i/30i manuals, Siemens 840D sl, Heidenhain TNC ISO, and the
//! ultra-precision lathes' G-code — and shares no code with the writer
//! (`post/`): it takes the dialect and the machine only as data (limits,
//! travel, the dialect's own block lists and number format).
//!
//! Which controller a dialect is for is read from its data
//! ([`Controller::of`]): a Klartext dialect is a TNC's in Klartext
//! (`klartext`, its own lexer: Klartext has no address-word blocks); a block end with `*` is Heidenhain's; `;` comments
//! are Siemens'; a program number line (`O{number}`) is Fanuc's; `G21` in
//! the setup is LinuxCNC's; anything else is read by the ultra-precision
//! lathes' rules (G71 metric, M19/M18 position mode as the dialect says).
//!
//! Every finding names its line and a byte span in the whole text, with a
//! [`Rule`] (its diagnostic code lives with the compiler's others).

mod bspline;
mod bspline_moves;
#[cfg(test)]
mod bspline_tests;
mod chord;
mod expr;
mod header;
mod klartext;
mod lexer;
mod modal;
mod motion;
mod nurbs;
mod nurbs_moves;
pub mod parts;
mod policy;
mod spline;
pub mod timing;

pub use header::{
    HeaderNames, comment_text, header_control_offset, header_names, header_source,
    header_source_hash,
};
pub use policy::{Class, Policy};

use crate::dialect::Dialect;

/// What the reader needs of the machine, as data.
#[derive(Clone, Debug, PartialEq)]
pub struct MachineLimits {
    /// A lathe (X a radius or diameter about the spindle) or not.
    pub lathe: bool,
    /// Travel of X (radius on a lathe), Y, Z (mm) and C (rad), where stated.
    pub travel: [Option<(f64, f64)>; 4],
    /// Highest programmable feed (mm/min).
    pub max_feed: Option<f64>,
    /// Highest spindle speed (rpm).
    pub max_spindle_rpm: Option<f64>,
    /// A fast tool servo the control programs as an axis of its own
    /// (LinuxCNC's U, V or W): its words are moves of the servo, the tool
    /// tip at Z plus the servo.
    pub servo: Option<ServoAxis>,
}

/// A fast tool servo programmed on its own letter, beside Z.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ServoAxis {
    /// Its letter (upper case: U, V or W).
    pub letter: char,
    /// Its velocity limit (mm/min): no move may drive it faster.
    pub max_velocity: f64,
    /// Its stroke (mm): the positions a program gives it may span no
    /// more, wherever its zero is set.
    pub stroke: f64,
}

/// The family of controller whose rules a dialect is read by.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Controller {
    LinuxCnc,
    Fanuc,
    Siemens,
    HeidenhainIso,
    HeidenhainKlartext,
    UltraPrecision,
}

impl Controller {
    /// The controller a dialect writes for, from its data (see the module
    /// documentation).
    pub fn of(d: &Dialect) -> Controller {
        let setup = d.lathe_setup.iter().chain(&d.mill_setup);
        if d.language == crate::dialect::Language::Klartext {
            Controller::HeidenhainKlartext
        } else if d.block_end.trim_end().ends_with('*') {
            Controller::HeidenhainIso
        } else if d.comment == crate::dialect::CommentStyle::Semicolon {
            Controller::Siemens
        } else if d.start.iter().any(|l| l.trim_start().starts_with('O')) {
            Controller::Fanuc
        } else if setup.flat_map(|l| l.split_whitespace()).any(|w| w == "G21") {
            Controller::LinuxCnc
        } else {
            Controller::UltraPrecision
        }
    }
}

/// A rule a program breaks.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Rule {
    UnclosedComment,
    LineTooLong,
    UnknownWord,
    MalformedNumber,
    TooManyDigits,
    TooManyDecimals,
    DecimalPoint,
    SameModalGroup,
    RepeatedWord,
    NoFeedMode,
    SpindleStopped,
    NoFeedRate,
    NoTool,
    OutsideTravel,
    FeedTooHigh,
    RapidIntoPart,
    ArcRadiusMismatch,
    ZeroRadiusArc,
    FullCircle,
    ArcWords,
    ModalStateUnstated,
    NoMotionMode,
    SpindleSpeedMode,
    NoSpindleSpeed,
    SpindleTooFast,
    NoSpeedCap,
    BlockNumber,
    BlockEnd,
    ProgramEnd,
    NestedComment,
    /// Klartext: a block number out of sequence.
    BlockSequence,
    /// Klartext: an arc `C` before any circle centre `CC`.
    NoCircleCentre,
    /// Klartext: the program not opened by `BEGIN PGM` or not closed by
    /// `END PGM` of the same name.
    ProgramFrame,
    /// A parameter word (I J K R P Q L D H) no code of its block uses
    /// (LinuxCNC; Fanuc, Sinumerik and Heidenhain ISO for the words whose
    /// use lensc reads).
    UnusedWord,
    /// An arc from a point the program never stated (lensc's policy).
    PositionUnknown,
    /// A block after the program's end (lensc's policy).
    BlockAfterEnd,
    /// A spline block the controller refuses: its rank, knots, weights,
    /// a block without its knot, a curve cut short or not starting where
    /// the tool is (Fanuc G06.2, `nurbs`).
    SplineRefused,
    /// M99 in a main program (LinuxCNC): the program starts again from
    /// its first block, for ever (lensc's policy).
    MainProgramLoop,
    /// A LinuxCNC NURBS block (G5.2) left without its G5.3: the control
    /// never cuts the curve (lensc's policy).
    NurbsNotCut,
    /// A weight not above zero in the first block of a LinuxCNC NURBS
    /// block, an absent P there read as −1 (lensc's policy).
    NurbsWeight,
}

/// One thing wrong with a program: where (line from 1, byte span in the
/// whole text), what, and how to mend it where that is known.
#[derive(Clone, Debug, PartialEq)]
pub struct Finding {
    pub rule: Rule,
    pub line: usize,
    pub span: (usize, usize),
    pub message: String,
    pub hint: Option<String>,
}

/// A move as the controller makes it from the text, in machine
/// coordinates: absolute, in mm (an inch program's too), X the radius on a
/// lathe (a diameter program's too), C in degrees; an axis is `None`
/// until the program first states it. On a machine whose fast tool servo
/// is an axis of its own (`MachineLimits::servo`), Z is the tool tip's:
/// the slide's Z plus the servo (taken at its zero until the program
/// states it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Executed {
    pub from: [Option<f64>; 4],
    pub to: [Option<f64>; 4],
    pub path: Path,
}

/// The path of an [`Executed`] move.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Path {
    Rapid,
    Line,
    /// An arc in `plane` about `centre` (its two coordinates in the
    /// plane's order: XY (X, Y), ZX (Z, X), YZ (Y, Z)), turning `turn`
    /// rad (> 0) clockwise (`cw`) or counter-clockwise as seen in that
    /// order. Where its start and end radii differ (within the
    /// controller's limit) the controller blends them: see
    /// `verify::simulate`.
    Arc {
        plane: crate::moves::Plane,
        centre: (f64, f64),
        cw: bool,
        turn: f64,
    },
}

/// `moves` (read from a program whose control point lies `offset` mm
/// from the tool's centre, `header_control_offset`) as the tool centre's
/// moves: the offset taken off every position and arc centre, so a
/// program written for the tip simulates as the one written for the
/// centre.
pub fn to_tool_centre(moves: &mut [Executed], offset: [f64; 3]) {
    if offset == [0.0; 3] {
        return;
    }
    for m in moves {
        for p in [&mut m.from, &mut m.to] {
            for (v, o) in p.iter_mut().zip(offset) {
                if let Some(v) = v {
                    *v -= o;
                }
            }
        }
        if let Path::Arc { plane, centre, .. } = &mut m.path {
            let (a, b) = plane.axes();
            centre.0 -= offset[a];
            centre.1 -= offset[b];
        }
    }
}

/// Reads `text` (a whole program) in `dialect` on `machine`: every rule
/// broken, the first line breaking each, in order of their lines.
pub fn read(text: &str, dialect: &Dialect, machine: &MachineLimits) -> Vec<Finding> {
    let mut r = Reader::new(dialect, machine);
    r.lines(text, 0);
    r.finish()
}

/// Reads `text` as [`read`] does, and hands over every move the
/// controller would make, in order (a block with no motion mode makes
/// none, nor an arc with no plane or centre the reader can take).
pub fn read_moves(
    text: &str,
    dialect: &Dialect,
    machine: &MachineLimits,
) -> (Vec<Finding>, Vec<Executed>) {
    read_moves_by(text, dialect, machine, true)
}

/// [`read_moves`] with the common block read in one pass (`fast`, as
/// every other reading does) or whole, line by line: the same findings
/// and moves either way, which the integration tests check on every
/// program lensc writes.
#[doc(hidden)]
pub fn read_moves_by(
    text: &str,
    dialect: &Dialect,
    machine: &MachineLimits,
    fast: bool,
) -> (Vec<Finding>, Vec<Executed>) {
    let mut r = Reader::new(dialect, machine);
    r.set_fast_path(fast);
    r.state.moves = Some(Vec::new());
    r.lines(text, 0);
    let moves = r.state.moves.take().unwrap_or_default();
    (r.finish(), moves)
}

/// Reads a program from `input` line by line (a program of millions of
/// lines is never held whole); bytes that are not UTF-8 are read as `�`,
/// which no controller reads either.
pub fn read_from(
    mut input: impl std::io::BufRead,
    dialect: &Dialect,
    machine: &MachineLimits,
) -> std::io::Result<Vec<Finding>> {
    let mut r = Reader::new(dialect, machine);
    // The text read but not yet handed over: the start of a line whose
    // end has not been read.
    let mut pending: Vec<u8> = Vec::new();
    let mut offset = 0;
    loop {
        let chunk = input.fill_buf()?;
        if chunk.is_empty() {
            break;
        }
        // The last line break is looked for in the new bytes only: a line
        // of megabytes arriving in chunks is scanned once, not once per
        // chunk (which made a 4 MB line take 12 s to read).
        let before = pending.len();
        let last_break = chunk.iter().rposition(|&b| b == b'\n');
        pending.extend_from_slice(chunk);
        let n = chunk.len();
        input.consume(n);
        if let Some(last) = last_break.map(|i| before + i) {
            offset = r.bytes(&pending[..=last], offset);
            pending.drain(..=last);
        }
    }
    r.bytes(&pending, offset);
    Ok(r.finish())
}

/// A program read line by line (the largest run to millions of lines and
/// are read from their spool file as they are).
pub struct Reader {
    state: modal::State,
    findings: Vec<Finding>,
    /// Lines breaking each rule after its first.
    repeats: std::collections::BTreeMap<Rule, usize>,
    line_no: usize,
    last_span: (usize, usize),
    /// Rapids down before the first cut: lowest point along the axis out
    /// of the material, line, span in the whole text.
    pre_cut: Vec<(f64, usize, (usize, usize))>,
}

std::thread_local! {
    /// Programs this thread has begun to read (`reads_on_this_thread`).
    static READS: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

/// How many programs this thread has begun to read: a build reads its
/// program's text once, for the simulation and the read-back both, and
/// the tests hold it to that.
#[doc(hidden)]
pub fn reads_on_this_thread() -> usize {
    READS.with(|r| r.get())
}

impl Reader {
    pub fn new(dialect: &Dialect, machine: &MachineLimits) -> Reader {
        READS.with(|r| r.set(r.get() + 1));
        Reader {
            state: modal::State::new(dialect, machine),
            findings: Vec::new(),
            repeats: Default::default(),
            line_no: 0,
            last_span: (0, 0),
            pre_cut: Vec::new(),
        }
    }

    /// Whether the common block (`G1 X… Z… C… F…`) is read in one pass
    /// (on by default): off, every line goes the whole way through the
    /// lexer and the modal state. The findings are the same either way;
    /// the switch is for the benchmark and the tests that compare them.
    pub fn set_fast_path(&mut self, on: bool) {
        self.state.fast_on = on;
    }

    /// Keeps the moves the controller makes from here on, to be taken by
    /// [`Reader::take_moves`] as the program is read (a program of
    /// millions of lines is never held whole, nor its moves).
    pub fn keep_moves(&mut self) {
        self.state.moves.get_or_insert_with(Vec::new);
    }

    /// The moves made since the last call (none unless `keep_moves`).
    pub fn take_moves(&mut self) -> Vec<Executed> {
        self.state
            .moves
            .as_mut()
            .map(std::mem::take)
            .unwrap_or_default()
    }

    /// Reads every line of `text`, which starts at byte `offset` of the
    /// program, as `line` would be given each (the pieces
    /// `split_inclusive('\n')` makes: a last line without its break is
    /// read as it is); returns the offset after the text.
    pub fn lines(&mut self, text: &str, offset: usize) -> usize {
        for (start, line) in pieces(text) {
            self.line(line, offset + start);
        }
        offset + text.len()
    }

    /// Reads every line of `bytes` as `lines` does where they are UTF-8;
    /// where they are not, line by line, each line's bytes that are not
    /// read as `�` (the offsets still count the bytes).
    fn bytes(&mut self, bytes: &[u8], mut offset: usize) -> usize {
        if let Ok(text) = std::str::from_utf8(bytes) {
            return self.lines(text, offset);
        }
        for line in bytes.split_inclusive(|&b| b == b'\n') {
            self.line(&String::from_utf8_lossy(line), offset);
            offset += line.len();
        }
        offset
    }

    /// Reads one line (with or without its line break) that starts at
    /// byte `offset` of the program.
    pub fn line(&mut self, line: &str, offset: usize) {
        self.line_no += 1;
        // `trim_end_matches(['\n', '\r'])`, byte by byte (both ASCII).
        let mut end = line.len();
        while end > 0 && matches!(line.as_bytes()[end - 1], b'\n' | b'\r') {
            end -= 1;
        }
        let text = &line[..end];
        self.last_span = (offset, offset + text.len());
        let mut out = Vec::new();
        self.state.line(text, &mut out);
        // A finding's span lies in its line, on character boundaries, its
        // start not after its end (a rule's span that ran backwards, or into
        // a `�` that stands for a byte that is not UTF-8, cannot reach a
        // renderer).
        let fit = |p: usize| {
            let mut p = p.min(text.len());
            while !text.is_char_boundary(p) {
                p -= 1;
            }
            p
        };
        let fit_span = |(s, e): (usize, usize)| {
            let (s, e) = (fit(s), fit(e));
            (s, e.max(s))
        };
        let out = out
            .into_iter()
            .map(|(rule, span, message, hint)| (rule, fit_span(span), message, hint))
            .collect();
        if let Some((low, span)) = self.state.pre_cut_rapid.take() {
            let (s, e) = fit_span(span);
            self.pre_cut
                .push((low, self.line_no, (offset + s, offset + e)));
        }
        self.found(out, offset);
    }

    /// Keeps the first finding of each rule (counting the others), on the
    /// line being read, which starts at byte `offset`.
    fn found(&mut self, out: Vec<lexer::Found>, offset: usize) {
        for (rule, (s, e), message, hint) in out {
            if self.findings.iter().any(|f| f.rule == rule) {
                *self.repeats.entry(rule).or_default() += 1;
                continue;
            }
            self.findings.push(Finding {
                rule,
                line: self.line_no,
                span: (offset + s, offset + e),
                message,
                hint,
            });
        }
    }

    /// Every finding, once the whole program is read.
    pub fn finish(mut self) -> Vec<Finding> {
        // A rapid down before the first cut, below the highest point the
        // cuts then reach: a plunge into the material (conservative, as
        // every rapid rule: the reader knows no stock).
        if let Some(top) = self.state.top
            && let Some(&(low, line, span)) =
                self.pre_cut.iter().find(|(low, ..)| *low < top - 1e-7)
        {
            let axis = ["X", "Y", "Z", "C"][self.state.away];
            let n = self
                .pre_cut
                .iter()
                .filter(|(l, ..)| *l < top - 1e-7)
                .count();
            let at = self.line_no;
            self.line_no = line;
            self.found(
                vec![(
                    Rule::RapidIntoPart,
                    (0, 0),
                    format!(
                        "a rapid down to {axis}{} before the first cut, below the highest point the cuts reach ({axis}{}): it would plunge the tool into the part",
                        motion_num(low),
                        motion_num(top)
                    ),
                    Some(format!("rapid to above {axis}{} and feed down from there", motion_num(top))),
                )],
                0,
            );
            if let Some(f) = self
                .findings
                .iter_mut()
                .rfind(|f| f.rule == Rule::RapidIntoPart && f.line == line)
            {
                f.span = span;
            }
            if n > 1 {
                *self.repeats.entry(Rule::RapidIntoPart).or_default() += n - 1;
            }
            self.line_no = at;
        }
        let mut out = Vec::new();
        self.state.finish(&mut out);
        for (rule, _, message, hint) in out {
            self.findings.push(Finding {
                rule,
                line: self.line_no.max(1),
                span: self.last_span,
                message,
                hint,
            });
        }
        for f in &mut self.findings {
            if let Some(n) = self.repeats.get(&f.rule) {
                let more = format!(
                    "{n} more line{} break{} this rule",
                    if *n == 1 { "" } else { "s" },
                    if *n == 1 { "s" } else { "" }
                );
                f.hint = Some(match f.hint.take() {
                    Some(h) => format!("{h}; {more}"),
                    None => more,
                });
            }
        }
        self.findings.sort_by_key(|f| f.line);
        self.findings
    }
}

/// The lines of `text` with their line breaks, and where each starts: the
/// pieces of `split_inclusive('\n')`.
fn pieces(text: &str) -> impl Iterator<Item = (usize, &str)> {
    let mut start = 0;
    std::iter::from_fn(move || {
        if start == text.len() {
            return None;
        }
        let from = start;
        start = line_end(&text.as_bytes()[from..]).map_or(text.len(), |k| from + k + 1);
        // A line break is ASCII: `start` is a character boundary.
        Some((from, &text[from..start]))
    })
}

/// Where the first line break (`\n`) in `bytes` is, looked for eight
/// bytes at a time: a byte equal to the break is a zero byte of the word
/// XOR eight breaks, and the lowest zero byte of a word is the lowest
/// byte whose `(w - 0x01…01) & !w & 0x80…80` bit is set (a borrow can
/// set bits only above a zero byte). On program lines (about 40 bytes)
/// this is faster than the `memchr` crate's vector search, whose set-up
/// a short line does not repay: the reader bench's fast path took 63–65
/// ns a line with this and 70–73 with `memchr::memchr` (2026-11-27).
fn line_end(bytes: &[u8]) -> Option<usize> {
    const BREAKS: u64 = u64::from_ne_bytes([b'\n'; 8]);
    const ONES: u64 = u64::from_ne_bytes([0x01; 8]);
    const HIGHS: u64 = u64::from_ne_bytes([0x80; 8]);
    let mut i = 0;
    while let Some(chunk) = bytes.get(i..i + 8) {
        let w = u64::from_le_bytes(chunk.try_into().expect("eight bytes")) ^ BREAKS;
        let zero = w.wrapping_sub(ONES) & !w & HIGHS;
        if zero != 0 {
            return Some(i + (zero.trailing_zeros() / 8) as usize);
        }
        i += 8;
    }
    bytes[i..].iter().position(|&b| b == b'\n').map(|k| i + k)
}

/// A figure for a message: up to 7 decimals, no trailing zeros.
fn motion_num(v: f64) -> String {
    let s = format!("{v:.7}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.to_string() }
}

#[cfg(test)]
mod tests;
