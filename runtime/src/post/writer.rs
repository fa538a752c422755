//! The program writer: a move stream to the text of a program, word by
//! word, with every number through the one fixed-point formatter.

use super::ProgramError;
use super::format::{
    Decimals, PRINTED_ROOM, decimals_for, fixed_units, pow10, push_fixed, push_units_to,
};
use super::header::{num, write_comment};
use crate::dialect::{CommentStyle, Dialect, Language, WordFormat};
use crate::moves::{ControlOffset, Coolant, Plane, Position, Rotation, Start};
use std::f64::consts::PI;

/// Which safe-start lines a program uses, and the arc plane they select.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Setup {
    /// `lathe_setup`, G18 (Z, X): X is the radius or the diameter.
    Lathe,
    /// `mill_setup`, G17 (X, Y).
    Mill,
}

impl Setup {
    /// The kind of program, as the dialect's `<name>_setup` key has it.
    fn name(self) -> &'static str {
        match self {
            Setup::Lathe => "lathe",
            Setup::Mill => "mill",
        }
    }
}

/// The dialect's own words, checked once: every number the writer prints
/// itself is well formed by construction (`number`), and every line taken
/// from the dialect is checked as it is written, so no text leaves the
/// writer unchecked.
fn check_dialect_words(dialect: &Dialect) -> Result<(), ProgramError> {
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
    Ok(())
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
    /// The axes with a letter, bit i for axis i (`letters`).
    lettered_axes: u8,
    /// Decimals of each axis: the resolution's, C's own for C.
    axis_decimals: [u32; 4],
    /// Factor from the move stream's value to the printed one per axis:
    /// X's scale (2 in diameter mode), 1, 1, degrees per radian for C
    /// (`f64::to_degrees` is this same product).
    axis_scale: [f64; 4],
    /// Each axis's decimals, ready to round and print with.
    axis_formats: [Decimals; 4],
    /// What goes before each axis's number: a space and its letter.
    axis_heads: [WordHead; 4],
    /// Per axis, the unit count (of its last decimal) from which its
    /// word has more digits before the point than its format allows
    /// (`u64::MAX`: no limit).
    axis_unit_limits: [u64; 4],
    /// The motion words: rapid, linear, clockwise and counter-clockwise arc.
    motion_words: [Snippet; 4],
    /// The dialect's block end and the newline.
    line_end: Snippet,
    /// The dialect's digit limit (none: `usize::MAX`).
    max_digits: usize,
    /// The dialect's line-length limit (none: `usize::MAX`).
    max_line_length: usize,
    /// The last value printed per axis, in units of its last decimal
    /// (`NOT_PRINTED`: none yet).
    last: [i64; 4],
    /// Where the axes are (mm, rad; the stream's values).
    at: [f64; 4],
    plane: Plane,
    /// The setup's plane: G18 for a lathe, G17 for a mill.
    plane_at_start: Plane,
    mode: Option<FeedMode>,
    /// The last feed printed, in units of its last decimal.
    last_feed: Option<i64>,
    /// The next block number.
    block: u64,
    c_axis_on: bool,
    job: String,
    /// The tool call and coolant, once written (`call_tool`).
    start: Option<Start>,
    /// What the spindle is doing.
    spindle: Spindle,
    /// The tool's control point from its centre, added to every position
    /// (`Start::control`); none: the program is the centre's.
    control: Option<ControlOffset>,
    /// Klartext: the path-tolerance blocks (cycle 32), written after the
    /// blank by `call_tool`.
    tolerance_lines: Vec<String>,
    /// Klartext: the tool-call blocks and coolant word not yet written,
    /// waiting for the spindle's speed (`TOOL CALL 3 Z S12000`).
    pending_tool_call: Option<(Vec<String>, Option<String>)>,
    /// The length-offset words (`G43 H3 `) still to be written with the
    /// first move that states Z (`Dialect::length_offset`).
    pending_length_offset: Option<String>,
    /// Constant surface speed is on and selects feed per revolution
    /// itself (`Dialect::surface_speed_per_revolution`).
    css_per_revolution: bool,
    /// `common_blocks` as it was before a pending length offset turned it
    /// off, restored once the offset is written.
    common_blocks_after_offset: bool,
    /// The most digits before the point per word letter A…Z, as a power
    /// of ten (`u64::MAX`: no limit).
    integer_limit: [u64; 26],
    /// Decimals of feeds per minute and per revolution.
    feed_decimals: u32,
    /// The same, ready to round and print with.
    feed_format: Decimals,
    /// The unit counts (of feeds per minute or per revolution, and of
    /// inverse time) from which F has more digits before the point than
    /// its format allows (`u64::MAX`: no limit).
    feed_unit_limits: [u64; 2],
    /// Klartext: the circle centre `CC` last written, in units of the
    /// axes' last decimal.
    circle_centre: Option<(Plane, i64, i64)>,
    pub moves: usize,
    /// How far the text's spare capacity is zeroed: see `block_room`.
    zeroed: Zeroed,
    /// Whether rapids and lines may go the one-pass way
    /// (`common_block`): the dialect allows it.
    common_blocks: bool,
    /// Whether the processor has what `write_all_avx2` is compiled for
    /// (`has_avx2`).
    #[cfg(target_arch = "x86_64")]
    avx2: bool,
    /// How many blocks went the one-pass way (for the tests).
    #[cfg(test)]
    common_written: usize,
}

/// The spindle's state as the program has set it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Spindle {
    Stopped,
    Turning,
    Held,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum FeedMode {
    PerMinute,
    PerRevolution,
    InverseTime,
}

/// `ProgramWriter::last` of an axis not printed yet: no unit count is
/// (every printed one is below 10^18 in magnitude), so the first value
/// is always written.
const NOT_PRINTED: i64 = i64::MIN;

/// Decimals of feeds per minute and per revolution, and of inverse time.
const FEED_DECIMALS: u32 = 6;
const INVERSE_TIME_DECIMALS: u32 = 3;
const INVERSE_TIME_FORMAT: Decimals = Decimals::new(INVERSE_TIME_DECIMALS);

/// The shortest move time (s), at least `t`, whose inverse-time F as
/// printed (1/min, rounded to its decimals) is not above 60 / `t`: a move
/// slowed to a limit must not read faster than the limit once printed.
/// Times so long that F would print as 0 are returned as they are. A
/// quotient a rounding error below a whole number of units (60 / t for t
/// = 60 / F itself) is taken as that number: F is then above 60 / t by at
/// most 1e-12 of it, far inside any controller's (and the reader's) limit.
pub fn inverse_time_not_faster(t: f64) -> f64 {
    let scale = 10f64.powi(INVERSE_TIME_DECIMALS as i32);
    let units = (60.0 / t * scale * (1.0 + 1e-12)).floor();
    if units >= 1.0 {
        60.0 / (units / scale)
    } else {
        t
    }
}

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
        let decimals = check_dialect(dialect, setup, resolution)?;
        let setup_lines = match setup {
            Setup::Lathe => &dialect.lathe_setup,
            Setup::Mill => &dialect.mill_setup,
        };
        let mut w = ProgramWriter::blank(dialect, setup, job, axes, decimals);
        check_dialect_words(dialect)?;
        for line in &dialect.start {
            let l = w.fill(line, path_tolerance);
            w.line_as_written(&l)?;
        }
        for line in header {
            w.comment(line);
        }
        for line in setup_lines {
            let l = w.fill(line, path_tolerance);
            w.block_line(&l)?;
        }
        for line in &dialect.path_tolerance {
            let l = w.fill(line, path_tolerance);
            if dialect.language == Language::Klartext {
                // After the blank, which follows `BEGIN PGM` (`call_tool`).
                w.tolerance_lines.push(l);
            } else {
                w.block_line(&l)?;
            }
        }
        Ok(w)
    }

    /// A lathe's fast tool servo programmed as an axis of its own, on
    /// `letter` (U, V or W): a lathe has no Y, so the move stream carries
    /// the servo in Y's place (`Position::xzc_servo`) and its words are
    /// printed with this letter, to the resolution, as X and Z are.
    pub fn servo_in_y(&mut self, letter: char) {
        let limit = integer_limits(&self.dialect)[letter_index(letter)];
        self.letters[1] = Some(letter);
        self.lettered_axes |= 1 << 1;
        self.axis_heads[1] = WordHead::new(letter);
        self.axis_unit_limits[1] = limit.saturating_mul(pow10(self.axis_decimals[1]));
    }

    /// A writer with nothing written yet, every word of the dialect
    /// prepared and no axis position known.
    fn blank(dialect: &Dialect, setup: Setup, job: &str, axes: &str, decimals: u32) -> Self {
        let has = |c: char| axes.contains(c).then_some(c);
        let axis_decimals = [decimals, decimals, decimals, dialect.c_decimals];
        let limits = integer_limits(dialect);
        // The F word's own format, else the dialect's most decimals of any
        // word (as the reader holds F: a Fanuc lathe's per-revolution feed
        // of 0.018182 mm was written with six decimals and refused), at
        // most six.
        let feed_decimals = dialect
            .format_of('F')
            .and_then(|f| f.decimals)
            .or(dialect.max_decimals)
            .map_or(FEED_DECIMALS, |d| d.min(FEED_DECIMALS));
        let x_scale = if setup == Setup::Lathe && dialect.lathe_x_diameter {
            2.0
        } else {
            1.0
        };
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
            lettered_axes: (0..4).fold(0, |m, i| m | (letters[i].is_some() as u8) << i),
            axis_decimals,
            axis_scale: [x_scale, 1.0, 1.0, 180.0 / PI],
            axis_formats: axis_decimals.map(Decimals::new),
            axis_heads: letters.map(|l| WordHead::new(l.unwrap_or(' '))),
            axis_unit_limits: std::array::from_fn(|i| {
                let limit = letters[i].map_or(u64::MAX, |l| limits[letter_index(l)]);
                limit.saturating_mul(pow10(axis_decimals[i]))
            }),
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
            last: [NOT_PRINTED; 4],
            at: [f64::NAN; 4],
            plane: match setup {
                Setup::Lathe => Plane::Zx,
                Setup::Mill => Plane::Xy,
            },
            plane_at_start: match setup {
                Setup::Lathe => Plane::Zx,
                Setup::Mill => Plane::Xy,
            },
            // The first feed states its mode, whatever the setup says.
            mode: None,
            last_feed: None,
            // Klartext numbers from 0 (`0 BEGIN PGM`).
            block: match dialect.language {
                Language::Klartext => 0,
                Language::GCode => dialect.line_numbers.unwrap_or(0),
            },
            c_axis_on: false,
            job: job.to_string(),
            start: None,
            spindle: Spindle::Stopped,
            control: None,
            pending_tool_call: None,
            tolerance_lines: Vec::new(),
            pending_length_offset: None,
            css_per_revolution: false,
            common_blocks_after_offset: false,
            integer_limit: limits,
            feed_decimals,
            feed_format: Decimals::new(feed_decimals),
            feed_unit_limits: [feed_decimals, INVERSE_TIME_DECIMALS]
                .map(|d| limits[letter_index('F')].saturating_mul(pow10(d))),
            circle_centre: None,
            moves: 0,
            zeroed: Zeroed::default(),
            common_blocks: false,
            #[cfg(target_arch = "x86_64")]
            avx2: has_avx2(),
            #[cfg(test)]
            common_written: 0,
        };
        w.common_blocks = w.common_blocks_apply();
        w
    }

    /// Calls the tool and sets the coolant: the dialect's tool-call blocks
    /// for this kind of program, then the coolant word. Every program
    /// calls it once, after `new` and before its first move (a move
    /// before it is refused).
    pub fn call_tool(&mut self, start: &Start) -> Result<(), ProgramError> {
        self.control = (!start.control.is_zero()).then_some(start.control);
        let lines = tool_call_lines(&self.dialect, self.setup_kind(), start)?;
        let coolant = coolant_word(&self.dialect, start.coolant)?;
        if self.dialect.language == Language::Klartext {
            // The blank first; the tool is called with its speed, in one
            // `TOOL CALL` block, once the spindle's first move says it.
            if let Some(blank) = start.blank {
                self.blank_form(&blank)?;
            }
            for line in std::mem::take(&mut self.tolerance_lines) {
                self.block_line(&line)?;
            }
            self.pending_tool_call = Some((lines, coolant));
        } else {
            if let Some(blank) = start.blank {
                self.blank_blocks(&blank)?;
            }
            for line in lines {
                self.block_line(&line)?;
            }
            if let Some(word) = coolant {
                self.block_line(&word)?;
            }
        }
        if !self.dialect.length_offset.is_empty() {
            let words = self
                .dialect
                .length_offset
                .replace("{offset}", &start.offset.to_string())
                .replace("{tool}", &start.tool.to_string());
            check_numbers(&words, self.dialect.comment)?;
            check_word_formats(&words, &self.dialect)?;
            self.pending_length_offset = Some(words);
            // Every block takes the general path until the offset is
            // written (the common path's test stays as it was: its cost
            // is per line).
            self.common_blocks_after_offset = self.common_blocks;
            self.common_blocks = false;
        }
        self.start = Some(*start);
        Ok(())
    }

    /// The dialect's `blank_form` blocks with the blank's corners filled
    /// in, to the machine's decimals (Heidenhain ISO's G30 and G31).
    fn blank_blocks(&mut self, blank: &crate::moves::Blank) -> Result<(), ProgramError> {
        for line in self.dialect.blank_form.clone() {
            let mut l = line;
            for (i, axis) in ['x', 'y', 'z'].into_iter().enumerate() {
                for (corner, value) in [('0', blank.min[i]), ('1', blank.max[i])] {
                    let mut n = String::new();
                    if !push_fixed(&mut n, value, self.decimals) {
                        return Err(ProgramError::NotPrintable {
                            word: axis.to_ascii_uppercase(),
                            value,
                        });
                    }
                    l = l.replace(&format!("{{{axis}{corner}}}"), &n);
                }
            }
            self.block_line(&l)?;
        }
        Ok(())
    }

    /// Klartext: the tool call held back by `call_tool`, with the
    /// spindle speed `s` in its `TOOL CALL` block where one is given,
    /// then the coolant word.
    fn write_tool_call(&mut self, s: Option<&str>) -> Result<(), ProgramError> {
        let Some((lines, coolant)) = self.pending_tool_call.take() else {
            return Ok(());
        };
        for line in lines {
            match s {
                Some(s) if line.starts_with("TOOL CALL") => {
                    self.block_line(&format!("{line} S{s}"))?
                }
                _ => self.block_line(&line)?,
            }
        }
        if let Some(word) = coolant {
            self.block_line(&word)?;
        }
        Ok(())
    }

    /// Whether the program is a lathe's (its X scale or plane says so).
    fn setup_kind(&self) -> Setup {
        if self.plane_at_start == Plane::Zx {
            Setup::Lathe
        } else {
            Setup::Mill
        }
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
            if self.dialect.language == Language::GCode {
                self.text.push(b'N');
            }
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
        self.next_block_number();
        Ok(())
    }

    /// The next block's number, if the dialect numbers blocks.
    #[inline(always)]
    fn next_block_number(&mut self) {
        if let Some(step) = self.dialect.line_numbers {
            self.block += step;
            if self.dialect.max_line_number.is_some_and(|m| self.block > m) {
                self.block = step;
            }
        }
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

    /// The decimals of the machine's linear axes.
    pub fn decimals(&self) -> u32 {
        self.decimals
    }

    /// The dialect the program is written in.
    pub fn dialect(&self) -> &Dialect {
        &self.dialect
    }

    /// A `start` or `trailer` line: as it is in G-code (`%`), a numbered
    /// block in Klartext (`0 BEGIN PGM NAME MM`, `END PGM NAME MM`).
    fn line_as_written(&mut self, l: &str) -> Result<(), ProgramError> {
        if self.dialect.language == Language::Klartext {
            return self.block_line(l);
        }
        check_numbers(l, self.dialect.comment)?;
        self.text.extend_from_slice(l.as_bytes());
        self.text.push(b'\n');
        Ok(())
    }

    /// Writes one block of the dialect's own words, checked as it is written.
    pub fn block_line(&mut self, words: &str) -> Result<(), ProgramError> {
        check_numbers(words, self.dialect.comment)?;
        check_word_formats(words, &self.dialect)?;
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
        let limit = self.integer_limit[letter_index(letter)];
        if limit != u64::MAX && n.unsigned_abs() / 10u64.pow(d.min(18)) >= limit {
            return Err(self.too_many_integer_digits(letter, v));
        }
        Ok(())
    }

    #[cold]
    fn too_many_integer_digits(&self, letter: char, v: f64) -> ProgramError {
        let f = self.dialect.format_of(letter);
        ProgramError::Unsupported(format!(
            "{letter}{v} ({} writes at most {} digits before the point in {letter})",
            self.dialect.name,
            f.map_or(0, |f| f.integer_digits)
        ))
    }

    #[cold]
    fn too_many_digits(&self, letter: char, v: f64, digits: usize) -> ProgramError {
        ProgramError::Unsupported(format!(
            "{letter}{v} in {digits} digits ({} takes at most {})",
            self.dialect.name, self.max_digits
        ))
    }

    /// Writes one move, straight into the text (no allocation per move:
    /// a move that changes no printed axis is written and then cut off).
    pub fn write(&mut self, m: &crate::moves::Move) -> Result<(), ProgramError> {
        self.write_move(m)
    }

    /// `write`, inlined into the loop of `write_all`.
    #[inline(always)]
    fn write_move(&mut self, m: &crate::moves::Move) -> Result<(), ProgramError> {
        use crate::moves::Move as M;
        // The stream is the tool centre's; the program the control point's.
        let moved;
        let m = match self.control {
            Some(c) => {
                moved = c.apply_to(m);
                &moved
            }
            None => m,
        };
        let common = match *m {
            M::Linear { to, feed } => self.common_block(Word::Linear, to, feed),
            M::Rapid(to) => self.common_block(Word::Rapid, to, None),
            _ => false,
        };
        if common {
            return Ok(());
        }
        if self.start.is_none() {
            return Err(ProgramError::Unsupported(
                "a move before the tool is called (the writer's `call_tool`)".into(),
            ));
        }
        if self.pending_tool_call.is_some() && !matches!(*m, M::SpindleOn(_)) {
            self.write_tool_call(None)?;
        }
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
        let r = match self.dialect.language {
            Language::GCode => self.motion(word, to, feed, arc),
            Language::Klartext => self.klartext_motion(word, to, feed, arc),
        };
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
            M::SpindleOn(speed) => self.spindle_rpm(speed),
            M::SpindleSurfaceSpeed { surface_speed, cap } => {
                self.spindle_surface_speed(surface_speed, cap)
            }
            M::SpindleHeld => {
                self.spindle = Spindle::Held;
                let lines = self.dialect.spindle_orient.clone();
                if lines.is_empty() {
                    return Err(ProgramError::Unsupported(format!(
                        "a spindle held still for a shaping tool ({} has no `spindle_orient`)",
                        self.dialect.name
                    )));
                }
                lines.iter().try_for_each(|l| self.block_line(l))
            }
            M::SpindleOff => {
                self.spindle = Spindle::Stopped;
                let off = self.dialect.spindle_off.clone();
                self.block_line(&off)
            }
        };
        if r.is_err() {
            self.text.truncate(start);
        }
        r
    }

    /// The spindle-on word for the job's direction.
    fn spindle_on_word(&self) -> String {
        match self.start.map(|s| s.rotation) {
            Some(Rotation::CounterClockwise) => self.dialect.spindle_ccw.clone(),
            _ => self.dialect.spindle_on.clone(),
        }
    }

    /// A constant-rpm start in one block: the word cancelling constant
    /// surface speed (`G97`), the speed in the S word's format, the
    /// spindle-on word (`G97 S1000 M3`).
    fn spindle_rpm(&mut self, speed: f64) -> Result<(), ProgramError> {
        let rpm = speed * 60.0 / (2.0 * PI);
        let s = self.s_value(rpm, false)?;
        if self.dialect.language == Language::Klartext {
            // The speed is the tool call's: the first in the tool's own
            // call, `TOOL CALL 3 Z S…`; a later one `TOOL CALL Z S…`, for
            // the tool in the spindle. M3 starts it in its own block.
            self.spindle = Spindle::Turning;
            if self.pending_tool_call.is_some() {
                self.write_tool_call(Some(&s))?;
            } else {
                self.block_line(&format!("TOOL CALL Z S{s}"))?;
            }
            let on = self.spindle_on_word();
            return self.block_line(&on);
        }
        let mut block = String::new();
        if let Some(w) = &self.dialect.constant_rpm {
            block.push_str(w);
            block.push(' ');
        }
        block.push('S');
        block.push_str(&s);
        block.push(' ');
        block.push_str(&self.spindle_on_word());
        self.spindle = Spindle::Turning;
        // Some controllers group G96/G97 with the feed modes (Sinumerik's
        // group 15): the next feed states its mode again.
        self.mode = None;
        self.css_per_revolution = false;
        self.block_line(&block)
    }

    /// Constant surface speed: the dialect's blocks (the cap first where
    /// the controller needs it), each number in the S word's format, then
    /// the spindle-on word.
    fn spindle_surface_speed(&mut self, surface_speed: f64, cap: f64) -> Result<(), ProgramError> {
        let lines = self.dialect.surface_speed.clone();
        if lines.is_empty() {
            return Err(ProgramError::Unsupported(format!(
                "constant surface speed ({} has no `surface_speed` lines)",
                self.dialect.name
            )));
        }
        let speed = self.s_value(surface_speed * 60.0 / 1000.0, false)?;
        let rpm = self.s_value(cap * 60.0 / (2.0 * PI), true)?;
        for line in lines {
            let l = line.replace("{speed}", &speed).replace("{cap}", &rpm);
            self.block_line(&l)?;
        }
        let on = self.spindle_on_word();
        self.spindle = Spindle::Turning;
        // Where G96 selects feed per revolution itself (Sinumerik), no
        // feed-mode word follows it: G95 would switch it off.
        self.css_per_revolution = self.dialect.surface_speed_per_revolution;
        self.mode = self.css_per_revolution.then_some(FeedMode::PerRevolution);
        self.block_line(&on)
    }

    /// A spindle value (rpm or m/min) as the dialect's S word takes it:
    /// rounded to a whole number without a point where S is an integer
    /// word (a cap rounded down, `floor`), else to its decimals (3 by
    /// default) with the point. Refused if it is not finite, prints as
    /// zero or has more digits than the word allows.
    fn s_value(&self, v: f64, floor: bool) -> Result<String, ProgramError> {
        let f = self.dialect.format_of('S');
        let decimals = f.map_or(Some(3), |f| f.decimals);
        // A cap rounds down, past the last bits a unit conversion leaves
        // (3000 rpm as rad/s and back is 2999.9999999999995).
        let v_floor = if floor { (v + 1e-6).floor() } else { v };
        let mut out = String::new();
        let printed = match decimals {
            None => {
                let n = v_floor.round();
                (n.is_finite() && n.abs() < 1e15).then(|| {
                    out.push_str(&format!("{}", n as i64));
                    n != 0.0
                })
            }
            Some(d) => {
                let ok = push_fixed(&mut out, v_floor, d);
                ok.then(|| fixed_units(v_floor, d).is_some_and(|n| n != 0))
            }
        };
        match printed {
            Some(true) => {}
            Some(false) => {
                return Err(ProgramError::Unsupported(format!(
                    "a spindle speed of {v} that prints as S{out}"
                )));
            }
            None => {
                return Err(ProgramError::NotPrintable {
                    word: 'S',
                    value: v,
                });
            }
        }
        if let Some(f) = f {
            let whole = out.split('.').next().unwrap_or("").len() as u32;
            if whole > f.integer_digits {
                return Err(ProgramError::Unsupported(format!(
                    "S{out} ({} writes at most {} digits in S)",
                    self.dialect.name, f.integer_digits
                )));
            }
        }
        Ok(out)
    }

    /// A motion block: its prefix (block number, feed-mode and plane
    /// words) into the text, then its words printed into one room added
    /// at the text's end (`BLOCK_ROOM`) and cut back to their length: the
    /// text's length is touched twice a block, not twice a word. The
    /// values printed are kept word by word and become the last printed
    /// values only when the block is written (a block refused leaves them
    /// as they were).
    #[inline(always)]
    fn motion(
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
        if !matches!(word, Word::Rapid) && self.spindle == Spindle::Stopped && !self.c_axis_on {
            return Err(ProgramError::Unsupported(
                "a feed move with the spindle stopped".into(),
            ));
        }
        let start = self.text.len();
        self.begin_block();
        let [per_unit_limit, inverse_unit_limit] = self.feed_unit_limits;
        let mode = feed.map(|f| match f {
            F::PerTime(v) => (
                FeedMode::PerMinute,
                v * 60.0,
                self.feed_format,
                per_unit_limit,
            ),
            F::PerRevolution(v) => (
                FeedMode::PerRevolution,
                v * 2.0 * PI,
                self.feed_format,
                per_unit_limit,
            ),
            F::InverseTime(t) => (
                FeedMode::InverseTime,
                60.0 / t,
                INVERSE_TIME_FORMAT,
                inverse_unit_limit,
            ),
        });
        let mode_changes = mode.is_some_and(|(m, ..)| self.mode != Some(m));
        if self.css_per_revolution && mode_changes {
            self.text.truncate(start);
            return Err(ProgramError::Unsupported(format!(
                "a feed not per revolution under constant surface speed ({}: G96 selects feed per revolution, and G94 or G93 would switch constant surface speed off)",
                self.dialect.name
            )));
        }
        if !to.z.is_nan()
            && let Some(words) = self.pending_length_offset.take()
        {
            self.text.extend_from_slice(words.as_bytes());
            self.text.push(b' ');
            self.common_blocks = std::mem::take(&mut self.common_blocks_after_offset);
        }
        if let Some((m, ..)) = mode
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
        let motion_word = &self.motion_words[word as usize];
        if motion_word.len > SNIPPET_ROOM {
            self.text.extend_from_slice(&motion_word.long);
        }
        let axes = to.axes();
        // The arc's centre words, worked out (and its radii checked)
        // before the room is taken, printed after the axes' words.
        let centre = arc.map(|(plane, centre)| self.centre_words(plane, to, centre));
        let at = self.text.len();
        let room = block_room(&mut self.text, &mut self.zeroed);
        let mut pos = 0;
        if motion_word.len <= SNIPPET_ROOM {
            room[..SNIPPET_ROOM].copy_from_slice(&motion_word.room);
            pos = motion_word.len;
        }
        let max_digits = self.max_digits;
        let mut printed = [0i64; 4];
        let mut changed = 0u8;
        let mut refusal = None;
        for i in 0..4 {
            let v = axes[i];
            if v.is_nan() {
                continue;
            }
            let value = v * self.axis_scale[i];
            let format = &self.axis_formats[i];
            let (Some(letter), Some(n)) = (self.letters[i], format.units(value)) else {
                refusal = Some(Refusal::NotPrintable(i, v));
                break;
            };
            // Modal: a word whose printed value has not changed is left out.
            if self.last[i] == n {
                continue;
            }
            let unit_limit = self.axis_unit_limits[i];
            let head = &self.axis_heads[i];
            match print_word(
                room, pos, head, letter, value, n, format, max_digits, unit_limit,
            ) {
                Ok(p) => pos = p,
                Err(r) => {
                    refusal = Some(r);
                    break;
                }
            }
            printed[i] = n;
            changed |= 1 << i;
        }
        if refusal.is_none() && changed != 0 {
            if let Some(centre) = centre {
                match centre {
                    Ok(words) => {
                        let format = Decimals::new(self.decimals);
                        for (letter, value, n) in words {
                            let limit = self.integer_limit[letter_index(letter)];
                            let unit_limit = limit.saturating_mul(pow10(self.decimals));
                            let head = WordHead::new(letter);
                            match print_word(
                                room, pos, &head, letter, value, n, &format, max_digits, unit_limit,
                            ) {
                                Ok(p) => pos = p,
                                Err(r) => {
                                    refusal = Some(r);
                                    break;
                                }
                            }
                        }
                    }
                    Err(r) => refusal = Some(r),
                }
            }
            if let Some(mode) = mode
                && refusal.is_none()
            {
                let modal = (&mut self.last_feed, &mut self.mode);
                match feed_word(room, pos, mode, mode_changes, modal, max_digits) {
                    Ok(p) => pos = p,
                    Err(r) => refusal = Some(r),
                }
            }
        }
        // The line's length is where its words end: nothing rescanned.
        let too_long = at - start + pos + self.dialect.block_end.len() > self.max_line_length;
        if refusal.is_none() && changed != 0 && !too_long && self.line_end.len <= SNIPPET_ROOM {
            room[pos..pos + SNIPPET_ROOM].copy_from_slice(&self.line_end.room);
            pos += self.line_end.len;
            self.text.truncate(at + pos);
        } else {
            self.text.truncate(at + pos);
            if let Some(r) = refusal {
                return Err(self.refused(r));
            }
            if changed == 0 {
                self.text.truncate(start);
                return Ok(());
            }
            if too_long {
                return Err(self.line_too_long(start));
            }
            self.text.extend_from_slice(&self.line_end.long);
        }
        self.next_block_number();
        self.moved(&printed, changed, axes);
        Ok(())
    }

    /// A motion block written: the printed values of the axes `changed`
    /// (bit i for axis i) become the modal ones, the tool is at `axes`
    /// (NaN: an axis that did not move).
    #[inline(always)]
    fn moved(&mut self, printed: &[i64], changed: u8, axes: [f64; 4]) {
        for (i, &n) in printed.iter().enumerate() {
            if changed & 1 << i != 0 {
                self.last[i] = n;
            }
        }
        for (at, v) in self.at.iter_mut().zip(axes) {
            if !v.is_nan() {
                *at = v;
            }
        }
        self.moves += 1;
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
    /// ` F…` for a spline's feed `v` (mm/s), in mm/min, on the block that
    /// starts the curve (Fanuc's G06.2, Siemens' BSPLINE); its printed units.
    fn curve_feed_word(&mut self, v: f64) -> Result<i64, ProgramError> {
        let f = v * 60.0;
        let Some(units) = self.feed_format.units(f) else {
            return Err(ProgramError::NotPrintable {
                word: 'F',
                value: f,
            });
        };
        self.text.extend_from_slice(b" F");
        self.number('F', f, units, self.feed_decimals)?;
        Ok(units)
    }

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

    /// An arc's centre words (letter, value, units), once its radii are
    /// checked as the controller checks them.
    #[inline(never)]
    fn centre_words(
        &self,
        plane: Plane,
        to: Position,
        centre: Position,
    ) -> Result<[(char, f64, i64); 2], Refusal> {
        if let Err(e) = self.check_arc_radii(plane, to, centre) {
            return Err(Refusal::Error(Box::new(e)));
        }
        let (a, b) = plane.axes();
        // I J K in that order, whatever the plane's orientation.
        let mut words = [(' ', 0.0, 0); 2];
        for (word, i) in words.iter_mut().zip([a.min(b), a.max(b)]) {
            let c = centre.axes()[i];
            let from = if self.dialect.arc_centre_absolute {
                0.0
            } else {
                self.at[i]
            };
            let letter = ['I', 'J', 'K'][i];
            let (Some(cu), Some(fu)) = (
                fixed_units(c, self.decimals),
                fixed_units(from, self.decimals),
            ) else {
                return Err(Refusal::Unprintable(letter, c));
            };
            *word = (letter, c - from, cu - fu);
        }
        Ok(words)
    }

    /// The error for a word the block's room refused.
    #[cold]
    fn refused(&self, r: Refusal) -> ProgramError {
        match r {
            Refusal::NotPrintable(i, v) => self.not_printable(i, v),
            Refusal::Unprintable(word, value) => ProgramError::NotPrintable { word, value },
            Refusal::TooManyDigits(letter, v, digits) => self.too_many_digits(letter, v, digits),
            Refusal::IntegerDigits(letter, v) => self.too_many_integer_digits(letter, v),
            Refusal::Error(e) => *e,
        }
    }

    /// An arc's start and end radii, from the rounded centre, start and
    /// end, as the controller measures them: refused beyond the
    /// dialect's `arc_radius_tolerance`.
    fn check_arc_radii(
        &self,
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
        Ok(())
    }

    /// Writes one step of a program written with splines.
    pub fn write_step(&mut self, s: &crate::moves::Step) -> Result<(), ProgramError> {
        match s {
            crate::moves::Step::Move(m) => self.write_move(m),
            crate::moves::Step::Spline(sp) => self.write_spline(sp),
        }
    }

    /// Writes a spline in the dialect's form: Fanuc's NURBS interpolation,
    /// `G06.2 P<order> K<knot> X Y Z [F]` with the first control point
    /// (where the axes are), one `K X Y Z` block per further control
    /// point, then one `K` block per end knot (docs/controllers/fanuc.md).
    /// Every control point states X, Y and Z (the control interpolates
    /// only the axes its second block names); knots are printed to the
    /// axes' decimals, weights left out (1). The blocks are written whole
    /// or not at all.
    pub fn write_spline(&mut self, s: &crate::moves::Spline) -> Result<(), ProgramError> {
        use crate::dialect::SplineForm;
        if self.dialect.spline.is_none() || self.dialect.language != Language::GCode {
            return Err(ProgramError::Unsupported(format!(
                "splines ({} has no spline lensc writes)",
                self.dialect.name
            )));
        }
        if self.start.is_none() {
            return Err(ProgramError::Unsupported(
                "a move before the tool is called (the writer's `call_tool`)".into(),
            ));
        }
        if self.pending_tool_call.is_some() {
            self.write_tool_call(None)?;
        }
        if self.spindle == Spindle::Stopped && !self.c_axis_on {
            return Err(ProgramError::Unsupported(
                "a feed move with the spindle stopped".into(),
            ));
        }
        if self.pending_length_offset.is_some() {
            return Err(ProgramError::Unsupported(
                "a spline before the first move that takes the length offset".into(),
            ));
        }
        if self.dialect.spline == Some(SplineForm::Bspline) {
            return self.write_bspline(s);
        }
        let n = s.points.len();
        if s.knots.len() != n + s.order || n < s.order || !(2..=4).contains(&s.order) {
            return Err(ProgramError::Unsupported(format!(
                "a spline of order {} with {n} control points and {} knots",
                s.order,
                s.knots.len()
            )));
        }
        if self.letters[..3].iter().any(|l| l.is_none()) {
            return Err(ProgramError::Unsupported(
                "a spline on a machine without X, Y and Z".into(),
            ));
        }
        let o = self.control.map_or([0.0; 3], |c| [c.x, c.y, c.z]);
        let start = self.text.len();
        let r = self.spline_blocks(s, o);
        if r.is_err() {
            self.text.truncate(start);
        }
        r
    }

    fn spline_blocks(&mut self, s: &crate::moves::Spline, o: [f64; 3]) -> Result<(), ProgramError> {
        use crate::moves::Feed as F;
        let d = self.decimals;
        let knot_format = Decimals::new(d);
        let mut printed = [0i64; 3];
        let mut new_mode = None;
        let mut new_feed = None;
        for (i, p) in s.points.iter().enumerate() {
            let start = self.text.len();
            self.begin_block();
            if i == 0 {
                if matches!(s.feed, Some(F::PerTime(_))) && self.mode != Some(FeedMode::PerMinute) {
                    let w = self.feed_mode_word(FeedMode::PerMinute)?.to_string();
                    self.text.extend_from_slice(w.as_bytes());
                    self.text.push(b' ');
                    new_mode = Some(FeedMode::PerMinute);
                } else if s.feed.is_some_and(|f| !matches!(f, F::PerTime(_))) {
                    return Err(ProgramError::Unsupported(
                        "a spline fed other than per minute".into(),
                    ));
                }
                self.text
                    .extend_from_slice(format!("G06.2 P{} ", s.order).as_bytes());
            }
            self.knot_word(s.knots[i], &knot_format)?;
            for (a, letter) in ['X', 'Y', 'Z'].into_iter().enumerate() {
                let value = (p[a] + o[a]) * self.axis_scale[a];
                let Some(units) = self.axis_formats[a].units(value) else {
                    return Err(self.not_printable(a, p[a]));
                };
                self.text.push(b' ');
                self.text.push(letter as u8);
                self.number(letter, value, units, self.axis_decimals[a])?;
                printed[a] = units;
            }
            if i == 0
                && let Some(F::PerTime(v)) = s.feed
            {
                new_feed = Some(self.curve_feed_word(v)?);
            }
            self.end_block(start)?;
        }
        for &k in &s.knots[s.points.len()..] {
            let start = self.text.len();
            self.begin_block();
            self.knot_word(k, &knot_format)?;
            self.end_block(start)?;
        }
        // The axes are at the last control point, as printed.
        if let Some(mode) = new_mode {
            self.mode = Some(mode);
        }
        if new_feed.is_some() {
            self.last_feed = new_feed;
        }
        let last = s.points[s.points.len() - 1];
        self.last[..3].copy_from_slice(&printed);
        self.at[..3].copy_from_slice(&last);
        self.moves += 1;
        Ok(())
    }

    /// Writes a spline as Siemens' B spline (docs/controllers/siemens.md):
    /// the first control point is where the tool is (not written), then
    /// `BSPLINE SD=<degree> PL=<spacing> X Y Z [F]` with the second, and
    /// one `PL=<spacing> X Y Z` block per further control point. The knot
    /// spacing is stated in every block, and must be the same throughout
    /// (the fit's `KnotSpacing::Uniform`): which knot interval a block's
    /// PL sets is not stated in the manual, and with one spacing it does
    /// not matter. Weights are left out (PW=1). Every axis the machine
    /// has among X, Y, Z is stated in every block; the axes it has not
    /// must not move. The blocks are written whole or not at all.
    fn write_bspline(&mut self, s: &crate::moves::Spline) -> Result<(), ProgramError> {
        let n = s.points.len();
        let degree = s.order.wrapping_sub(1);
        if s.knots.len() != n + s.order || n < s.order || !(2..=3).contains(&degree) {
            return Err(ProgramError::Unsupported(format!(
                "a B spline of order {} with {n} control points and {} knots (BSPLINE takes degree SD=2 or 3)",
                s.order,
                s.knots.len()
            )));
        }
        let k = &s.knots;
        let clamped = k[..s.order].iter().all(|v| *v == k[0])
            && k[n..].iter().all(|v| *v == k[n + s.order - 1]);
        let spacing = k[s.order] - k[s.order - 1];
        let uniform = k[degree..=n]
            .windows(2)
            .all(|w| ((w[1] - w[0]) - spacing).abs() <= 1e-9 * spacing.abs().max(1.0));
        if !clamped || !uniform || spacing.is_nan() || spacing <= 0.0 {
            return Err(ProgramError::Unsupported(
                "a B spline whose knots are not clamped and equally spaced (BSPLINE's PL)".into(),
            ));
        }
        let axes: Vec<usize> = (0..3).filter(|a| self.letters[*a].is_some()).collect();
        if !axes.contains(&0) || !axes.contains(&2) {
            return Err(ProgramError::Unsupported(
                "a spline on a machine without X and Z".into(),
            ));
        }
        let p0 = s.points[0];
        if (0..3).any(|a| !axes.contains(&a) && s.points.iter().any(|p| p[a] != p0[a])) {
            return Err(ProgramError::Unsupported(
                "a spline moving an axis the machine does not have".into(),
            ));
        }
        let o = self.control.map_or([0.0; 3], |c| [c.x, c.y, c.z]);
        let start = self.text.len();
        let r = self.bspline_blocks(s, &axes, spacing, o);
        if r.is_err() {
            self.text.truncate(start);
        }
        r
    }

    fn bspline_blocks(
        &mut self,
        s: &crate::moves::Spline,
        axes: &[usize],
        spacing: f64,
        o: [f64; 3],
    ) -> Result<(), ProgramError> {
        use crate::moves::Feed as F;
        let format = Decimals::new(self.decimals);
        let Some(pl_units) = format.units(spacing) else {
            return Err(ProgramError::NotPrintable {
                word: 'L',
                value: spacing,
            });
        };
        let mut printed = self.last;
        let mut new_mode = None;
        let mut new_feed = None;
        for (i, p) in s.points.iter().enumerate().skip(1) {
            let start = self.text.len();
            self.begin_block();
            if i == 1 {
                if matches!(s.feed, Some(F::PerTime(_))) && self.mode != Some(FeedMode::PerMinute) {
                    let w = self.feed_mode_word(FeedMode::PerMinute)?.to_string();
                    self.text.extend_from_slice(w.as_bytes());
                    self.text.push(b' ');
                    new_mode = Some(FeedMode::PerMinute);
                } else if s.feed.is_some_and(|f| !matches!(f, F::PerTime(_))) {
                    return Err(ProgramError::Unsupported(
                        "a spline fed other than per minute".into(),
                    ));
                }
                self.text
                    .extend_from_slice(format!("BSPLINE SD={} ", s.order - 1).as_bytes());
            }
            self.text.extend_from_slice(b"PL=");
            self.number('L', spacing, pl_units, format.places())?;
            for &a in axes {
                let letter = self.letters[a].expect("an axis the machine has");
                let value = (p[a] + o[a]) * self.axis_scale[a];
                let Some(units) = self.axis_formats[a].units(value) else {
                    return Err(self.not_printable(a, p[a]));
                };
                self.text.push(b' ');
                self.text.push(letter as u8);
                self.number(letter, value, units, self.axis_decimals[a])?;
                printed[a] = units;
            }
            if i == 1
                && let Some(F::PerTime(v)) = s.feed
            {
                new_feed = Some(self.curve_feed_word(v)?);
            }
            self.end_block(start)?;
        }
        // The axes are at the last control point, as printed.
        if let Some(mode) = new_mode {
            self.mode = Some(mode);
        }
        if new_feed.is_some() {
            self.last_feed = new_feed;
        }
        let last = s.points[s.points.len() - 1];
        for &a in axes {
            self.last[a] = printed[a];
            self.at[a] = last[a];
        }
        self.moves += 1;
        Ok(())
    }

    /// A knot word `K…`, printed to `format`'s decimals.
    fn knot_word(&mut self, k: f64, format: &Decimals) -> Result<(), ProgramError> {
        let Some(units) = format.units(k) else {
            return Err(ProgramError::NotPrintable {
                word: 'K',
                value: k,
            });
        };
        self.text.push(b'K');
        self.number('K', k, units, format.places())
    }

    /// Writes every move of a stream.
    pub fn write_all<'a>(
        &mut self,
        moves: impl IntoIterator<Item = &'a crate::moves::Move>,
    ) -> Result<(), ProgramError> {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: the processor has AVX2: `blank` asked it
            // (`is_x86_feature_detected!`) when the writer started.
            return unsafe { self.write_all_avx2(moves) };
        }
        moves.into_iter().try_for_each(|m| self.write_move(m))
    }

    /// `write_all` compiled for processors with AVX2, BMI1, BMI2 and
    /// LZCNT (`has_avx2`): the same code, no intrinsic of its own, in
    /// three-operand vector instructions (no register copies before
    /// each), shifts by a register that need not be `cl`, and leading
    /// zeros counted in one instruction. The same operations on the same
    /// values, so the same bytes (`write_all_for_avx2_writes_what_it_writes_for_any_x86_64`);
    /// no fused multiply-add (not enabled, and Rust never contracts a
    /// product and a sum into one).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,bmi1,bmi2,lzcnt")]
    fn write_all_avx2<'a>(
        &mut self,
        moves: impl IntoIterator<Item = &'a crate::moves::Move>,
    ) -> Result<(), ProgramError> {
        moves.into_iter().try_for_each(|m| self.write_move(m))
    }

    /// The text written since the last call (for streaming to a file),
    /// every number and dialect line in it checked as it was written (see
    /// `ProgramWriter`); the next chunk starts with room for as much
    /// again and an eighth more (the same moves a chunk make a little
    /// more text as numbers grow a digit: room for exactly as much had
    /// one chunk in five of the emission bench outgrow it, its text
    /// copied into an allocation twice the size).
    pub fn take_text(&mut self) -> Result<String, ProgramError> {
        let len = self.text.len();
        let room = len + len / 8 + BLOCK_ROOM;
        self.zeroed = Zeroed::default();
        let text = std::mem::replace(&mut self.text, Vec::with_capacity(room));
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: the processor has AVX2 (`blank` asked it).
            return unsafe { utf8_avx2(text) };
        }
        utf8(text)
    }

    /// Ends the program; the text not yet taken, checked.
    pub fn finish(mut self) -> Result<String, ProgramError> {
        let Some(start) = self.start else {
            return Err(ProgramError::Unsupported(
                "a program that calls no tool (the writer's `call_tool`)".into(),
            ));
        };
        if self.pending_tool_call.is_some() {
            self.write_tool_call(None)?;
        }
        if self.spindle != Spindle::Stopped {
            self.spindle = Spindle::Stopped;
            let off = self.dialect.spindle_off.clone();
            self.block_line(&off)?;
        }
        if start.coolant != Coolant::Off
            && let Some(off) = self.dialect.coolant_off.clone()
        {
            self.block_line(&off)?;
        }
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
            self.line_as_written(&l)?;
        }
        utf8(self.text)
    }
}

/// Whether this processor has what `write_all_avx2` is compiled for:
/// AVX2, BMI1, BMI2 and LZCNT.
#[cfg(target_arch = "x86_64")]
fn has_avx2() -> bool {
    std::arch::is_x86_feature_detected!("avx2")
        && std::arch::is_x86_feature_detected!("bmi1")
        && std::arch::is_x86_feature_detected!("bmi2")
        && std::arch::is_x86_feature_detected!("lzcnt")
}

/// The writer's text as a `String`: it only ever appends `str`s and
/// ASCII, so this holds; were it ever not so, the text is refused, not
/// handed out.
///
/// Text that is all ASCII (a program's usual text) is told so by one
/// pass of wide ORs (`all_ascii`), not the UTF-8 decoder's byte-pair
/// steps; any other text goes through the decoder.
#[inline(always)]
fn utf8(text: Vec<u8>) -> Result<String, ProgramError> {
    if all_ascii(&text) {
        // SAFETY: every byte was just found to be ASCII, and ASCII text
        // is UTF-8.
        return Ok(unsafe { String::from_utf8_unchecked(text) });
    }
    String::from_utf8(text)
        .map_err(|_| ProgramError::Unsupported("program text that is not UTF-8".into()))
}

/// `utf8` compiled for AVX2 (`all_ascii` 32 bytes an instruction).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn utf8_avx2(text: Vec<u8>) -> Result<String, ProgramError> {
    utf8(text)
}

/// Whether every byte of `bytes` is ASCII (below 0x80): the bytes ORed
/// together in 64-byte blocks, eight words a block (a loop the compiler
/// turns into vector ORs), the top bits of the result tested once.
#[inline(always)]
fn all_ascii(bytes: &[u8]) -> bool {
    const TOP_BITS: u64 = 0x8080_8080_8080_8080;
    let mut blocks = bytes.chunks_exact(64);
    let mut any = [0u64; 8];
    for block in &mut blocks {
        for (a, word) in any.iter_mut().zip(block.chunks_exact(8)) {
            let mut w = [0; 8];
            w.copy_from_slice(word);
            *a |= u64::from_le_bytes(w);
        }
    }
    let rest = blocks.remainder().iter().fold(0u8, |a, &b| a | b);
    any.iter().fold(0, |a, &w| a | w) & TOP_BITS == 0 && rest.is_ascii()
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

/// Room for a motion block's words after its prefix: the motion word,
/// four axis words, two arc-centre words, the feed word (each a space,
/// its letter and the longest number) and the line end.
const BLOCK_ROOM: usize = SNIPPET_ROOM + 7 * WORD_ROOM + SNIPPET_ROOM;

/// A space, a letter (up to four bytes) and the longest number, with the
/// head's fixed-size copy ending within it.
const WORD_ROOM: usize = 5 + PRINTED_ROOM;

/// `BLOCK_ROOM` bytes added at the end of `text` for a block to be
/// printed into (the caller cuts the text back to what it printed): bytes
/// of its spare capacity, zeroed a step (`ZERO_STEP`) ahead of the
/// blocks (`zeroed`), not byte by byte each block, and not the whole
/// spare capacity at once (a chunk's worth of zeros written out of the
/// first-level cache before the blocks write over them).
#[inline(always)]
fn block_room<'t>(text: &'t mut Vec<u8>, zeroed: &mut Zeroed) -> &'t mut [u8; BLOCK_ROOM] {
    let at = text.len();
    if zeroed.to < at + BLOCK_ROOM || zeroed.capacity != text.capacity() {
        zero_ahead(text, zeroed);
    }
    // SAFETY: `at + BLOCK_ROOM` is within the capacity (`zeroed.to` is,
    // and `zero_ahead` leaves it at least there), and every byte of the
    // allocation up to `zeroed.to` is initialised: below the length, as
    // a `Vec`'s are; from it, zeroed by `zero_ahead` while the
    // allocation was this one (`zeroed.capacity` is its capacity, and a
    // `Vec` only reallocates to a larger one; the writer replaces its
    // text only in `take_text`, which resets `zeroed`, and `finish`); a
    // `Vec` never de-initialises bytes beyond its length.
    unsafe { text.set_len(at + BLOCK_ROOM) };
    match text.last_chunk_mut::<BLOCK_ROOM>() {
        Some(room) => room,
        None => unreachable!("the room was just added"),
    }
}

/// How much of the text's allocation `block_room` may hand out: the
/// allocation's `capacity` when its bytes were zeroed up `to` (from its
/// length then); any other capacity, a new allocation: nothing.
#[derive(Clone, Copy, Debug, Default)]
struct Zeroed {
    capacity: usize,
    to: usize,
}

/// Bytes zeroed ahead of the blocks at a time: a few pages' worth, so
/// the zeros are still in the first-level cache when blocks are printed
/// over them.
const ZERO_STEP: usize = 8192;

/// Room for a block at the end of `text`, and its spare capacity zeroed
/// from the length (or where it was zeroed to) for `ZERO_STEP` bytes, or
/// to its end (`block_room`).
#[cold]
fn zero_ahead(text: &mut Vec<u8>, zeroed: &mut Zeroed) {
    text.reserve(BLOCK_ROOM);
    let len = text.len();
    if zeroed.capacity != text.capacity() {
        // A new allocation: nothing of its spare capacity is known.
        *zeroed = Zeroed {
            capacity: text.capacity(),
            to: len,
        };
    }
    let from = zeroed.to.max(len) - len;
    let to = (len + ZERO_STEP).min(text.capacity());
    if let Some(spare) = text.spare_capacity_mut().get_mut(from..to - len) {
        spare.fill(std::mem::MaybeUninit::new(0));
    }
    zeroed.to = zeroed.to.max(to);
}

/// Why a word cannot go into a block, found while the block is printed
/// into its room (the error is made once the room is given back).
enum Refusal {
    /// Axis i's value (the stream's) cannot be printed, or the machine
    /// has no such axis.
    NotPrintable(usize, f64),
    /// The word's value cannot be printed.
    Unprintable(char, f64),
    /// More digits in all than the dialect takes.
    TooManyDigits(char, f64, usize),
    /// More digits before the point than the letter's format allows.
    IntegerDigits(char, f64),
    /// Any other refusal (an arc's radii).
    Error(Box<ProgramError>),
}

/// Prints the word ` L<n>` (`head`, the space and letter L, then `n`
/// units of the last of `format`'s
/// decimals, `value` what they round) at `pos` of a block's room through
/// the one number formatter; the word's end, or why the dialect refuses
/// it: more digits than `max_digits`, or a unit count of `unit_limit` or
/// more (more digits before the point than the letter's format allows).
/// The digits come from an integer count of units, so they cannot spell
/// an exponent, NaN or `-0`: `check_number` holds of them by
/// construction (the format module's tests hold the printer to that), and
/// is asserted again in debug builds.
#[inline(always)]
#[allow(clippy::too_many_arguments, reason = "one word's parts, inlined")]
fn print_word(
    room: &mut [u8; BLOCK_ROOM],
    pos: usize,
    head: &WordHead,
    letter: char,
    value: f64,
    n: i64,
    format: &Decimals,
    max_digits: usize,
    unit_limit: u64,
) -> Result<usize, Refusal> {
    let Some(word) = room
        .get_mut(pos..)
        .and_then(|r| r.first_chunk_mut::<WORD_ROOM>())
    else {
        unreachable!("a block's words fit its room")
    };
    // A space and the letter (UTF-8: up to four bytes), then the number.
    word[..WORD_HEAD].copy_from_slice(&head.bytes);
    let Some(number) = word[head.len..].first_chunk_mut::<PRINTED_ROOM>() else {
        unreachable!("a word's room holds the longest number")
    };
    let (len, digits) = format.print(number, n);
    debug_assert!(check_number(&number[..len]).is_ok());
    if digits > max_digits {
        return Err(Refusal::TooManyDigits(letter, value, digits));
    }
    // |n| / 10^d ≥ limit exactly when |n| ≥ limit · 10^d (a product too
    // large for a u64 is more than any |n|, as is no limit at all).
    if n.unsigned_abs() >= unit_limit {
        return Err(Refusal::IntegerDigits(letter, value));
    }
    Ok(pos + head.len + len)
}

/// Room for a word's head: a space and a letter of up to four bytes.
const WORD_HEAD: usize = 8;

/// A word's head, a space and its letter, as a copy of fixed size.
#[derive(Clone, Copy)]
struct WordHead {
    bytes: [u8; WORD_HEAD],
    len: usize,
}

impl WordHead {
    #[inline(always)]
    fn new(letter: char) -> WordHead {
        let mut bytes = [b' '; WORD_HEAD];
        let len = 1 + letter.encode_utf8(&mut bytes[1..]).len();
        WordHead { bytes, len }
    }
}

/// The feed word's head.
const FEED_HEAD: WordHead = WordHead {
    bytes: *b" F      ",
    len: 2,
};

/// The feed word, printed at `pos` of the block's room: written when the
/// mode or the printed feed changes, and on every move in inverse time;
/// the last printed feed and mode (`modal`) become this one's. The mode
/// comes with the feed's value, its decimals and the unit count from
/// which it has too many digits before the point. Its end, or why it is
/// refused.
#[inline(always)]
fn feed_word(
    room: &mut [u8; BLOCK_ROOM],
    pos: usize,
    (m, value, format, unit_limit): (FeedMode, f64, Decimals, u64),
    mode_changes: bool,
    (last_feed, mode): (&mut Option<i64>, &mut Option<FeedMode>),
    max_digits: usize,
) -> Result<usize, Refusal> {
    let Some(n) = format.units(value).filter(|&n| n > 0) else {
        return Err(Refusal::Unprintable('F', value));
    };
    let mut end = pos;
    if mode_changes || m == FeedMode::InverseTime || *last_feed != Some(n) {
        end = print_word(
            room, pos, &FEED_HEAD, 'F', value, n, &format, max_digits, unit_limit,
        )?;
    }
    *last_feed = Some(n);
    *mode = Some(m);
    Ok(end)
}

#[derive(Clone, Copy)]
enum Word {
    Rapid,
    Linear,
    ArcCw,
    ArcCcw,
}

/// Whether `dialect` can write a program of this `setup` for a machine of
/// this resolution (mm): it has the setup's lines and prints as many
/// decimals as the resolution needs. The decimals, or why not. Every
/// writer checks it when it starts; the compiler's lowering checks it
/// before planning.
pub fn check_dialect(
    dialect: &Dialect,
    setup: Setup,
    resolution: f64,
) -> Result<u32, ProgramError> {
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
    if dialect.language == Language::Klartext && setup == Setup::Lathe {
        return Err(ProgramError::Unsupported(format!(
            "lathe programs ({} is Heidenhain Klartext, a TNC milling language)",
            dialect.name
        )));
    }
    // A Klartext program states its units in `BEGIN PGM … MM` and the
    // tool's plane in its tool call: it needs no setup blocks.
    if setup_lines.is_empty() && dialect.language == Language::GCode {
        return Err(ProgramError::Unsupported(format!(
            "{} programs ({} has no `{}_setup`)",
            setup.name(),
            dialect.name,
            setup.name(),
        )));
    }
    check_number_words(dialect, decimals)?;
    tool_call_lines(dialect, setup, &Start::default())?;
    Ok(decimals)
}

/// The words the writer prints numbers into must take what it prints:
/// axes and arc centres with a point and the resolution's decimals, C
/// with its own, F with a point.
fn check_number_words(dialect: &Dialect, decimals: u32) -> Result<(), ProgramError> {
    for f in &dialect.word_formats {
        let needs = match f.letter {
            'X' | 'Y' | 'Z' | 'I' | 'J' | 'K' => Some(decimals),
            c if c == dialect.c_letter => Some(dialect.c_decimals),
            'F' => Some(0),
            _ => None,
        };
        let Some(needs) = needs else { continue };
        match f.decimals {
            Some(d) if d >= needs => {}
            _ => {
                return Err(ProgramError::Unsupported(format!(
                    "the machine's numbers in {} ({} needs {needs} decimals and a point; the dialect's format `{}` gives {})",
                    f.letter,
                    dialect.name,
                    format_text(f),
                    f.decimals.map_or("none".to_string(), |d| d.to_string())
                )));
            }
        }
    }
    Ok(())
}

/// A word format as a dialect file writes it (`S5`, `X4.4`).
pub fn format_text(f: &WordFormat) -> String {
    match f.decimals {
        Some(d) => format!("{}{}.{d}", f.letter, f.integer_digits),
        None => format!("{}{}", f.letter, f.integer_digits),
    }
}

/// The dialect's tool-call blocks for a program of this `setup`, its
/// placeholders filled: `{tool}` and `{offset}`, and `{tool:2}` and
/// `{offset:2}` zero-padded to two digits (Fanuc's `T0101`). Each block
/// is checked against the dialect's word formats, so a tool number that
/// does not fit its word is refused here.
pub fn tool_call_lines(
    dialect: &Dialect,
    setup: Setup,
    start: &Start,
) -> Result<Vec<String>, ProgramError> {
    let lines = match setup {
        Setup::Lathe => &dialect.lathe_tool_call,
        Setup::Mill => &dialect.mill_tool_call,
    };
    if lines.is_empty() {
        return Err(ProgramError::Unsupported(format!(
            "a tool call ({} has no `{}_tool_call`)",
            dialect.name,
            setup.name()
        )));
    }
    let two = |n: u32| {
        (n < 100).then(|| format!("{n:02}")).ok_or_else(|| {
            ProgramError::Unsupported(format!(
                "tool or offset number {n} in the two digits `{}` gives it",
                dialect.name
            ))
        })
    };
    let mut out = Vec::with_capacity(lines.len());
    for line in lines {
        let mut l = line.clone();
        if l.contains("{tool:2}") {
            l = l.replace("{tool:2}", &two(start.tool)?);
        }
        if l.contains("{offset:2}") {
            l = l.replace("{offset:2}", &two(start.offset)?);
        }
        let l = l
            .replace("{tool}", &start.tool.to_string())
            .replace("{offset}", &start.offset.to_string());
        check_numbers(&l, dialect.comment)?;
        check_word_formats(&l, dialect)?;
        out.push(l);
    }
    Ok(out)
}

/// The dialect's word for the job's coolant (none for `Off`), or why it
/// cannot be given.
pub fn coolant_word(dialect: &Dialect, coolant: Coolant) -> Result<Option<String>, ProgramError> {
    let (word, name) = match coolant {
        Coolant::Off => return Ok(None),
        Coolant::Flood => (&dialect.coolant_flood, "flood"),
        Coolant::Mist => (&dialect.coolant_mist, "mist"),
    };
    match word {
        Some(w) if dialect.coolant_off.is_some() => Ok(Some(w.clone())),
        _ => Err(ProgramError::Unsupported(format!(
            "{name} coolant ({} has no `coolant_{name}` or no `coolant_off` word)",
            dialect.name
        ))),
    }
}

/// A word letter's index A…Z (anything else shares Z's: only the
/// writer's own letters reach here).
#[inline(always)]
fn letter_index(letter: char) -> usize {
    (letter as usize).wrapping_sub('A' as usize).min(25)
}

/// Per letter A…Z, 10 to the most digits before the point its format
/// allows (`u64::MAX`: no limit).
fn integer_limits(dialect: &Dialect) -> [u64; 26] {
    let mut limits = [u64::MAX; 26];
    for f in &dialect.word_formats {
        if f.letter.is_ascii_uppercase() {
            limits[letter_index(f.letter)] = 10u64.saturating_pow(f.integer_digits);
        }
    }
    limits
}

/// Every word of a block of code checked against the dialect's word
/// formats: no point in an integer word, no more digits before or after
/// the point than its format allows. Comments are not code.
pub fn check_word_formats(text: &str, dialect: &Dialect) -> Result<(), ProgramError> {
    if dialect.word_formats.is_empty() {
        return Ok(());
    }
    let opens = match dialect.comment {
        CommentStyle::Parentheses => '(',
        CommentStyle::Semicolon => ';',
    };
    for line in text.split('\n') {
        let code = &line[..line.find(opens).unwrap_or(line.len())];
        for word in code.split_whitespace() {
            let mut chars = word.chars();
            let Some(letter) = chars.next() else { continue };
            let Some(f) = dialect.format_of(letter) else {
                continue;
            };
            let number = chars.as_str().trim_start_matches(['-', '+']);
            if number.is_empty() || !number.bytes().all(|b| b.is_ascii_digit() || b == b'.') {
                continue;
            }
            if let Err(why) = fits(number, f) {
                return Err(ProgramError::Unsupported(format!(
                    "the word `{word}` ({why}) in the line `{line}`"
                )));
            }
        }
    }
    Ok(())
}

/// Whether the digits of a number (no sign) fit a word format.
fn fits(number: &str, f: WordFormat) -> Result<(), String> {
    let (whole, decimals) = match number.split_once('.') {
        Some((w, d)) => (w, Some(d)),
        None => (number, None),
    };
    match (f.decimals, decimals) {
        (None, Some(_)) => {
            return Err(format!(
                "{} is an integer word, written without a decimal point",
                f.letter
            ));
        }
        (Some(max), Some(d)) if d.len() as u32 > max => {
            return Err(format!("{} takes at most {max} decimals", f.letter));
        }
        _ => {}
    }
    if whole.len() as u32 > f.integer_digits {
        return Err(format!(
            "{} takes at most {} digits before the point",
            f.letter, f.integer_digits
        ));
    }
    Ok(())
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

mod common_block;
mod klartext;
#[cfg(test)]
mod tests;
