//! Completion: what may be written at the cursor. Modules after `use
//! std::` and their items after `use std::MODULE::`; units after a
//! number; a block's parameter names where an entry's name goes (those not
//! yet given); where a value of one category goes (`machine:`, `machine
//! m2 = `), that category's names, kinds and standard-library items only,
//! a standard-library item bringing its `use` line; where any other value
//! goes, the words its parameter takes, the names in scope, the kinds, the
//! standard library's items and the functions; an item's keyword at the
//! start of a top-level line.

use std::collections::HashSet;

use lensc_grammar::ast::{DeclKind, ItemKind};
use lensc_lang::check::FUNCTIONS;
use lensc_lang::loader::{Import, STDLIB};
use lensc_lang::schema::{self, Category, Ty};
use lensc_lang::{stdlib, units};
use lsp_types::{
    CompletionItem, CompletionItemKind, Documentation, MarkupContent, MarkupKind, TextEdit,
};

use super::analysis::Analysis;
use super::context::{self, Context};
use super::lookup::{kind_markdown, param_in, param_summary, params_at, stdlib_markdown};
use super::text::LineIndex;
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
    value_items(a, text, &cx)
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

/// The category of value the slot at the cursor takes, where it takes
/// one: a parameter of `Ty::Object`/`Ty::Objects` (`machine:` in a job),
/// or the value of a declaration (`machine m2 = …`).
fn slot_category(a: Option<&Analysis>, cx: &Context) -> Option<Category> {
    if let Some(f) = cx.frame() {
        let p = f.param.as_ref()?;
        let (params, kind) = params_at(a, &cx.frames)?;
        return match param_in(params, kind, p)?.ty {
            Ty::Object(c) | Ty::Objects(c) => Some(c),
            _ => None,
        };
    }
    // `KEYWORD NAME = WORD` at the top level.
    let line = cx.line.strip_suffix(cx.word.as_str())?.trim();
    let (head, rest) = line.split_once('=')?;
    if !rest.trim().is_empty() {
        return None;
    }
    let mut words = head.split_whitespace();
    let keyword = DeclKind::from_keyword(words.next()?)?;
    words.next()?;
    words.next().is_none().then(|| Category::of(keyword))
}

/// Where a value goes: the parameter's words, the names in scope, the
/// kinds, the standard library's items and the functions; only the names,
/// kinds and items of its category where the slot takes one, with the
/// `use` line added when a standard-library item not yet in scope is
/// picked.
fn value_items(a: Option<&Analysis>, text: &str, cx: &Context) -> Vec<CompletionItem> {
    if let Some(c) = slot_category(a, cx) {
        return category_items(a, text, c);
    }
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
    for (n, what, _) in names_in_scope(a) {
        if seen.insert(n.clone()) {
            out.push(item(&n, CompletionItemKind::VARIABLE, Some(what), None));
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

/// The names the document can use: its `let`s and declarations, those
/// of the files it uses, and the names it brings in one by one; each with
/// what it is (`let`, a declaration's keyword, `used`) and its
/// declaration's kind if it is one.
fn names_in_scope(a: Option<&Analysis>) -> Vec<(String, String, Option<DeclKind>)> {
    let Some(a) = a else {
        return Vec::new();
    };
    let loaded = &a.checked.loaded;
    let root = &loaded.files[0];
    let mut files = vec![root.id];
    files.extend(root.imports.iter().filter_map(|i| match i {
        Import::All { file, .. } => Some(*file),
        Import::One { .. } => None,
    }));
    let mut names: Vec<(String, String, Option<DeclKind>)> = root
        .imports
        .iter()
        .filter_map(|i| match i {
            Import::One { file, name } => Some((
                name.name.clone(),
                "used".to_string(),
                loaded
                    .file(*file)
                    .ast
                    .items
                    .iter()
                    .find_map(|it| match &it.kind {
                        ItemKind::Decl { kind, name: n, .. } if n.name == name.name => Some(*kind),
                        _ => None,
                    }),
            )),
            Import::All { .. } => None,
        })
        .collect();
    for f in files {
        for it in &loaded.file(f).ast.items {
            match &it.kind {
                ItemKind::Let { name, .. } => names.push((name.name.clone(), "let".into(), None)),
                ItemKind::Decl { kind, name, .. } => {
                    names.push((name.name.clone(), kind.keyword().into(), Some(*kind)))
                }
                _ => {}
            }
        }
    }
    names
}

/// The names, kinds and standard-library items of category `c`: what a
/// slot of that category takes. A standard-library item not yet in scope
/// carries the edit that adds its `use` line.
fn category_items(a: Option<&Analysis>, text: &str, c: Category) -> Vec<CompletionItem> {
    let mut out = Vec::new();
    let mut seen = HashSet::new();
    for (n, what, kind) in names_in_scope(a) {
        if kind.map(Category::of) == Some(c) && seen.insert(n.clone()) {
            out.push(item(&n, CompletionItemKind::VARIABLE, Some(what), None));
        }
    }
    for k in schema::KINDS.iter().filter(|k| k.category == c) {
        if seen.insert(k.name.to_string()) {
            out.push(item(
                k.name,
                CompletionItemKind::CLASS,
                Some(format!("{}, built-in kind", k.category.noun())),
                Some(kind_markdown(k)),
            ));
        }
    }
    let at = use_line_offset(text);
    let place = LineIndex::new(text).range(at, at);
    for i in stdlib::items().iter().filter(|i| Category::of(i.kind) == c) {
        if seen.insert(i.name.clone()) {
            let mut it = item(
                &i.name,
                CompletionItemKind::CONSTANT,
                Some(format!("{} of the standard library", i.kind.keyword())),
                Some(stdlib_markdown(i)),
            );
            it.additional_text_edits = Some(vec![TextEdit {
                range: place,
                new_text: format!("use std::{}::{}\n", i.module, i.name),
            }]);
            out.push(it);
        }
    }
    out
}

/// Where a new `use` line goes: after the last `use` line at the top of
/// the file (after its leading comments if it has none).
pub fn use_line_offset(text: &str) -> usize {
    let mut offset = 0;
    let mut after = None;
    for line in text.split_inclusive('\n') {
        let t = line.trim_start();
        if t.starts_with("use ") {
            after = Some(offset + line.len());
        } else if !(t.is_empty() || t.starts_with("//")) {
            break;
        } else if after.is_none() && t.starts_with("//") {
            // Leading comments stay first.
            offset += line.len();
            continue;
        }
        offset += line.len();
    }
    match after {
        Some(a) => a,
        None => text
            .split_inclusive('\n')
            .take_while(|l| l.trim_start().starts_with("//"))
            .map(str::len)
            .sum(),
    }
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
