//! The standard library as a catalogue: every machine, tool, strategy and
//! dialect its modules declare, with the module it lives in and the `//`
//! comment written just above it (its documentation). Parsed once from the
//! embedded text the loader uses, so messages ("add `use
//! std::machines::…`") and `lensc list` never keep a copy of their own.

use std::sync::OnceLock;

use lensc_grammar::FileId;
use lensc_grammar::ast::{DeclKind, Expr, ExprKind, ItemKind};

use crate::loader::STDLIB;

/// One declaration of the standard library.
#[derive(Clone, Debug)]
pub struct StdItem {
    /// The module: `machines`, `tools`, `strategies`, `dialects`.
    pub module: &'static str,
    pub name: String,
    pub kind: DeclKind,
    /// The comment lines just above the declaration, joined into one
    /// paragraph per blank comment line.
    pub doc: String,
    /// The name its value is made from: a kind (`lathe { … }`) or another
    /// item it copies (`linuxcnc_lathe { … }`).
    pub made_from: Option<String>,
    /// The declaration as written (its travel, limits and settings).
    pub source: String,
}

impl StdItem {
    /// The `use` that brings this item into a file.
    pub fn use_line(&self) -> String {
        format!("use std::{}::{}", self.module, self.name)
    }
}

/// Every standard-library declaration, module by module in file order.
pub fn items() -> &'static [StdItem] {
    static ITEMS: OnceLock<Vec<StdItem>> = OnceLock::new();
    ITEMS.get_or_init(|| {
        STDLIB
            .iter()
            .flat_map(|&(module, text)| module_items(module, text))
            .collect()
    })
}

/// The standard-library declaration called `name`, if any.
pub fn find(name: &str) -> Option<&'static StdItem> {
    items().iter().find(|i| i.name == name)
}

fn module_items(module: &'static str, text: &str) -> Vec<StdItem> {
    let (file, _) = lensc_grammar::parse(text, FileId(0));
    file.items
        .iter()
        .filter_map(|item| match &item.kind {
            ItemKind::Decl { kind, name, value } => Some(StdItem {
                module,
                name: name.name.clone(),
                kind: *kind,
                doc: doc_above(text, item.span.start as usize),
                made_from: head_name(value),
                source: text
                    .get(item.span.start as usize..item.span.end as usize)
                    .unwrap_or_default()
                    .to_string(),
            }),
            _ => None,
        })
        .collect()
}

/// `lathe` of `lathe { … }`, `circle` of `circle(…)`, `a` of `a`.
fn head_name(e: &Expr) -> Option<String> {
    match &e.kind {
        ExprKind::Name(n) => Some(n.clone()),
        ExprKind::WithBlock { base, .. } => head_name(base),
        ExprKind::Call { callee, .. } => head_name(callee),
        _ => None,
    }
}

/// The built-in kind an item is made with, following the items it copies.
pub fn kind_of(item: &StdItem) -> Option<&str> {
    let mut name = item.made_from.as_deref()?;
    for _ in 0..items().len() {
        match find(name) {
            Some(i) => name = i.made_from.as_deref()?,
            None => return Some(name),
        }
    }
    None
}

/// The `//` comment block that ends on the line just above byte `start`.
fn doc_above(text: &str, start: usize) -> String {
    let before = text[..start.min(text.len())].trim_end_matches([' ', '\t']);
    let before = before.strip_suffix('\n').unwrap_or(before);
    let mut lines: Vec<&str> = Vec::new();
    for line in before.split('\n').rev() {
        match line.trim().strip_prefix("//") {
            Some(c) => lines.push(c.trim()),
            None => break,
        }
    }
    lines.reverse();
    let mut out = String::new();
    for l in lines {
        if l.is_empty() {
            out.push_str("\n\n");
        } else {
            if !out.is_empty() && !out.ends_with('\n') {
                out.push(' ');
            }
            out.push_str(l);
        }
    }
    out.trim().to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_module_is_read_and_items_carry_their_comment() {
        let m = find("ultra_precision_lathe").expect("a stdlib machine");
        assert_eq!(m.module, "machines");
        assert_eq!(m.kind, DeclKind::Machine);
        assert!(m.doc.starts_with("LT Ultra MTC400-class"), "{}", m.doc);
        assert_eq!(
            m.use_line(),
            "use std::machines::ultra_precision_lathe".to_string()
        );
        for (module, _) in STDLIB {
            assert!(items().iter().any(|i| i.module == *module), "{module}");
        }
    }
}
