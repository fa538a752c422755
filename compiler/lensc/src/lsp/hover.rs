//! Hover: what the word under the cursor is. A parameter's name shows its
//! documentation, dimension, unit, allowed range and default; a kind its
//! documentation and parameters; a `let` its value as the checker
//! evaluated it, with its unit; a declaration or standard-library item
//! what it is and its documentation; a unit its dimension and size.

use lensc_grammar::ast::ItemKind;
use lensc_lang::check::{FUNCTIONS, trim_num};
use lensc_lang::{schema, stdlib, units};

use super::analysis::{self, Analysis};
use super::context;
use super::lookup::{kind_markdown, param_in, param_markdown, params_at, stdlib_markdown};
use crate::commands::list::value_text;

/// The Markdown for the word at byte `offset` of `text`, and the word's span.
pub fn hover(a: Option<&Analysis>, text: &str, offset: usize) -> Option<(String, usize, usize)> {
    let (start, word) = context::word_around(text, offset)?;
    let end = start + word.len();
    let cx = context::at(text, start);
    if cx.in_trivia {
        return None;
    }
    let md = if cx.after_number {
        unit_markdown(word)?
    } else if cx.frame().is_some_and(|f| f.at_name) && context::names_a_parameter(text, end) {
        let (params, kind) = params_at(a, &cx.frames)?;
        param_markdown(param_in(params, kind, word)?)
    } else {
        name_markdown(a, word)?
    };
    Some((md, start, end))
}

fn unit_markdown(word: &str) -> Option<String> {
    let u = units::lookup(word)?;
    let (unit, factor) = u.dim.display_unit();
    let size = if unit.is_empty() || u.name == unit {
        String::new()
    } else {
        format!(": 1 {} = {} {unit}", u.name, trim_num(u.factor * factor))
    };
    Some(format!("**{}** — a unit of {}{size}", u.name, u.dim))
}

/// A name in a value: a `let`, a declaration, a kind, a standard-library
/// item not yet used, a function.
fn name_markdown(a: Option<&Analysis>, word: &str) -> Option<String> {
    if let Some(a) = a
        && let Some((file, span)) = analysis::declaration(a, word)
    {
        if let Some((.., v)) = a
            .checked
            .checked
            .lets
            .iter()
            .find(|(f, s, _)| *f == file && *s == span)
        {
            return Some(format!(
                "```lens\nlet {word} = {}\n```\n{}",
                value_text(v),
                v.describe()
            ));
        }
        let src = a.checked.loaded.sources.get(file);
        if src.path.is_none()
            && let Some(item) = stdlib::find(word)
        {
            return Some(stdlib_markdown(item));
        }
        let item = a
            .checked
            .loaded
            .file(file)
            .ast
            .items
            .iter()
            .find_map(|i| match &i.kind {
                ItemKind::Let { name, .. } if name.span == span => Some(("let".to_string(), None)),
                ItemKind::Decl { kind, name, .. } if name.span == span => Some((
                    kind.keyword().to_string(),
                    a.checked.checked.declarations.get(word),
                )),
                _ => None,
            })?;
        let made = item
            .1
            .map_or(String::new(), |o| format!(" = {} {{ … }}", o.kind.name));
        let mut md = format!(
            "```lens\n{} {word}{made}\n```\ndeclared in `{}`",
            item.0, src.name
        );
        if let Some(o) = item.1 {
            md.push_str(&format!("\n\n{}", o.kind.doc));
        }
        return Some(md);
    }
    if let Some(k) = schema::kind(word) {
        return Some(kind_markdown(k));
    }
    if let Some(item) = stdlib::find(word) {
        return Some(stdlib_markdown(item));
    }
    if FUNCTIONS.contains(&word) {
        return Some(format!("**{word}** — a built-in math function"));
    }
    None
}
