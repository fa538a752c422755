//! Rendering diagnostics at the edge: ariadne for people (byte-indexed, so
//! a `µ` or `°` before an error does not shift its labels), JSON lines for
//! tools.

use std::io::Write;

use ariadne::{Color, Config, IndexType, Label, Report, ReportKind};
use lensc_grammar::{Diagnostic, Severity};
use serde_json::json;

use lensc_lang::source::SourceMap;

/// Renders diagnostics as ariadne reports.
pub fn human(
    diags: &[Diagnostic],
    sources: &SourceMap,
    color: bool,
    out: &mut dyn Write,
) -> std::io::Result<()> {
    let mut cache = ariadne::sources(
        sources
            .iter()
            .map(|(_, f)| (f.name.clone(), f.text.clone())),
    );
    for d in diags {
        let p = d.primary();
        let name = |id| sources.get(id).name.clone();
        let clamp = |id, span: lensc_grammar::Span| {
            let len = sources.get(id).text.len();
            let s = (span.start as usize).min(len);
            s..(span.end as usize).clamp(s, len)
        };
        let (kind, primary_color) = match d.severity {
            Severity::Error => (ReportKind::Error, Color::Red),
            Severity::Warning => (ReportKind::Warning, Color::Yellow),
        };
        let mut r = Report::build(kind, (name(p.file), clamp(p.file, p.span)))
            .with_config(
                Config::default()
                    .with_index_type(IndexType::Byte)
                    .with_color(color),
            )
            .with_code(d.code)
            .with_message(&d.message);
        for (i, l) in d.labels.iter().enumerate() {
            let mut label = Label::new((name(l.file), clamp(l.file, l.span))).with_order(i as i32);
            if color {
                label = label.with_color(if i == 0 { primary_color } else { Color::Blue });
            }
            if !l.message.is_empty() {
                label = label.with_message(&l.message);
            }
            r = r.with_label(label);
        }
        if let Some(h) = &d.help {
            r = r.with_help(h);
        }
        r.finish().write(&mut cache, &mut *out)?;
    }
    Ok(())
}

/// One JSON object per diagnostic per line.
pub fn json_lines(
    diags: &[Diagnostic],
    sources: &SourceMap,
    out: &mut dyn Write,
) -> std::io::Result<()> {
    for d in diags {
        writeln!(out, "{}", json_value(d, sources))?;
    }
    Ok(())
}

pub fn json_value(d: &Diagnostic, sources: &SourceMap) -> serde_json::Value {
    let place = |file, span: lensc_grammar::Span| {
        let (line, column) = sources.line_col(file, span.start as usize);
        (sources.get(file).name.clone(), line, column)
    };
    let p = d.primary();
    let (file, line, column) = place(p.file, p.span);
    let labels: Vec<serde_json::Value> = d
        .labels
        .iter()
        .map(|l| {
            let (file, line, column) = place(l.file, l.span);
            json!({
                "file": file, "line": line, "column": column,
                "span": { "start": l.span.start, "end": l.span.end },
                "message": l.message,
            })
        })
        .collect();
    json!({
        "severity": d.severity.as_str(),
        "code": d.code,
        "message": d.message,
        "file": file,
        "line": line,
        "column": column,
        "span": { "start": p.span.start, "end": p.span.end },
        "labels": labels,
        "help": d.help,
    })
}
