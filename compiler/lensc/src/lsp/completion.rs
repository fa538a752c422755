//! Completion: what may be written at the cursor. Modules after `use
//! std::` and their items after `use std::MODULE::`; units after a
//! number; a block's parameter names where an entry's name goes (those not
//! yet given); where a value goes, the words its parameter takes, the
//! names in scope, the kinds, the standard library's items and the
//! functions; an item's keyword at the start of a top-level line.

use std::collections::HashSet;

use lensc_grammar::ast::ItemKind;
use lensc_lang::check::FUNCTIONS;
use lensc_lang::loader::{Import, STDLIB};
use lensc_lang::schema::{self, Ty};
use lensc_lang::{stdlib, units};
use lsp_types::{CompletionItem, CompletionItemKind, Documentation, MarkupContent, MarkupKind};

use super::analysis::Analysis;
use super::context::{self, Context};
use super::lookup::{kind_markdown, param_in, param_summary, params_at, stdlib_markdown};
use crate::commands::list::param_doc;

const KEYWORDS: &[&str] = &[
    "use", "let", "surface", "tool", "machine", "strategy", "dialect", "job",
];

/// The completions at byte `offset` of `text`.
pub fn complete(a: Option<&Analysis>, text: &str, offset: usize) -> Vec<CompletionItem> {
    let cx = context::at(text, offset);
    if cx.in_trivia {
        return Vec::new();
    }
    if let Some(items) = use_path(&cx) {
        return items;
    }
    if cx.after_number {
        return unit_items();
    }
    if let Some(f) = cx.frame()
        && f.at_name
        && let Some((params, _)) = params_at(a, &cx.frames)
    {
        let given = given_names(text, &cx);
        return params
            .iter()
            .filter(|p| !given.contains(p.name))
            .map(|p| {
                let d = param_doc(p);
                CompletionItem {
                    label: p.name.to_string(),
                    kind: Some(CompletionItemKind::FIELD),
                    detail: Some(param_summary(&d)),
                    documentation: Some(markdown(d.doc.to_string())),
                    insert_text: Some(format!("{}: ", p.name)),
                    ..Default::default()
                }
            })
            .collect();
    }
    if cx.item_start {
        return KEYWORDS
            .iter()
            .map(|k| item(k, CompletionItemKind::KEYWORD, None, None))
            .collect();
    }
    value_items(a, &cx)
}

/// `use std::` offers the modules, `use std::MODULE::` its items.
fn use_path(cx: &Context) -> Option<Vec<CompletionItem>> {
    if !cx.frames.is_empty() {
        return None;
    }
    let path = cx.line.trim_start().strip_prefix("use")?.trim_start();
    let path = path.strip_suffix(cx.word.as_str())?;
    let segs: Vec<&str> = path.split("::").collect();
    match segs.as_slice() {
        ["std", ""] => Some(
            STDLIB
                .iter()
                .map(|(m, _)| item(m, CompletionItemKind::MODULE, None, None))
                .collect(),
        ),
        ["std", module, ""] => Some(
            stdlib::items()
                .iter()
                .filter(|i| i.module == *module)
                .map(|i| {
                    item(
                        &i.name,
                        CompletionItemKind::CONSTANT,
                        Some(i.kind.keyword().to_string()),
                        Some(stdlib_markdown(i)),
                    )
                })
                .collect(),
        ),
        _ => None,
    }
}

fn unit_items() -> Vec<CompletionItem> {
    units::UNITS
        .iter()
        .map(|u| {
            item(
                u.name,
                CompletionItemKind::UNIT,
                Some(u.dim.to_string()),
                None,
            )
        })
        .collect()
}

/// The names already given in the innermost block, before and after the
/// cursor (but not the one being typed).
fn given_names(text: &str, cx: &Context) -> HashSet<String> {
    let Some(frame) = cx.frame() else {
        return HashSet::new();
    };
    context::entries(text)
        .into_iter()
        .filter(|(id, _, at)| *id == frame.id && *at != cx.word_start)
        .map(|(_, name, _)| name)
        .collect()
}

/// Where a value goes: the parameter's words, the names in scope, the
/// kinds, the standard library's items and the functions.
fn value_items(a: Option<&Analysis>, cx: &Context) -> Vec<CompletionItem> {
    let mut out = Vec::new();
    if let Some(f) = cx.frame()
        && let Some(p) = &f.param
        && let Some((params, kind)) = params_at(a, &cx.frames)
        && let Some(param) = param_in(params, kind, p)
        && let Ty::Word(words) = param.ty
    {
        out.extend(words.iter().map(|w| {
            item(
                w,
                CompletionItemKind::ENUM_MEMBER,
                Some(p.to_string()),
                None,
            )
        }));
    }
    let mut seen = HashSet::new();
    if let Some(a) = a {
        let loaded = &a.checked.loaded;
        let root = &loaded.files[0];
        let mut files = vec![root.id];
        files.extend(root.imports.iter().filter_map(|i| match i {
            Import::All { file, .. } => Some(*file),
            Import::One { .. } => None,
        }));
        let ones = root.imports.iter().filter_map(|i| match i {
            Import::One { name, .. } => Some(name.name.clone()),
            Import::All { .. } => None,
        });
        let mut names: Vec<(String, String)> = ones.map(|n| (n, "used".to_string())).collect();
        for f in files {
            for it in &loaded.file(f).ast.items {
                match &it.kind {
                    ItemKind::Let { name, .. } => names.push((name.name.clone(), "let".into())),
                    ItemKind::Decl { kind, name, .. } => {
                        names.push((name.name.clone(), kind.keyword().into()))
                    }
                    _ => {}
                }
            }
        }
        for (n, what) in names {
            if seen.insert(n.clone()) {
                out.push(item(&n, CompletionItemKind::VARIABLE, Some(what), None));
            }
        }
    }
    for k in schema::KINDS {
        if seen.insert(k.name.to_string()) {
            out.push(item(
                k.name,
                CompletionItemKind::CLASS,
                Some(format!("{}, built-in kind", k.category.noun())),
                Some(kind_markdown(k)),
            ));
        }
    }
    for i in stdlib::items() {
        if seen.insert(i.name.clone()) {
            out.push(item(
                &i.name,
                CompletionItemKind::CONSTANT,
                Some(format!("{} of the standard library", i.kind.keyword())),
                Some(stdlib_markdown(i)),
            ));
        }
    }
    for f in FUNCTIONS {
        out.push(item(
            f,
            CompletionItemKind::FUNCTION,
            Some("function".into()),
            None,
        ));
    }
    out
}

fn item(
    label: &str,
    kind: CompletionItemKind,
    detail: Option<String>,
    doc: Option<String>,
) -> CompletionItem {
    CompletionItem {
        label: label.to_string(),
        kind: Some(kind),
        detail,
        documentation: doc.map(markdown),
        ..Default::default()
    }
}

fn markdown(value: String) -> Documentation {
    Documentation::MarkupContent(MarkupContent {
        kind: MarkupKind::Markdown,
        value,
    })
}
