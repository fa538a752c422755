//! The long explanation of every diagnostic code, as `lensc explain CODE`
//! prints it: one Markdown file per code in `compiler/lang/explain/`
//! (gathered by `build.rs`), each with a title line, what the code means
//! and what to write instead, and examples. A fenced block marked
//! ```` ```lens error ```` is a file `lensc check` or `lensc build` answers
//! with that code; ```` ```lens fix ```` is the same file corrected. Words
//! after `error`/`fix` starting with `--` are passed to `lensc build`
//! (`--dialect=heidenhain_iso`). The test suite checks both.

use lensc_grammar::diagnostic::codes as syntax_codes;

use crate::codes;

/// `(code, Markdown text)`, by code.
static EXPLANATIONS: &[(&str, &str)] = include!(concat!(env!("OUT_DIR"), "/explanations.rs"));

/// Every code lensc emits: the syntax codes, then the compiler's.
pub fn every_code() -> impl Iterator<Item = &'static str> {
    syntax_codes::ALL.iter().chain(codes::ALL).copied()
}

/// Every explanation there is, by code.
pub fn all() -> &'static [(&'static str, &'static str)] {
    EXPLANATIONS
}

/// The long explanation of `code` (`E0147`, `e0147` or `147`), if it has one.
pub fn explain(code: &str) -> Option<(&'static str, &'static str)> {
    let code = normalise(code)?;
    EXPLANATIONS.iter().copied().find(|(c, _)| *c == code)
}

/// `e147`, `147`, `E0147` → `E0147`; `w5` → `W0005`.
fn normalise(code: &str) -> Option<String> {
    let code = code.trim();
    let (letter, digits) = match code.chars().next()? {
        c if c.is_ascii_alphabetic() => (c.to_ascii_uppercase(), &code[1..]),
        _ => ('E', code),
    };
    let n: u32 = digits.parse().ok()?;
    (n < 10_000).then(|| format!("{letter}{n:04}"))
}

/// The title: the first line, without its `# CODE: ` prefix.
pub fn title(text: &str) -> &str {
    let first = text
        .lines()
        .next()
        .unwrap_or("")
        .trim_start_matches('#')
        .trim();
    first.split_once(": ").map_or(first, |(_, t)| t)
}

/// What an example is meant to show.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Expect {
    /// `lensc check` or `lensc build` reports the code.
    Error,
    /// The corrected file: the code is not reported.
    Fix,
}

/// One fenced `lens` example of an explanation.
#[derive(Clone, Debug, PartialEq)]
pub struct Example {
    pub expect: Expect,
    /// Arguments for `lensc build` (`--dialect=…`).
    pub args: Vec<String>,
    pub source: String,
}

/// The `lens error` and `lens fix` examples of an explanation, in order.
pub fn examples(text: &str) -> Vec<Example> {
    let mut out = Vec::new();
    let mut lines = text.lines();
    while let Some(line) = lines.next() {
        let Some(info) = line.trim().strip_prefix("```") else {
            continue;
        };
        let mut words = info.split_whitespace();
        let lens = words.next() == Some("lens");
        let expect = match words.next() {
            Some("error") if lens => Some(Expect::Error),
            Some("fix") if lens => Some(Expect::Fix),
            _ => None,
        };
        let args = words.map(str::to_string).collect();
        let mut source = String::new();
        for l in lines.by_ref() {
            if l.trim_start().starts_with("```") {
                break;
            }
            source.push_str(l);
            source.push('\n');
        }
        if let Some(expect) = expect {
            out.push(Example {
                expect,
                args,
                source,
            });
        }
    }
    out
}

/// The text for a terminal: fences keep their language, not the test's
/// marks (`lens error --dialect=x` → `lens`), and the note for the test
/// that an explanation has no `lens` example is left out.
pub fn for_terminal(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for line in text.lines() {
        if line.starts_with("<!-- no lens example: ") {
            continue;
        }
        match line.trim_start().strip_prefix("```") {
            Some(info) if !info.is_empty() => {
                out.push_str("```");
                out.push_str(info.split_whitespace().next().unwrap_or(""));
            }
            _ => out.push_str(line),
        }
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_are_found_however_written() {
        for asked in ["E0147", "e0147", "147", "E147"] {
            assert_eq!(explain(asked).map(|(c, _)| c), Some("E0147"), "{asked}");
        }
        assert_eq!(normalise("w5").as_deref(), Some("W0005"));
        assert_eq!(explain("E9999"), None);
        assert_eq!(explain("nonsense"), None);
    }

    #[test]
    fn examples_and_their_marks_are_read() {
        let text = "# E0001: x\n\n```lens error --dialect=a\nlet a =\n```\n\n```console\n$ x\n```\n```lens fix\nlet a = 1\n```\n";
        let ex = examples(text);
        assert_eq!(ex.len(), 2);
        assert_eq!(ex[0].expect, Expect::Error);
        assert_eq!(ex[0].args, ["--dialect=a"]);
        assert_eq!(ex[0].source, "let a =\n");
        assert_eq!(ex[1].expect, Expect::Fix);
        assert_eq!(title(text), "x");
        assert!(for_terminal(text).contains("```lens\nlet a =\n"));
    }
}
