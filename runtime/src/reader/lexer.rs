//! One line of program text to its words, as the dialect's controller
//! splits it: the block number, address words (`X1.5`), Siemens'
//! keywords (`DIAMOF`, `LIMS=3000.`), comments, and the `%` lines that
//! open and close a program; with the refusals a controller makes while
//! reading a line (line length, comments, number format).

use super::{Controller, Rule};
use crate::dialect::{CommentStyle, Dialect, WordFormat};

/// A finding as the line reports it: rule, span within the line, message,
/// hint.
pub(crate) type Found = (Rule, (usize, usize), String, Option<String>);

/// An address word: a letter and its number.
#[derive(Clone, Debug)]
pub(crate) struct Word {
    pub letter: char,
    pub value: f64,
    pub span: (usize, usize),
    pub point: bool,
    /// Digits after the point.
    pub decimals: usize,
}

impl Word {
    /// The word as written.
    pub fn text<'a>(&self, line: &'a str) -> &'a str {
        &line[self.span.0..self.span.1]
    }
}

/// A Siemens keyword (`DIAMOF`, `LIMS=3000.`, `T="DIAMOND"`).
#[derive(Clone, Debug)]
pub(crate) struct Keyword {
    pub kind: KeywordKind,
    pub value: Option<f64>,
    pub span: (usize, usize),
}

/// What a Siemens keyword is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum KeywordKind {
    /// A word of several letters the reader knows (`DIAMOF`, `LIMS=3000.`).
    Word(SiemensWord),
    /// An address letter given a string: `T="DIAMOND"`, a tool by name.
    Text(char),
    /// `CYCLE832(…)`: the high-speed settings (tolerance, smoothing,
    /// compressor), which move nothing.
    Cycle832,
}

/// The Siemens words of several letters the reader knows (840D sl
/// programming manual): the ones lensc's dialects write and their
/// opposites. Any other is refused as a word the controller does not read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum SiemensWord {
    Diamof,
    Diamon,
    Diam90,
    Compcad,
    Compcurv,
    Compon,
    Compof,
    Spcon,
    Spcof,
    Spos,
    Ctol,
    Otol,
    Atol,
    Lims,
    Soft,
    Brisk,
    Ffwon,
    Ffwof,
    Supa,
    /// B spline interpolation (a motion mode) and its block words: the
    /// degree SD, the knot spacing PL, a control point's weight PW.
    Bspline,
    Sd,
    Pl,
    Pw,
}

impl SiemensWord {
    /// Every word, in declaration order.
    const ALL: [SiemensWord; 23] = [
        SiemensWord::Diamof,
        SiemensWord::Diamon,
        SiemensWord::Diam90,
        SiemensWord::Compcad,
        SiemensWord::Compcurv,
        SiemensWord::Compon,
        SiemensWord::Compof,
        SiemensWord::Spcon,
        SiemensWord::Spcof,
        SiemensWord::Spos,
        SiemensWord::Ctol,
        SiemensWord::Otol,
        SiemensWord::Atol,
        SiemensWord::Lims,
        SiemensWord::Soft,
        SiemensWord::Brisk,
        SiemensWord::Ffwon,
        SiemensWord::Ffwof,
        SiemensWord::Supa,
        SiemensWord::Bspline,
        SiemensWord::Sd,
        SiemensWord::Pl,
        SiemensWord::Pw,
    ];

    /// The word as a program writes it.
    fn name(self) -> &'static str {
        match self {
            SiemensWord::Diamof => "DIAMOF",
            SiemensWord::Diamon => "DIAMON",
            SiemensWord::Diam90 => "DIAM90",
            SiemensWord::Compcad => "COMPCAD",
            SiemensWord::Compcurv => "COMPCURV",
            SiemensWord::Compon => "COMPON",
            SiemensWord::Compof => "COMPOF",
            SiemensWord::Spcon => "SPCON",
            SiemensWord::Spcof => "SPCOF",
            SiemensWord::Spos => "SPOS",
            SiemensWord::Ctol => "CTOL",
            SiemensWord::Otol => "OTOL",
            SiemensWord::Atol => "ATOL",
            SiemensWord::Lims => "LIMS",
            SiemensWord::Soft => "SOFT",
            SiemensWord::Brisk => "BRISK",
            SiemensWord::Ffwon => "FFWON",
            SiemensWord::Ffwof => "FFWOF",
            SiemensWord::Supa => "SUPA",
            SiemensWord::Bspline => "BSPLINE",
            SiemensWord::Sd => "SD",
            SiemensWord::Pl => "PL",
            SiemensWord::Pw => "PW",
        }
    }

    /// The word `name` is; `None` for a word the reader does not know.
    fn of(name: &str) -> Option<SiemensWord> {
        SiemensWord::ALL.into_iter().find(|w| w.name() == name)
    }
}

/// A line's contents.
#[derive(Clone, Debug, Default)]
pub(crate) struct Block {
    pub number: Option<Word>,
    pub words: Vec<Word>,
    pub keywords: Vec<Keyword>,
    /// Comment texts, in order.
    pub comments: Vec<String>,
    /// A `%` line: the program's start or end marker.
    pub percent: bool,
}

impl Block {
    /// No words, keywords or comments, as `Block::default()`, keeping the
    /// storage.
    pub fn clear(&mut self) {
        self.number = None;
        self.words.clear();
        self.keywords.clear();
        self.comments.clear();
        self.percent = false;
    }

    pub fn is_empty(&self) -> bool {
        self.words.is_empty() && self.keywords.is_empty()
    }
}

/// How a dialect's lines are split.
pub(crate) struct Lexer {
    pub controller: Controller,
    comment: CommentStyle,
    block_end: String,
    max_line_length: Option<usize>,
    max_decimals: Option<u32>,
    max_digits: Option<u32>,
    /// The dialect's format of each word (`S5`, `X4.4`).
    formats: Vec<WordFormat>,
    /// LinuxCNC's parameters (`expr`), and those the line being read sets,
    /// which take effect once it is read.
    params: std::cell::RefCell<super::expr::Parameters>,
    pending: std::cell::RefCell<Vec<(super::expr::Name, f64)>>,
}

impl Lexer {
    pub fn new(d: &Dialect) -> Lexer {
        Lexer {
            controller: Controller::of(d),
            comment: d.comment,
            block_end: d.block_end.trim().to_string(),
            max_line_length: d.max_line_length,
            max_decimals: d.max_decimals,
            max_digits: d.max_digits,
            params: Default::default(),
            pending: Default::default(),
            formats: d.word_formats.clone(),
        }
    }

    /// Splits `line` (without its line break) into the block `b`, emptied
    /// first (a reader reuses one block's storage for every line).
    pub fn block_into(&self, line: &str, out: &mut Vec<Found>, b: &mut Block) {
        b.clear();
        self.line_length(line, out);
        let mut code = line.trim_end();
        if code.trim().is_empty() {
            return;
        }
        if !self.block_end.is_empty() {
            match code.strip_suffix(self.block_end.as_str()) {
                Some(c) => code = c,
                None => out.push((
                    Rule::BlockEnd,
                    (0, line.len()),
                    format!("this block does not end with `{}`", self.block_end),
                    Some(format!("end every block with ` {}`", self.block_end)),
                )),
            }
        }
        let code = self.strip_comments(code, b, out);
        self.words(&code, b, out);
        // Parameters set on the line take effect once it is read.
        let mut params = self.params.borrow_mut();
        for (n, v) in self.pending.borrow_mut().drain(..) {
            params.set(n, v);
        }
    }

    /// Whether a block needs nothing closing it (no `*` end to strip).
    pub(crate) fn open_ended(&self) -> bool {
        self.block_end.is_empty()
    }

    /// The longest line the controller reads, in bytes: a line no longer
    /// has no more characters either.
    pub(crate) fn max_line_length(&self) -> Option<usize> {
        self.max_line_length
    }

    /// The dialect's line-length limit.
    pub(crate) fn line_length(&self, line: &str, out: &mut Vec<Found>) {
        if let Some(max) = self.max_line_length
            && line.len() > max
            && line.chars().count() > max
        {
            out.push((
                Rule::LineTooLong,
                (0, line.len()),
                format!(
                    "this line has {} characters; the controller reads at most {max}",
                    line.chars().count()
                ),
                Some("split the line or shorten its comment".into()),
            ));
        }
    }

    /// The line up to its comments (their texts kept in `b`); a `(` never
    /// closed or opened inside another is refused.
    fn strip_comments<'c>(
        &self,
        code: &'c str,
        b: &mut Block,
        out: &mut Vec<Found>,
    ) -> std::borrow::Cow<'c, str> {
        let semicolon =
            self.comment == CommentStyle::Semicolon || self.controller == Controller::LinuxCnc;
        // Every byte looked at (no early exit), so the scan runs on whole
        // vectors of bytes: most lines have no comment.
        let marks = code
            .bytes()
            .fold(false, |seen, c| seen | (c == b'(') | (c == b';'));
        if !marks {
            return code.into();
        }
        let mut kept = String::with_capacity(code.len());
        let mut chars = code.char_indices();
        while let Some((i, c)) = chars.next() {
            if c == ';' && semicolon {
                b.comments.push(code[i + 1..].trim().to_string());
                kept.extend(std::iter::repeat_n(' ', code.len() - i));
                break;
            }
            if c != '(' || self.comment != CommentStyle::Parentheses {
                kept.push(c);
                continue;
            }
            let Some(close) = code[i + 1..].find(')') else {
                out.push((
                    Rule::UnclosedComment,
                    (i, code.len()),
                    "this comment is never closed: the controller refuses the block".into(),
                    Some("close it with `)` on the same line".into()),
                ));
                kept.extend(std::iter::repeat_n(' ', code.len() - i));
                break;
            };
            let inner = &code[i + 1..i + 1 + close];
            if let Some(nested) = inner.find('(') {
                out.push((
                    Rule::NestedComment,
                    (i + 1 + nested, i + 2 + nested),
                    "a comment opened inside a comment: the controller refuses the block".into(),
                    Some("comments cannot nest; write `[` `]` inside one".into()),
                ));
            }
            b.comments.push(inner.to_string());
            kept.extend(std::iter::repeat_n(' ', close + 2));
            for _ in 0..inner.chars().count() + 1 {
                chars.next();
            }
        }
        kept.into()
    }

    /// The words of a line with its comments blanked (byte positions kept).
    fn words(&self, code: &str, b: &mut Block, out: &mut Vec<Found>) {
        let bytes = code.as_bytes();
        let mut i = 0;
        while i < bytes.len() {
            let c = bytes[i];
            if c.is_ascii_whitespace() {
                i += 1;
                continue;
            }
            if c == b'%' && b.words.iter().all(|w| w.letter == 'N') && b.keywords.is_empty() {
                // A program's start or end marker, with its name.
                b.percent = true;
                i += code[i..]
                    .find(char::is_whitespace)
                    .unwrap_or(code.len() - i);
                continue;
            }
            if c == b'/' && self.controller == Controller::LinuxCnc && code[..i].trim().is_empty() {
                // Block delete, first on the line: the block is read as
                // run (the switch off, as `rs274 -g` runs it).
                i += 1;
                continue;
            }
            if c == b'#' && self.controller == Controller::LinuxCnc {
                i = self.assignment(code, i, out);
                continue;
            }
            if !c.is_ascii_alphabetic() {
                let end = i + code[i..].chars().next().map_or(1, char::len_utf8);
                out.push(unknown(
                    (i, end),
                    "a character the controller does not read here",
                ));
                i = end;
                continue;
            }
            let start = i;
            while i < bytes.len() && bytes[i].is_ascii_alphabetic() {
                i += 1;
            }
            let name = &code[start..i];
            if name.len() > 1 {
                i = self.keyword(code, start, i, b, out);
                continue;
            }
            let mut letter = name.chars().next().unwrap_or('?');
            if self.controller == Controller::LinuxCnc {
                letter = letter.to_ascii_uppercase();
            }
            if self.controller == Controller::Siemens && bytes.get(i) == Some(&b'=') {
                i += 1;
                if bytes.get(i) == Some(&b'"') {
                    let close = code[i + 1..].find('"').map_or(code.len(), |c| i + 2 + c);
                    b.keywords.push(Keyword {
                        kind: KeywordKind::Text(letter),
                        value: None,
                        span: (start, close),
                    });
                    i = close;
                    continue;
                }
            }
            let after = code[i..].trim_start();
            if self.controller == Controller::LinuxCnc
                && (after.starts_with('[') || after.starts_with('#'))
            {
                let params = self.params.borrow();
                match super::expr::value(code, i, &params) {
                    Ok((value, end)) => {
                        let w = Word {
                            letter,
                            value,
                            span: (start, end),
                            point: true,
                            decimals: 0,
                        };
                        drop(params);
                        self.number_format(&w, code, out);
                        if w.letter == 'N' && b.words.is_empty() && b.number.is_none() {
                            b.number = Some(w);
                        } else {
                            b.words.push(w);
                        }
                        i = end;
                    }
                    Err(e) => {
                        out.push((
                            Rule::MalformedNumber,
                            (start, code.len()),
                            format!("`{}`: {e}", &code[start..]),
                            None,
                        ));
                        i = code.len();
                    }
                }
                continue;
            }
            let (number, end) = number(code, i);
            i = end;
            let Some((value, point, decimals)) = number else {
                out.push((
                    Rule::MalformedNumber,
                    (start, end.max(start + 1)),
                    format!(
                        "`{}` has no number after its letter",
                        &code[start..end.max(start + 1)]
                    ),
                    None,
                ));
                continue;
            };
            let w = Word {
                letter,
                value,
                span: (start, end),
                point,
                decimals,
            };
            self.number_format(&w, code, out);
            if w.letter == 'N' && b.words.is_empty() && b.number.is_none() {
                b.number = Some(w);
            } else {
                b.words.push(w);
            }
        }
    }

    /// A LinuxCNC parameter setting at `code[i..]` (`#1=2`, `#<depth>=[#1*2]`),
    /// kept until the line is read; returns where it ends.
    fn assignment(&self, code: &str, i: usize, out: &mut Vec<Found>) -> usize {
        let params = self.params.borrow();
        let set = super::expr::name(code, i + 1, &params).and_then(|(n, j)| {
            let rest = &code[j..];
            let eq = j + rest.len() - rest.trim_start().len();
            if code.as_bytes().get(eq) != Some(&b'=') {
                return Err("a parameter is set with `=`".to_string());
            }
            let (v, end) = super::expr::value(code, eq + 1, &params)?;
            Ok((n, v, end))
        });
        match set {
            Ok((n, v, end)) => {
                self.pending.borrow_mut().push((n, v));
                end
            }
            Err(e) => {
                out.push((
                    Rule::MalformedNumber,
                    (i, code.len()),
                    format!("`{}`: {e}", &code[i..]),
                    None,
                ));
                code.len()
            }
        }
    }

    /// A word of several letters: Siemens' keywords, read up to its value.
    fn keyword(
        &self,
        code: &str,
        start: usize,
        mut i: usize,
        b: &mut Block,
        out: &mut Vec<Found>,
    ) -> usize {
        let bytes = code.as_bytes();
        // A Sinumerik cycle call, `CYCLE832(0.001,1,1)`: its name with its
        // number, and its arguments, numbers separated by commas.
        if self.controller == Controller::Siemens
            && &code[start..i] == "CYCLE"
            && let Some(call) = cycle_call(code, i)
        {
            let name = &code[start..call.0];
            if SIEMENS_CYCLES.contains(&name) {
                b.keywords.push(Keyword {
                    kind: KeywordKind::Cycle832,
                    value: None,
                    span: (start, call.1),
                });
            } else {
                out.push(unknown(
                    (start, call.1),
                    &format!("`{name}` is not a cycle lensc reads"),
                ));
            }
            return call.1;
        }
        let name = &code[start..i];
        let mut value = None;
        if bytes.get(i) == Some(&b'=') {
            let (n, end) = number(code, i + 1);
            value = n.map(|n| n.0);
            if n.is_none() {
                out.push((
                    Rule::MalformedNumber,
                    (start, end.max(i + 1)),
                    format!("`{name}=` has no number"),
                    None,
                ));
            }
            i = end;
        }
        if self.controller == Controller::Siemens
            && let Some(word) = SiemensWord::of(name)
        {
            b.keywords.push(Keyword {
                kind: KeywordKind::Word(word),
                value,
                span: (start, i),
            });
        } else {
            out.push(unknown(
                (start, i),
                &format!("`{}` is not a word this controller reads", &code[start..i]),
            ));
        }
        i
    }

    /// What the dialect's number format allows a word of `letter`.
    pub(crate) fn limits(&self, letter: char) -> WordLimits {
        let format = self.formats.iter().find(|f| f.letter == letter);
        let whole = format.is_some_and(|f| f.decimals.is_none());
        WordLimits {
            point: self.controller == Controller::LinuxCnc
                || !(whole || integer_only(self.controller, letter)),
            integer_only: integer_only(self.controller, letter),
            max_decimals: format.and_then(|f| f.decimals).or(self.max_decimals),
            // No limit on the digits to hold them against: not counted.
            digits_counted: self.max_digits.is_some() || format.is_some(),
            max_digits: self.max_digits,
            integer_digits: format.map(|f| f.integer_digits),
        }
    }

    /// Digits, decimals and the decimal point of a word against the
    /// dialect's number format.
    pub(crate) fn number_format(&self, w: &Word, code: &str, out: &mut Vec<Found>) {
        let text = &code[w.span.0..w.span.1];
        let limits = self.limits(w.letter);
        if self.controller == Controller::LinuxCnc {
            // LinuxCNC reads any word with a point; M, T and H must be
            // whole numbers within 0.0001 as its `read_integer_value`
            // takes them: the fraction above the floor over 0.0001 and
            // under 0.9999 is "Non integer value for integer" (`M3.00009`
            // reads, `M3.0001` and `T1.0002` do not).
            let fraction = w.value - w.value.floor();
            if matches!(w.letter, 'M' | 'T' | 'H') && fraction > 1e-4 && fraction <= 0.9999 {
                out.push((
                    Rule::DecimalPoint,
                    w.span,
                    format!(
                        "`{text}`: LinuxCNC reads {} words as whole numbers (within 0.0001)",
                        w.letter
                    ),
                    Some(format!("write {}{}", w.letter, w.value.round())),
                ));
            }
        } else if w.point && !limits.point {
            let whose = if limits.integer_only {
                "this controller reads"
            } else {
                "the dialect's format gives"
            };
            out.push((
                Rule::DecimalPoint,
                w.span,
                format!(
                    "`{text}`: {whose} {} words as whole numbers, without a decimal point",
                    w.letter
                ),
                Some(format!("write {}{}", w.letter, w.value.trunc())),
            ));
        }
        if let Some(max) = limits.max_decimals
            && w.decimals > max as usize
        {
            out.push((
                Rule::TooManyDecimals,
                w.span,
                format!(
                    "`{text}` has {} decimals; the controller reads at most {max}",
                    w.decimals
                ),
                None,
            ));
        }
        if !limits.digits_counted {
            return;
        }
        let digits = significant_digits(text.as_bytes());
        if let Some(max) = limits.max_digits
            && digits > max as usize
        {
            out.push((
                Rule::TooManyDigits,
                w.span,
                format!("`{text}` has {digits} digits; the controller reads at most {max}"),
                None,
            ));
        }
        let before = digits.saturating_sub(w.decimals);
        if let Some(most) = limits.integer_digits
            && before > most as usize
        {
            out.push((
                Rule::TooManyDigits,
                w.span,
                format!(
                    "`{text}` has {before} digits before the point; the dialect's {} words have at most {most}",
                    w.letter
                ),
                None,
            ));
        }
    }
}

/// What a dialect's number format allows one word letter (`Lexer::limits`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct WordLimits {
    /// A decimal point may be written.
    pub point: bool,
    /// The controller reads the letter as a whole number only.
    integer_only: bool,
    pub max_decimals: Option<u32>,
    /// Whether any limit on the digits applies (`max_digits` or the
    /// word's own format).
    pub digits_counted: bool,
    pub max_digits: Option<u32>,
    /// The most digits before the point, by the word's own format.
    pub integer_digits: Option<u32>,
}

impl WordLimits {
    /// Whether a word of this letter written `text` (letter and number),
    /// with or without a `point` and with `decimals` digits after it,
    /// breaks none of the limits: `Lexer::number_format` finds nothing.
    #[inline]
    pub fn allow(&self, text: &[u8], point: bool, decimals: usize) -> bool {
        if point && !self.point {
            return false;
        }
        if self.max_decimals.is_some_and(|max| decimals > max as usize) {
            return false;
        }
        if !self.digits_counted {
            return true;
        }
        let digits = significant_digits(text);
        !(self.max_digits.is_some_and(|max| digits > max as usize)
            || self
                .integer_digits
                .is_some_and(|most| digits.saturating_sub(decimals) > most as usize))
    }
}

/// The digits of a word after its letters, `=`, the sign and leading
/// zeros (byte by byte: every one of those characters is ASCII).
fn significant_digits(t: &[u8]) -> usize {
    let mut i = 0;
    while i < t.len() && (t[i].is_ascii_alphabetic() || matches!(t[i], b'=' | b'-' | b'+')) {
        i += 1;
    }
    while i < t.len() && t[i] == b'0' {
        i += 1;
    }
    t[i..].iter().filter(|b| b.is_ascii_digit()).count()
}

/// The Sinumerik cycles lensc reads: CYCLE832, high-speed settings
/// (tolerance, smoothing, compressor), which moves nothing.
const SIEMENS_CYCLES: &[&str] = &["CYCLE832"];

/// `832(…)` after `CYCLE` at `i`: the end of the cycle's number and the
/// end of the call (after its `)`), if its arguments are numbers
/// separated by commas.
fn cycle_call(code: &str, i: usize) -> Option<(usize, usize)> {
    let bytes = code.as_bytes();
    let mut j = i;
    while j < bytes.len() && bytes[j].is_ascii_digit() {
        j += 1;
    }
    if j == i || bytes.get(j) != Some(&b'(') {
        return None;
    }
    let close = j + code[j..].find(')')?;
    let args = &code[j + 1..close];
    args.split(',')
        .all(|a| a.trim().parse::<f64>().is_ok())
        .then_some((j, close + 1))
}

/// Whether a controller reads `letter` as a whole number only (a decimal
/// point in it is refused): block and program numbers and M codes
/// everywhere; Fanuc's S, T, D, H, P and L too (its manuals: "a decimal
/// point cannot be used" in these addresses).
fn integer_only(c: Controller, letter: char) -> bool {
    match letter {
        // LinuxCNC reads a line number with a point (`N56.78`) and an M
        // code within 0.0001 of a whole number (`M3.`, `M3.00001`; `M3.0001`
        // is "Non integer value for integer"): `Lexer::number_format`.
        'N' | 'M' if c == Controller::LinuxCnc => false,
        'N' | 'O' | 'M' => true,
        'T' => c != Controller::LinuxCnc,
        'S' | 'D' | 'H' | 'P' | 'L' => c == Controller::Fanuc,
        _ => false,
    }
}

fn unknown(span: (usize, usize), message: &str) -> Found {
    (Rule::UnknownWord, span, message.to_string(), None)
}

/// A number at `code[i..]`: sign, digits, a point, digits (at least one
/// digit). Returns (value, has a point, decimals) and where it ends.
#[inline(always)]
pub(crate) fn number(code: &str, mut i: usize) -> (Option<(f64, bool, usize)>, usize) {
    let bytes = code.as_bytes();
    let start = i;
    let negative = bytes.get(i) == Some(&b'-');
    if matches!(bytes.get(i), Some(b'+' | b'-')) {
        i += 1;
    }
    let mut digits = 0;
    let mut point = false;
    let mut decimals = 0;
    // The digits as a whole number, while they fit.
    let mut mantissa: u64 = 0;
    while let Some(&c) = bytes.get(i) {
        match c {
            b'0'..=b'9' => {
                digits += 1;
                if point {
                    decimals += 1;
                }
                if digits <= FAST_DIGITS {
                    mantissa = 10 * mantissa + u64::from(c - b'0');
                }
            }
            b'.' if !point => point = true,
            _ => break,
        }
        i += 1;
    }
    if digits == 0 {
        return (None, i);
    }
    let value = if digits <= FAST_DIGITS && decimals < POWERS_OF_TEN.len() {
        // Both exact in f64, so the one division rounds the quotient
        // correctly: the value `parse` gives (Clinger's fast path, which
        // `parse` takes for these too).
        // (A whole number is its own quotient by 10^0.)
        let v = if decimals == 0 {
            mantissa as f64
        } else {
            mantissa as f64 / POWERS_OF_TEN[decimals]
        };
        Some(if negative { -v } else { v })
    } else {
        code[start..i].parse::<f64>().ok()
    };
    (value.map(|v| (v, point, decimals)), i)
}

/// Digits a number may have for its value to be read exactly as a whole
/// number (10^15 < 2^53).
const FAST_DIGITS: usize = 15;

/// 10^0 … 10^22, each exact in f64.
const POWERS_OF_TEN: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

#[cfg(test)]
mod tests {
    use super::*;

    /// Every Siemens word is in `ALL`, at its place, and reads back from
    /// its name (the match in `name` is exhaustive, so a new word needs
    /// one; the reader's matches over keywords are too).
    #[test]
    fn every_siemens_word_reads_back_from_its_name() {
        assert_eq!(SiemensWord::ALL.len(), SiemensWord::Pw as usize + 1);
        for (i, w) in SiemensWord::ALL.into_iter().enumerate() {
            assert_eq!(w as usize, i);
            assert_eq!(SiemensWord::of(w.name()), Some(w));
        }
        assert_eq!(SiemensWord::of("DIAMOND"), None);
    }

    /// Every number the fast path reads is the value `parse` gives, bit
    /// for bit (signs, zeros, a point at either end, 15 digits), and the
    /// longer ones are `parse`'s own.
    #[test]
    fn numbers_read_as_parse_reads_them() {
        let mut texts: Vec<String> = [
            "0",
            "-0",
            "+0",
            "-0.0",
            "0.",
            ".5",
            "-.5",
            "5.",
            "1.5",
            "-12.3456",
            "+7.25",
            "999999999999999",
            "99999999999999.9",
            "0.000000000000001",
            "123456789012345",
            "1234567890123456",
            "0.1234567890123456789",
            "12345678901234567890.5",
            "0.0000000000000000000001",
            "0.00000000000000000000001",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        // Pseudo-random numbers as the writer prints them, 0 to 6 decimals.
        let mut r: u64 = 0x9e37_79b9_7f4a_7c15;
        for _ in 0..2_000_000 {
            r ^= r << 13;
            r ^= r >> 7;
            r ^= r << 17;
            let whole = (r >> 20) % 10u64.pow((r % 9) as u32 + 1);
            let decimals = (r >> 8) % 7;
            let sign = if r & 1 == 1 { "-" } else { "" };
            let t = whole.to_string();
            let d = decimals as usize;
            let t = if d == 0 {
                t
            } else if t.len() > d {
                format!("{}.{}", &t[..t.len() - d], &t[t.len() - d..])
            } else {
                format!("0.{:0>d$}", t)
            };
            texts.push(format!("{sign}{t}"));
        }
        for t in &texts {
            let code = format!("X{t} ");
            let (got, end) = number(&code, 1);
            assert_eq!(end, code.len() - 1, "{t}");
            let (v, point, decimals) = got.expect("a number");
            let want: f64 = t.parse().expect("parses");
            assert_eq!(v.to_bits(), want.to_bits(), "{t}: {v:e} against {want:e}");
            assert_eq!(point, t.contains('.'), "{t}");
            let after = t.split_once('.').map_or(0, |(_, d)| d.len());
            assert_eq!(decimals, after, "{t}");
        }
        assert_eq!(number("X-.", 1).0, None);
        assert_eq!(number("X+", 1).0, None);
    }

    /// Every number of every program snapshot (each dialect's, every
    /// example's head or whole program; about 190 k numbers) reads as
    /// `parse` reads it; and of the programs `LENSC_NUMBERS_OF` names
    /// (paths separated by `:`), such as the big examples' whole programs.
    #[test]
    fn every_number_lensc_writes_reads_as_parse_reads_it() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/snapshots");
        let mut files = Vec::new();
        for dir in ["programs", "dialects"] {
            for e in std::fs::read_dir(root.join(dir)).expect("snapshots") {
                files.push(e.expect("entry").path());
            }
        }
        if let Ok(more) = std::env::var("LENSC_NUMBERS_OF") {
            files.extend(more.split(':').map(std::path::PathBuf::from));
        }
        let mut read = 0;
        for path in files {
            let text = std::fs::read_to_string(&path).expect("read");
            let b = text.as_bytes();
            for i in 1..b.len() {
                if !b[i - 1].is_ascii_alphabetic()
                    || !(b[i].is_ascii_digit() || matches!(b[i], b'-' | b'+' | b'.'))
                {
                    continue;
                }
                let (Some((v, _, _)), end) = number(&text, i) else {
                    continue;
                };
                let want: f64 = text[i..end].parse().expect("parses");
                assert_eq!(v.to_bits(), want.to_bits(), "{}", &text[i..end]);
                read += 1;
            }
        }
        println!("{read} numbers read as parse reads them");
        assert!(read > 100_000, "{read} numbers");
    }
}
