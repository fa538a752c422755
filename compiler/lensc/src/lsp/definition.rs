//! Go to definition: a name to where it is declared, in the document, in
//! a file it uses or in the standard library (its cached copy); a `use
//! std::MODULE::ITEM` segment to the module or the item; a `use
//! "file.lens"` to the file.

use lensc_grammar::ast::{ItemKind, Span, UseTarget};
use lensc_lang::loader::Import;
use lsp_types::{Location, Uri};

use super::analysis::{self, Analysis};
use super::context;

/// Where the thing at byte `offset` of the document is declared.
pub fn definition(a: &Analysis, doc_uri: &Uri, text: &str, offset: usize) -> Option<Location> {
    if let Some(loc) = in_use(a, doc_uri, offset) {
        return Some(loc);
    }
    let (start, word) = context::word_around(text, offset)?;
    let cx = context::at(text, start);
    if cx.in_trivia
        || cx.after_number
        || (cx.frame().is_some_and(|f| f.at_name)
            && context::names_a_parameter(text, start + word.len()))
    {
        return None;
    }
    let (file, span) = analysis::declaration(a, word)?;
    analysis::location(a, doc_uri, file, span)
}

/// The cursor on a `use` item of the document: the file or item it names.
fn in_use(a: &Analysis, doc_uri: &Uri, offset: usize) -> Option<Location> {
    let root = a.checked.loaded.files.first()?;
    let inside = |s: Span| (s.start as usize..=s.end as usize).contains(&offset);
    let (target, span) = root.ast.items.iter().find_map(|i| match &i.kind {
        ItemKind::Use(t) if inside(i.span) => Some((t, i.span)),
        _ => None,
    })?;
    // The file this `use` brought in, as the loader recorded it.
    let file = root.imports.iter().find_map(|imp| match imp {
        Import::All { file, span: s } if *s == span => Some(*file),
        Import::One { file, name } if span.to(name.span) == span => Some(*file),
        _ => None,
    })?;
    match target {
        UseTarget::Std(segs) => {
            if let Some(item) = segs.get(2).filter(|s| inside(s.span)) {
                let at = analysis::declared_in(a, file, &item.name)?;
                return analysis::location(a, doc_uri, file, at);
            }
            analysis::location(a, doc_uri, file, Span::new(0, 0))
        }
        UseTarget::File { .. } => analysis::location(a, doc_uri, file, Span::new(0, 0)),
    }
}
