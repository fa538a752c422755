//! What the text around a cursor is, read from the text itself rather
//! than the syntax tree: an editor asks while the user is typing, when the
//! item under the cursor rarely parses. A small scanner (comments and
//! strings skipped) follows the brackets open at the cursor, what each
//! belongs to (`raster {`, `circle(`, `job j {`, `simulate: {`), and
//! whether the cursor stands where a parameter's name or its value goes.

/// What an open bracket belongs to.
#[derive(Clone, Debug, PartialEq)]
pub enum Owner {
    /// `NAME {` or `NAME(`: a kind, a declaration it copies, or a function.
    Name(String),
    /// `job NAME {`.
    Job,
    /// `param: {`: a nested block of the enclosing owner's parameter.
    Param(String),
    /// A list, a parenthesis, anything else.
    Other,
}

#[derive(Clone, Debug)]
pub struct Frame {
    pub owner: Owner,
    /// Whether the next word is an entry's name (`{`, `(`, after `,`).
    pub at_name: bool,
    /// The parameter whose value is being written, after `name:`.
    pub param: Option<String>,
    /// Which bracket this is: the count of brackets opened before it.
    pub id: usize,
}

/// The cursor's surroundings.
#[derive(Clone, Debug, Default)]
pub struct Context {
    /// The brackets open at the cursor, outermost first.
    pub frames: Vec<Frame>,
    /// Inside a comment or a string: nothing to offer.
    pub in_trivia: bool,
    /// The word being typed, up to the cursor, and where it starts.
    pub word: String,
    pub word_start: usize,
    /// The token before the word is a number: a unit goes here.
    pub after_number: bool,
    /// At the top level where an item's keyword goes (nothing else yet on
    /// this item).
    pub item_start: bool,
    /// The text of the line up to the cursor.
    pub line: String,
}

impl Context {
    /// The innermost frame, if inside any bracket.
    pub fn frame(&self) -> Option<&Frame> {
        self.frames.last()
    }
}

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    /// A word and where it starts.
    Word(String, usize),
    Number,
    Punct(char),
}

fn is_word_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_' || matches!(c, 'µ' | 'μ' | '°')
}

/// The context at byte `offset` of `text`.
pub fn at(text: &str, offset: usize) -> Context {
    let mut offset = offset.min(text.len());
    while !text.is_char_boundary(offset) {
        offset -= 1;
    }
    let before = &text[..offset];
    let mut cx = Context {
        line: before.rsplit('\n').next().unwrap_or("").to_string(),
        ..Context::default()
    };
    // The word being typed: word characters just before the cursor.
    cx.word_start = before
        .char_indices()
        .rev()
        .take_while(|(_, c)| is_word_char(*c))
        .last()
        .map_or(offset, |(i, _)| i);
    cx.word = before[cx.word_start..].to_string();
    let s = scan(text, cx.word_start);
    cx.frames = s.frames;
    cx.in_trivia = s.in_trivia;
    cx.after_number =
        s.last == Some(Tok::Number) && !text[..cx.word_start].ends_with('\n') && !cx.in_trivia;
    // At the top level an item starts at a keyword on a fresh line.
    cx.item_start = cx.frames.is_empty() && cx.line.trim_start() == cx.word;
    cx
}

/// Every `name:` of every block and call in `text`: the bracket it is
/// written in (`Frame::id`), the name and where it starts.
pub fn entries(text: &str) -> Vec<(usize, String, usize)> {
    scan(text, text.len()).entries
}

/// What a scan of `text[..end]` found.
#[derive(Default)]
struct Scan {
    frames: Vec<Frame>,
    /// `end` is inside a comment or a string.
    in_trivia: bool,
    last: Option<Tok>,
    /// The token before `last`.
    prev: Option<Tok>,
    /// Brackets opened so far: the next frame's id.
    opened: usize,
    entries: Vec<(usize, String, usize)>,
}

fn scan(text: &str, end: usize) -> Scan {
    let mut s = Scan::default();
    let mut chars = text[..end].char_indices().peekable();
    while let Some((i, c)) = chars.next() {
        let rest = &text[i..end];
        if rest.starts_with("//") {
            match rest.find('\n') {
                Some(n) => skip_to(&mut chars, i + n),
                None => {
                    s.in_trivia = true;
                    break;
                }
            }
            continue;
        }
        if let Some(inner) = rest.strip_prefix("/*") {
            match inner.find("*/") {
                Some(n) => skip_to(&mut chars, i + 2 + n + 2),
                None => {
                    s.in_trivia = true;
                    break;
                }
            }
            continue;
        }
        if c == '"' {
            let mut closed = false;
            while let Some((_, d)) = chars.next() {
                match d {
                    '\\' => {
                        chars.next();
                    }
                    '"' | '\n' => {
                        closed = true;
                        break;
                    }
                    _ => {}
                }
            }
            if !closed {
                s.in_trivia = true;
                break;
            }
            s.tok(Tok::Punct('"'));
            continue;
        }
        if c == '\n' {
            newline(&mut s.frames, s.last.as_ref());
            continue;
        }
        if c.is_whitespace() {
            continue;
        }
        if c.is_ascii_digit() {
            while let Some(&(j, d)) = chars.peek() {
                if d.is_ascii_digit() || d == '.' {
                    chars.next();
                } else if d == 'e' || d == 'E' {
                    // An exponent only if a digit (or sign) follows.
                    let next = text[j + 1..].chars().next();
                    if next.is_some_and(|n| n.is_ascii_digit() || n == '+' || n == '-') {
                        chars.next();
                        chars.next();
                    } else {
                        break;
                    }
                } else {
                    break;
                }
            }
            s.tok(Tok::Number);
            continue;
        }
        if is_word_char(c) {
            let mut w_end = i + c.len_utf8();
            while let Some(&(j, d)) = chars.peek() {
                if !is_word_char(d) {
                    break;
                }
                w_end = j + d.len_utf8();
                chars.next();
            }
            s.tok(Tok::Word(text[i..w_end].to_string(), i));
            continue;
        }
        punct(&mut s, c);
        s.tok(Tok::Punct(c));
    }
    s
}

fn skip_to(chars: &mut std::iter::Peekable<std::str::CharIndices<'_>>, end: usize) {
    while chars.peek().is_some_and(|(j, _)| *j < end) {
        chars.next();
    }
}

/// A line break ends a block entry unless the line ends in an operator.
fn newline(frames: &mut [Frame], last: Option<&Tok>) {
    let continues = matches!(
        last,
        Some(Tok::Punct(
            '+' | '-' | '*' | '/' | '^' | ':' | '=' | '(' | '['
        ))
    );
    if let Some(f) = frames.last_mut()
        && f.owner != Owner::Other
        && !continues
    {
        f.at_name = true;
        f.param = None;
    }
}

fn punct(s: &mut Scan, c: char) {
    let word = match &s.last {
        Some(Tok::Word(w, at)) => Some((w.clone(), *at)),
        _ => None,
    };
    match c {
        '{' | '(' => {
            let owner = match (&word, s.frames.last()) {
                (Some(_), _) if c == '{' && s.job_name_follows() => Owner::Job,
                (Some((w, _)), _) => Owner::Name(w.clone()),
                (None, Some(f)) if c == '{' && s.last == Some(Tok::Punct(':')) => {
                    f.param.clone().map_or(Owner::Other, Owner::Param)
                }
                _ => Owner::Other,
            };
            let at_name = owner != Owner::Other;
            s.push(owner, at_name);
        }
        '[' => s.push(Owner::Other, false),
        '}' | ')' | ']' => {
            s.frames.pop();
        }
        ':' => {
            if let Some(f) = s.frames.last_mut()
                && f.at_name
            {
                f.at_name = false;
                f.param = word.as_ref().map(|(w, _)| w.clone());
                if let Some((w, at)) = word {
                    s.entries.push((f.id, w, at));
                }
            }
        }
        ',' => {
            if let Some(f) = s.frames.last_mut()
                && f.owner != Owner::Other
            {
                f.at_name = true;
                f.param = None;
            }
        }
        '=' => {
            if let Some(f) = s.frames.last_mut() {
                f.at_name = false;
            }
        }
        _ => {}
    }
}

impl Scan {
    fn push(&mut self, owner: Owner, at_name: bool) {
        self.frames.push(Frame {
            owner,
            at_name,
            param: None,
            id: self.opened,
        });
        self.opened += 1;
    }

    fn tok(&mut self, t: Tok) {
        self.prev = self.last.replace(t);
    }

    /// Whether the word just read is a job's name (`job NAME {`).
    fn job_name_follows(&self) -> bool {
        matches!(&self.prev, Some(Tok::Word(w, _)) if w == "job")
    }
}

/// The word around byte `offset` (the cursor inside it or just after it)
/// and where it starts.
pub fn word_around(text: &str, offset: usize) -> Option<(usize, &str)> {
    let mut offset = offset.min(text.len());
    while !text.is_char_boundary(offset) {
        offset -= 1;
    }
    let start = text[..offset]
        .char_indices()
        .rev()
        .take_while(|(_, c)| is_word_char(*c))
        .last()
        .map_or(offset, |(i, _)| i);
    let end = offset
        + text[offset..]
            .char_indices()
            .take_while(|(_, c)| is_word_char(*c))
            .last()
            .map_or(0, |(i, c)| i + c.len_utf8());
    (end > start).then(|| (start, &text[start..end]))
}

/// Whether the word ending at `end` is followed by `:` (not `::`): a
/// parameter's name.
pub fn names_a_parameter(text: &str, end: usize) -> bool {
    let rest = text[end..].trim_start_matches([' ', '\t']);
    rest.starts_with(':') && !rest.starts_with("::")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cx(text: &str) -> Context {
        let at_cursor = text.find('|').expect("a cursor");
        let t = text.replace('|', "");
        at(&t, at_cursor)
    }

    #[test]
    fn a_parameter_name_inside_a_kinds_block() {
        let c = cx("strategy s = raster {\n    along: x\n    st|\n}");
        let f = c.frame().expect("in a block");
        assert_eq!(f.owner, Owner::Name("raster".into()));
        assert!(f.at_name);
        assert_eq!(c.word, "st");
        let c = cx("strategy s = raster { along: x, feed: 1|");
        assert!(!c.frame().expect("block").at_name);
        assert_eq!(c.frame().expect("block").param.as_deref(), Some("feed"));
    }

    #[test]
    fn nested_blocks_jobs_and_calls() {
        let c = cx("job j {\n  simulate: {\n    x: 0 mm .. 1 mm\n    sp|");
        assert_eq!(c.frames[0].owner, Owner::Job);
        assert_eq!(
            c.frame().expect("block").owner,
            Owner::Param("simulate".into())
        );
        let c = cx("surface s = conic { aperture: circle(dia|");
        assert_eq!(c.frame().expect("call").owner, Owner::Name("circle".into()));
        assert!(c.frame().expect("call").at_name);
    }

    #[test]
    fn units_after_a_number_and_nothing_in_comments_or_strings() {
        let c = cx("tool t = round_nose { nose_radius: 85 u|");
        assert!(c.after_number);
        assert_eq!(c.word, "u");
        let c = cx("tool t = round_nose { nose_radius: 1.5e-3 |");
        assert!(c.after_number);
        let c = cx("tool t = round_nose { // a { b: 1 |");
        assert!(c.in_trivia);
        let c = cx("use \"com|");
        assert!(c.in_trivia);
        let c = cx("/* { */ tool t = round_nose { nose_radius: 1 mm }\nsur|");
        assert!(c.frames.is_empty() && c.item_start);
    }

    #[test]
    fn the_word_around_a_cursor() {
        let t = "feed: 100 µm/min";
        assert_eq!(word_around(t, 2), Some((0, "feed")));
        assert_eq!(word_around(t, 4), Some((0, "feed")));
        assert!(names_a_parameter(t, 4));
        let mu = t.find('µ').expect("µ");
        assert_eq!(word_around(t, mu + 2), Some((mu, "µm")));
        assert_eq!(word_around("a : : b", 3), None);
    }
}
