//! The document's names as an editor navigates them: its outline
//! (document symbols: `let`s, declarations, jobs and a job's entries),
//! every reference to a name across the files it uses (each file's own
//! resolution of the name, a formula's parameters shadowing it), and
//! renaming one (refused for the standard library's read-only items and
//! for a new name that is not a name or is taken).

use std::collections::HashMap;

use lensc_grammar::FileId;
use lensc_grammar::ast::{Block, DeclKind, Entry, Expr, ExprKind, ItemKind, Span, UseTarget};
use lensc_lang::loader::Import;
use lsp_types::{self as lsp, DocumentSymbol, SymbolKind, Uri};

use super::analysis::{self, Analysis};
use super::context;
use super::text::LineIndex;

/// The document's outline.
#[allow(deprecated)] // `DocumentSymbol::deprecated` must still be given.
pub fn outline(a: &Analysis, text: &str) -> Vec<DocumentSymbol> {
    let ix = LineIndex::new(text);
    let symbol = |name: &str, detail: Option<String>, kind, whole: Span, at: Span, children| {
        DocumentSymbol {
            name: name.to_string(),
            detail,
            kind,
            tags: None,
            deprecated: None,
            range: ix.range(whole.start as usize, whole.end as usize),
            selection_range: ix.range(at.start as usize, at.end as usize),
            children,
        }
    };
    let Some(root) = a.checked.loaded.files.first() else {
        return Vec::new();
    };
    root.ast
        .items
        .iter()
        .filter_map(|item| match &item.kind {
            ItemKind::Let { name, .. } => Some(symbol(
                &name.name,
                Some("let".into()),
                SymbolKind::CONSTANT,
                item.span,
                name.span,
                None,
            )),
            ItemKind::Decl { kind, name, value } => Some(symbol(
                &name.name,
                Some(format!("{} {}", kind.keyword(), made_from(value))),
                match kind {
                    DeclKind::Surface => SymbolKind::OBJECT,
                    DeclKind::Tool => SymbolKind::STRUCT,
                    DeclKind::Machine => SymbolKind::CLASS,
                    DeclKind::Strategy => SymbolKind::FUNCTION,
                    DeclKind::Dialect => SymbolKind::NAMESPACE,
                },
                item.span,
                name.span,
                None,
            )),
            ItemKind::Job { name, body } => Some(symbol(
                &name.name,
                Some("job".into()),
                SymbolKind::EVENT,
                item.span,
                name.span,
                Some(
                    body.entries
                        .iter()
                        .map(|e| {
                            symbol(
                                &e.name().name,
                                None,
                                SymbolKind::FIELD,
                                e.span(),
                                e.name().span,
                                None,
                            )
                        })
                        .collect(),
                ),
            )),
            ItemKind::Use(_) => None,
        })
        .collect()
}

/// What a declaration's value is made from: its kind or the item it copies.
fn made_from(value: &Expr) -> String {
    match &value.kind {
        ExprKind::WithBlock { base, .. } => match &base.kind {
            ExprKind::Name(n) => n.clone(),
            _ => String::new(),
        },
        ExprKind::Name(n) => n.clone(),
        _ => String::new(),
    }
}

/// The name at byte `offset` of the document and where it is declared,
/// if it is a name of the document's scope (not a parameter's name, a
/// unit, a comment).
fn target(a: &Analysis, text: &str, offset: usize) -> Option<(String, FileId, Span)> {
    let (start, word) = context::word_around(text, offset)?;
    let cx = context::at(text, start);
    if cx.in_trivia
        || cx.after_number
        || (cx.frame().is_some_and(|f| f.at_name)
            && context::names_a_parameter(text, start + word.len()))
    {
        return None;
    }
    let (file, span) = resolve(a, FileId(0), word)?;
    Some((word.to_string(), file, span))
}

/// Where `name`, as file `from` sees it, is declared: its own `let`s and
/// declarations first, then what its `use`s bring, in order.
fn resolve(a: &Analysis, from: FileId, name: &str) -> Option<(FileId, Span)> {
    if let Some(span) = analysis::declared_in(a, from, name) {
        return Some((from, span));
    }
    a.checked
        .loaded
        .file(from)
        .imports
        .iter()
        .find_map(|imp| match imp {
            Import::One { file, name: n } if n.name == name => {
                analysis::declared_in(a, *file, name).map(|s| (*file, s))
            }
            Import::All { file, .. } => analysis::declared_in(a, *file, name).map(|s| (*file, s)),
            Import::One { .. } => None,
        })
}

/// Every place that names the declaration `(file, span)` of `name`, by
/// file: the declaration itself, the `use` segments that bring it, and
/// the names in expressions that resolve to it.
fn places(a: &Analysis, name: &str, decl: (FileId, Span)) -> Vec<(FileId, Span)> {
    let mut out = vec![decl];
    for f in &a.checked.loaded.files {
        if resolve(a, f.id, name) != Some(decl) {
            continue;
        }
        for imp in &f.imports {
            if let Import::One { name: n, .. } = imp
                && n.name == name
            {
                out.push((f.id, n.span));
            }
        }
        let mut spans = Vec::new();
        for item in &f.ast.items {
            match &item.kind {
                ItemKind::Let { value, .. } | ItemKind::Decl { value, .. } => {
                    names_in(value, name, &mut spans)
                }
                ItemKind::Job { body, .. } => names_in_block(body, name, &mut spans),
                ItemKind::Use(UseTarget::Std(_) | UseTarget::File { .. }) => {}
            }
        }
        out.extend(spans.into_iter().map(|s| (f.id, s)));
    }
    out.sort_by_key(|(f, s)| (f.0, s.start));
    out.dedup();
    out
}

fn names_in_block(b: &Block, name: &str, out: &mut Vec<Span>) {
    for e in &b.entries {
        match e {
            Entry::Param { value, .. } => names_in(value, name, out),
            // A formula's parameters shadow the name in its body.
            Entry::Formula { params, body, .. } => {
                if !params.iter().any(|p| p.name == name) {
                    names_in(body, name, out);
                }
            }
        }
    }
}

fn names_in(e: &Expr, name: &str, out: &mut Vec<Span>) {
    match &e.kind {
        ExprKind::Name(n) if n == name => out.push(e.span),
        ExprKind::Unary { operand, .. } => names_in(operand, name, out),
        ExprKind::Binary { lhs, rhs, .. } => {
            names_in(lhs, name, out);
            names_in(rhs, name, out);
        }
        ExprKind::Call { callee, args } => {
            names_in(callee, name, out);
            for arg in args {
                names_in(&arg.value, name, out);
            }
        }
        ExprKind::WithBlock { base, block } => {
            names_in(base, name, out);
            names_in_block(block, name, out);
        }
        ExprKind::Block(b) => names_in_block(b, name, out),
        ExprKind::List(items) => {
            for i in items {
                names_in(i, name, out);
            }
        }
        ExprKind::Quantity { .. } | ExprKind::Str(_) | ExprKind::Name(_) | ExprKind::Invalid => {}
    }
}

/// Every reference to the name at `offset`, as locations (the
/// declaration too when `with_declaration`).
pub fn references(
    a: &Analysis,
    doc_uri: &Uri,
    text: &str,
    offset: usize,
    with_declaration: bool,
) -> Vec<lsp::Location> {
    let Some((name, file, span)) = target(a, text, offset) else {
        return Vec::new();
    };
    places(a, &name, (file, span))
        .into_iter()
        .filter(|p| with_declaration || *p != (file, span))
        .filter_map(|(f, s)| analysis::location(a, doc_uri, f, s))
        .collect()
}

/// The edits that rename the name at `offset` to `new_name` in every file
/// that names it, or why not.
// `WorkspaceEdit::changes` is the protocol crate's map keyed by `Uri`,
// whose cached parts are cells; the keys are never changed in the map.
#[allow(clippy::mutable_key_type)]
pub fn rename(
    a: &Analysis,
    doc_uri: &Uri,
    text: &str,
    offset: usize,
    new_name: &str,
) -> Result<lsp::WorkspaceEdit, String> {
    let Some((name, file, span)) = target(a, text, offset) else {
        return Err("there is no name of the document's here to rename".into());
    };
    let is_name = new_name
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && new_name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_');
    if !is_name {
        return Err(format!(
            "`{new_name}` is not a name (letters, digits and _, not first a digit)"
        ));
    }
    if a.checked.loaded.sources.get(file).path.is_none() && file != FileId(0) {
        return Err(format!(
            "`{name}` is the standard library's: it cannot be renamed (declare your own copy, `machine mine = {name} {{ }}`)"
        ));
    }
    if new_name != name
        && a.checked
            .loaded
            .files
            .iter()
            .any(|f| resolve(a, f.id, new_name).is_some())
    {
        return Err(format!("`{new_name}` is already a name in these files"));
    }
    let mut changes: HashMap<Uri, Vec<lsp::TextEdit>> = HashMap::new();
    for (f, s) in places(a, &name, (file, span)) {
        let Some(loc) = analysis::location(a, doc_uri, f, s) else {
            continue;
        };
        changes.entry(loc.uri).or_default().push(lsp::TextEdit {
            range: loc.range,
            new_text: new_name.to_string(),
        });
    }
    Ok(lsp::WorkspaceEdit {
        changes: Some(changes),
        ..Default::default()
    })
}
