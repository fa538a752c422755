//! The comments of a source file, found once, and the questions the
//! printer asks of the text between tokens: is there a comment here, a
//! line break, a blank line, where does the next token start.

/// One comment: `// …` (to the end of its line, the line break not
/// included) or `/* … */`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Comment {
    pub start: usize,
    pub end: usize,
    /// `// …`: whatever follows it must start a new line.
    pub line: bool,
}

/// A source file's text and its comments in order.
pub(super) struct Trivia<'s> {
    pub src: &'s str,
    pub comments: Vec<Comment>,
}

impl<'s> Trivia<'s> {
    /// Finds every comment outside strings (the file has parsed, so every
    /// `//` and `/*` outside a string opens one).
    pub fn new(src: &'s str) -> Trivia<'s> {
        let b = src.as_bytes();
        let mut comments = Vec::new();
        let mut i = 0;
        while i < b.len() {
            match b[i] {
                b'"' => {
                    i += 1;
                    while i < b.len() && b[i] != b'"' {
                        i += if b[i] == b'\\' { 2 } else { 1 };
                    }
                    i += 1;
                }
                b'/' if b.get(i + 1) == Some(&b'/') => {
                    let start = i;
                    while i < b.len() && b[i] != b'\n' {
                        i += 1;
                    }
                    comments.push(Comment {
                        start,
                        end: i,
                        line: true,
                    });
                }
                b'/' if b.get(i + 1) == Some(&b'*') => {
                    let start = i;
                    i += 2;
                    while i < b.len() && !(b[i] == b'*' && b.get(i + 1) == Some(&b'/')) {
                        i += 1;
                    }
                    i = (i + 2).min(b.len());
                    comments.push(Comment {
                        start,
                        end: i,
                        line: false,
                    });
                }
                _ => i += 1,
            }
        }
        Trivia { src, comments }
    }

    /// The comment as it is printed: a line comment without trailing
    /// blanks, a block comment as written (with `\n` line breaks).
    pub fn text(&self, c: Comment) -> String {
        let t = &self.src[c.start..c.end];
        if c.line {
            t.trim_end().to_string()
        } else {
            t.replace("\r\n", "\n")
        }
    }

    /// Line breaks in `src[a..b]` (none if the range is empty or reversed).
    pub fn newlines(&self, a: usize, b: usize) -> usize {
        self.src
            .get(a..b)
            .map_or(0, |s| s.bytes().filter(|&c| c == b'\n').count())
    }

    /// Whether a comment starts inside `a..b`.
    pub fn has_comment(&self, a: usize, b: usize) -> bool {
        let i = self.comments.partition_point(|c| c.start < a);
        self.comments.get(i).is_some_and(|c| c.start < b)
    }

    /// Whether `a..b` must be laid out one element a line: its author
    /// broke it over lines, or a comment inside needs lines of its own.
    pub fn broken(&self, a: usize, b: usize) -> bool {
        self.newlines(a, b) > 0 || self.has_comment(a, b)
    }

    /// The first position at or after `pos` that is neither white space
    /// nor inside a comment.
    pub fn skip_forward(&self, mut pos: usize) -> usize {
        loop {
            let rest = &self.src[pos..];
            let trimmed = rest.trim_start_matches(is_blank);
            pos += rest.len() - trimmed.len();
            let i = self.comments.partition_point(|c| c.start < pos);
            match self.comments.get(i) {
                Some(c) if c.start == pos => pos = c.end,
                _ => return pos,
            }
        }
    }

    /// The last position at or before `pos` that ends a token: white space
    /// and comments before `pos` skipped.
    pub fn skip_back(&self, mut pos: usize) -> usize {
        loop {
            let head = &self.src[..pos];
            pos = head.trim_end_matches(is_blank).len();
            // A line comment's trailing blanks are part of it.
            let i = self.comments.partition_point(|c| c.end < pos);
            match self.comments.get(i) {
                Some(c) if c.start < pos => pos = c.start,
                _ => return pos,
            }
        }
    }
}

/// What the grammar skips between tokens besides comments.
fn is_blank(c: char) -> bool {
    matches!(c, ' ' | '\t' | '\r' | '\n' | '\u{FEFF}')
}
