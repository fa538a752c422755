//! `lensc fmt`'s one canonical layout of a `.lens` file (also what a
//! language server's formatting request answers): items at the left
//! margin, four spaces a level, one space around `=` and operators and
//! after `:` (but `10 rad/(3 mm)`, a quantity over a bracketed one, is
//! written as the compound unit it reads as), a number and its unit one
//! space apart (`7°` together), each block, list and call on
//! one line (`{ a: 1, b: 2 }`, `[a, b]`, `f(a, b)`) unless its author
//! broke it over lines or a comment inside needs a line, then one element
//! a line (block entries without commas, list elements and arguments with
//! one after each). Blank lines are kept, at most one in a row; every
//! comment stays where it was, own-line or trailing. Parentheses are kept
//! as written. The result is checked to parse to the same tree as the
//! input, and formatting it again changes nothing.

mod print;
mod same;
mod trivia;

use lensc_grammar::{Diagnostic, FileId, Span};

use crate::codes;

/// The file in the canonical layout, or the syntax errors that keep it
/// from being formatted (the parser's own diagnostics, for `FileId(0)`).
pub fn format_source(text: &str) -> Result<String, Vec<Diagnostic>> {
    let (tree, diags) = lensc_grammar::parse(text, FileId(0));
    if diags.iter().any(Diagnostic::is_error) {
        return Err(diags);
    }
    let trivia = trivia::Trivia::new(text);
    let formatted = print::Printer::new(&trivia).file(&tree);
    // The formatter never changes what a file means: what it wrote must
    // parse to the same tree, with as many comments.
    let (again, diags) = lensc_grammar::parse(&formatted, FileId(0));
    if diags.iter().any(Diagnostic::is_error)
        || !same::files(&tree, &again)
        || trivia::Trivia::new(&formatted).comments.len() != trivia.comments.len()
    {
        return Err(vec![
            Diagnostic::error(
                codes::FORMAT_WOULD_CHANGE_MEANING,
                "lensc fmt cannot format this file without changing what it means",
                FileId(0),
                Span::new(0, 0),
            )
            .with_label("the file is left as it is")
            .with_help("this is a bug in lensc fmt: please report it with the file"),
        ]);
    }
    Ok(formatted)
}

#[cfg(test)]
mod tests;
