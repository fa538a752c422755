//! Code actions: the fixes lensc's own diagnostics carry, offered as
//! quick fixes. A help that says "did you mean `S`?" replaces the
//! diagnostic's text with `S`; one that says "add `use std::…`" adds that
//! line at the top of the file (after its `use` lines); a help with both
//! does both in one fix.

use std::collections::HashMap;

use lsp_types::{self as lsp, CodeActionOrCommand, Uri};

use super::completion::use_line_offset;
use super::text::LineIndex;

/// The quick fixes for the diagnostics the editor sends (those of lensc).
pub fn quick_fixes(
    uri: &Uri,
    text: &str,
    diagnostics: &[lsp::Diagnostic],
) -> Vec<CodeActionOrCommand> {
    let ix = LineIndex::new(text);
    let mut out = Vec::new();
    for d in diagnostics {
        if d.source.as_deref() != Some("lensc") {
            continue;
        }
        let Some(help) = d.message.split_once("\nhelp: ").map(|(_, h)| h) else {
            continue;
        };
        let mut edits = Vec::new();
        let mut titles = Vec::new();
        if let Some(meant) = quoted_after(help, "did you mean `") {
            edits.push(lsp::TextEdit {
                range: d.range,
                new_text: meant.to_string(),
            });
            titles.push(format!("write `{meant}`"));
        }
        if let Some(line) = quoted_after(help, "add `use ") {
            let at = use_line_offset(text);
            let present = text.lines().any(|l| l.trim() == format!("use {line}"));
            if !present {
                edits.push(lsp::TextEdit {
                    range: ix.range(at, at),
                    new_text: format!("use {line}\n"),
                });
                titles.push(format!("add `use {line}`"));
            }
        }
        if edits.is_empty() {
            continue;
        }
        out.push(CodeActionOrCommand::CodeAction(lsp::CodeAction {
            title: titles.join(" and "),
            kind: Some(lsp::CodeActionKind::QUICKFIX),
            diagnostics: Some(vec![d.clone()]),
            edit: Some(lsp::WorkspaceEdit {
                changes: Some(HashMap::from([(uri.clone(), edits)])),
                ..Default::default()
            }),
            is_preferred: Some(true),
            ..Default::default()
        }));
    }
    out
}

/// The text between `prefix` and the next backquote in `help`.
fn quoted_after<'h>(help: &'h str, prefix: &str) -> Option<&'h str> {
    let rest = &help[help.find(prefix)? + prefix.len()..];
    let text = &rest[..rest.find('`')?];
    (!text.is_empty()).then_some(text)
}
