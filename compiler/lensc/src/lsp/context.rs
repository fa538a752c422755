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
    Word(String),
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
    let mut toks: Vec<Tok> = Vec::new();
    let mut chars = text[..cx.word_start].char_indices().peekable();
    while let Some((i, c)) = chars.next() {
        let rest = &text[i..cx.word_start];
        if rest.starts_with("//") {
            match rest.find('\n') {
                Some(n) => skip_to(&mut chars, i + n),
                None => {
                    cx.in_trivia = true;
                    break;
                }
            }
            continue;
        }
        if rest.starts_with("/*") {
            match rest[2..].find("*/") {
                Some(n) => skip_to(&mut chars, i + 2 + n + 2),
                None => {
                    cx.in_trivia = true;
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
                cx.in_trivia = true;
                break;
            }
            toks.push(Tok::Punct('"'));
            continue;
        }
        if c == '\n' {
            newline(&mut cx.frames, toks.last());
            continue;
        }
        if c.is_whitespace() {
            continue;
        }
        if c.is_ascii_digit() {
            while let Some(&(_, d)) = chars.peek() {
                if d.is_ascii_digit() || d == '.' {
                    chars.next();
                } else if d == 'e' || d == 'E' {
                    // An exponent only if a digit (or sign) follows.
                    let j = chars.peek().map_or(0, |(j, _)| *j);
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
            toks.push(Tok::Number);
            continue;
        }
        if is_word_char(c) {
            let mut end = i + c.len_utf8();
            while let Some(&(j, d)) = chars.peek() {
                if !is_word_char(d) {
                    break;
                }
                end = j + d.len_utf8();
                chars.next();
            }
            let w = text[i..end].to_string();
            toks.push(Tok::Word(w));
            continue;
        }
        punct(&mut cx.frames, &toks, c);
        toks.push(Tok::Punct(c));
    }
    cx.after_number = toks.last() == Some(&Tok::Number)
        && !text[..cx.word_start].ends_with('\n')
        && !cx.in_trivia;
    // At the top level an item starts at a keyword on a fresh line.
    cx.item_start = cx.frames.is_empty() && cx.line.trim_start() == cx.word;
    cx
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

fn punct(frames: &mut Vec<Frame>, toks: &[Tok], c: char) {
    let word = |k: usize| match toks.len().checked_sub(k).and_then(|i| toks.get(i)) {
        Some(Tok::Word(w)) => Some(w.as_str()),
        _ => None,
    };
    match c {
        '{' | '(' => {
            let owner = match (word(1), word(2)) {
                (Some(_), Some("job")) if c == '{' => Owner::Job,
                (Some(w), _) => Owner::Name(w.to_string()),
                _ if c == '{' && toks.last() == Some(&Tok::Punct(':')) => {
                    let p = frames.last().and_then(|f| f.param.clone());
                    p.map_or(Owner::Other, Owner::Param)
                }
                _ => Owner::Other,
            };
            let at_name = owner != Owner::Other;
            frames.push(Frame {
                owner,
                at_name,
                param: None,
            });
        }
        '[' => frames.push(Frame {
            owner: Owner::Other,
            at_name: false,
            param: None,
        }),
        '}' | ')' | ']' => {
            frames.pop();
        }
        ':' => {
            if let Some(f) = frames.last_mut()
                && f.at_name
            {
                f.at_name = false;
                f.param = word(1).map(str::to_string);
            }
        }
        ',' => {
            if let Some(f) = frames.last_mut()
                && f.owner != Owner::Other
            {
                f.at_name = true;
                f.param = None;
            }
        }
        '=' => {
            if let Some(f) = frames.last_mut() {
                f.at_name = false;
            }
        }
        _ => {}
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
