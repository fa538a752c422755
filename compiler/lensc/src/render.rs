//! Rendering diagnostics at the edge: ariadne for people (byte-indexed, so
//! a `µ` or `°` before an error does not shift its labels), JSON lines for
//! tools.
//!
//! What people see goes to a terminal, so nothing from a file reaches it
//! raw: control characters (C0 but tab and line feed, DEL, C1) and the
//! bidirectional overrides are shown escaped, as `\u{1b}`, in the source
//! lines, the messages, the help and the file names (`escape`). And each
//! diagnostic is rendered from an excerpt of its files: the lines its
//! labels are on, each at most `WIDTH` bytes plus `CONTEXT` bytes either
//! side of each label's ends, the rest of a long line summarised as
//! `…(N bytes)…`; so a diagnostic on a 10 MB line prints a few hundred
//! bytes, and rendering takes time in proportion to what is printed.

use std::borrow::Cow;
use std::collections::HashMap;
use std::io::Write;

use ariadne::{Color, Config, FnCache, IndexType, Label, Report, ReportKind, Source};
use lensc_grammar::{Diagnostic, FileId, Severity};
use serde_json::json;

use lensc_lang::source::SourceMap;

/// A line longer than this, in bytes, is shown in windows around the
/// labels' ends.
pub const WIDTH: usize = 512;
/// The bytes shown either side of a label's end on a long line.
pub const CONTEXT: usize = 80;

/// Whether `c` is shown escaped on a terminal.
fn hidden(c: char) -> bool {
    (c.is_control() && c != '\t' && c != '\n')
        || matches!(c, '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}')
}

/// `s` with every control character (but tab and line feed) and
/// bidirectional override escaped as `\u{HEX}`.
pub fn escape(s: &str) -> Cow<'_, str> {
    if !s.chars().any(hidden) {
        return Cow::Borrowed(s);
    }
    let mut out = String::with_capacity(s.len() + 8);
    for c in s.chars() {
        if hidden(c) {
            out.push_str(&c.escape_unicode().to_string());
        } else {
            out.push(c);
        }
    }
    Cow::Owned(out)
}

/// The part of one file a diagnostic shows: its lines `first..`, escaped
/// and cut to width, and where each byte offset of the file went.
struct Excerpt {
    text: String,
    file: FileId,
    /// The file's lines shown, 0-based (as the whole file counts them, for
    /// a part of one).
    first_line: usize,
    last_line: usize,
    /// Whether anything was escaped or left out.
    altered: bool,
    /// (offset in the file, offset in `text`, whether the bytes after it
    /// are copied one for one) at each change of kind, in order.
    map: Vec<(usize, usize, bool)>,
}

impl Excerpt {
    fn new(sources: &SourceMap, file: FileId, points: &[usize]) -> Excerpt {
        let text = &sources.get(file).text;
        let lo = line_of(sources, file, points.iter().copied().min().unwrap_or(0));
        let hi = line_of(sources, file, points.iter().copied().max().unwrap_or(0));
        // Numbered as the file's lines (a part of a file starts later).
        let shown = sources.get(file).first_line;
        let mut e = Excerpt {
            text: String::new(),
            file,
            first_line: shown + lo,
            last_line: shown + hi,
            altered: false,
            map: Vec::new(),
        };
        for line in lo..=hi {
            let r = sources.line_range(file, line);
            let body = text[r.clone()].trim_end_matches('\n');
            let body = body.strip_suffix('\r').unwrap_or(body);
            let (start, end) = (r.start, r.start + body.len());
            let keep = windows(text, start, end, points);
            let mut at = start;
            for (s, t) in keep {
                if s > at {
                    e.map.push((at, e.text.len(), false));
                    e.text.push_str(&format!("…({} bytes)…", s - at));
                    e.altered = true;
                }
                e.copy(&text[s..t], s);
                at = t;
            }
            if end > at {
                e.map.push((at, e.text.len(), false));
                e.text.push_str(&format!("…({} bytes)…", end - at));
                e.altered = true;
            }
            if end < r.end {
                e.map.push((end, e.text.len(), false));
                e.text.push('\n');
                e.map.push((r.end, e.text.len(), true));
            }
        }
        e
    }

    /// Copies `s`, found at `at` in the file, escaping what is hidden.
    fn copy(&mut self, s: &str, at: usize) {
        let mut run = 0;
        for (i, c) in s.char_indices() {
            if hidden(c) {
                if i > run {
                    self.map.push((at + run, self.text.len(), true));
                    self.text.push_str(&s[run..i]);
                }
                self.map.push((at + i, self.text.len(), false));
                self.text.push_str(&c.escape_unicode().to_string());
                self.altered = true;
                run = i + c.len_utf8();
            }
        }
        if s.len() > run {
            self.map.push((at + run, self.text.len(), true));
            self.text.push_str(&s[run..]);
        }
    }

    /// Where the excerpt's byte `at` came from in the file.
    fn back(&self, at: usize) -> usize {
        let i = self.map.partition_point(|m| m.1 <= at);
        match i.checked_sub(1).map(|i| self.map[i]) {
            Some((o, d, true)) => o + (at - d),
            Some((o, _, false)) => o,
            None => 0,
        }
    }

    /// Where the file's byte `off` is in the excerpt.
    fn at(&self, off: usize) -> usize {
        let i = self.map.partition_point(|m| m.0 <= off);
        match i.checked_sub(1).map(|i| self.map[i]) {
            Some((o, d, true)) => d + (off - o),
            Some((_, d, false)) => d,
            None => 0,
        }
    }
}

/// The line of byte `p`, an offset at the end of a file that ends with a
/// line feed being on the last line (as ariadne shows it).
fn line_of(sources: &SourceMap, file: FileId, p: usize) -> usize {
    let text = &sources.get(file).text;
    if p > 0 && p >= text.len() && text.ends_with('\n') {
        return sources.line_of(file, text.len() - 1);
    }
    sources.line_of(file, p)
}

/// The ranges of the line `start..end` shown: all of it when it is short,
/// else `CONTEXT` bytes either side of each label end on it (or its first
/// `WIDTH` bytes when none is), merged, on character boundaries.
fn windows(text: &str, start: usize, end: usize, points: &[usize]) -> Vec<(usize, usize)> {
    if end - start <= WIDTH {
        return vec![(start, end)];
    }
    let floor = |mut i: usize| {
        while !text.is_char_boundary(i) {
            i -= 1;
        }
        i
    };
    let ceil = |mut i: usize| {
        while !text.is_char_boundary(i) {
            i += 1;
        }
        i
    };
    let mut w: Vec<(usize, usize)> = points
        .iter()
        .filter(|&&p| p >= start && p <= end)
        .map(|&p| {
            (
                floor(p.saturating_sub(CONTEXT).max(start)),
                ceil((p + CONTEXT).min(end)),
            )
        })
        .collect();
    if w.is_empty() {
        w.push((start, ceil(start + WIDTH)));
    }
    w.sort_unstable();
    let mut merged: Vec<(usize, usize)> = Vec::with_capacity(w.len());
    for (s, t) in w {
        match merged.last_mut() {
            Some(last) if s <= last.1 => last.1 = last.1.max(t),
            _ => merged.push((s, t)),
        }
    }
    merged
}

/// Renders diagnostics as ariadne reports.
pub fn human(
    diags: &[Diagnostic],
    sources: &SourceMap,
    color: bool,
    out: &mut dyn Write,
) -> std::io::Result<()> {
    for d in diags {
        // A span inside its file, on character boundaries (ariadne slices
        // the text there and panics mid-character).
        let clamp = |id: FileId, span: lensc_grammar::Span| {
            let text = &sources.get(id).text;
            let fit = |p: usize| {
                let mut p = p.min(text.len());
                while !text.is_char_boundary(p) {
                    p -= 1;
                }
                p
            };
            let s = fit(span.start as usize);
            (s, fit(span.end as usize).max(s))
        };
        // Each file the labels are in, by the name shown (two files with
        // one name share it: the first one's excerpt is shown).
        let mut files: Vec<(FileId, String, Vec<usize>)> = Vec::new();
        for l in &d.labels {
            let (s, e) = clamp(l.file, l.span);
            match files.iter_mut().find(|f| f.0 == l.file) {
                Some(f) => f.2.extend([s, e]),
                None => files.push((
                    l.file,
                    escape(&sources.get(l.file).name).into_owned(),
                    vec![s, e],
                )),
            }
        }
        let mut excerpts: HashMap<FileId, Excerpt> = HashMap::new();
        let mut shown: HashMap<String, Source<String>> = HashMap::new();
        for (id, name, points) in &files {
            let e = Excerpt::new(sources, *id, points);
            shown.entry(name.clone()).or_insert_with(|| {
                Source::from(e.text.clone()).with_display_line_offset(e.first_line)
            });
            excerpts.insert(*id, e);
        }
        let place = |id: FileId, span| {
            let (s, e) = clamp(id, span);
            let x = &excerpts[&id];
            let name = files.iter().find(|f| f.0 == id).map(|f| f.1.clone());
            (name.unwrap_or_default(), x.at(s)..x.at(e))
        };
        let (kind, primary_color) = match d.severity {
            Severity::Error => (ReportKind::Error, Color::Red),
            Severity::Warning => (ReportKind::Warning, Color::Yellow),
        };
        let p = d.primary();
        let mut r = Report::build(kind, place(p.file, p.span))
            .with_config(
                Config::default()
                    .with_index_type(IndexType::Byte)
                    .with_color(color),
            )
            .with_code(d.code)
            .with_message(escape(&d.message));
        for (i, l) in d.labels.iter().enumerate() {
            let mut label = Label::new(place(l.file, l.span)).with_order(i as i32);
            if color {
                label = label.with_color(if i == 0 { primary_color } else { Color::Blue });
            }
            if !l.message.is_empty() {
                label = label.with_message(escape(&l.message));
            }
            r = r.with_label(label);
        }
        if let Some(h) = &d.help {
            r = r.with_help(escape(h));
        }
        let cache = FnCache::new(
            (|id: &String| Err(format!("no source `{id}`")))
                as fn(&String) -> Result<String, String>,
        )
        .with_sources(shown);
        let mut buf = Vec::new();
        r.finish().write(cache, &mut buf)?;
        let named: Vec<(&str, &Excerpt)> = files
            .iter()
            .map(|(id, name, _)| (name.as_str(), &excerpts[id]))
            .collect();
        out.write_all(renumber(&String::from_utf8_lossy(&buf), &named, sources).as_bytes())?;
    }
    Ok(())
}

/// Ariadne's report with its margins' line numbers moved from the
/// excerpts' to the files' (ariadne 0.5 numbers the margin from each
/// source's first line, heeding `with_display_line_offset` only in the
/// `╭─[ file:line:col ]` heading, whose column is the excerpt's): each
/// group of lines after a heading naming a file is shifted by the lines
/// before its excerpt, every margin widened to the widest line number
/// shown, and each heading's line and column made the file's.
fn renumber(report: &str, files: &[(&str, &Excerpt)], sources: &SourceMap) -> String {
    if files.iter().all(|f| f.1.first_line == 0 && !f.1.altered) {
        return report.to_string(); // numbers and columns as in the files
    }
    let digits = |n: usize| n.to_string().len();
    let wide = files
        .iter()
        .map(|f| digits(f.1.last_line + 1))
        .max()
        .unwrap_or(1);
    let small = files
        .iter()
        .map(|f| digits(f.1.last_line - f.1.first_line + 1))
        .max()
        .unwrap_or(1);
    let grow = wide.saturating_sub(small);
    // The margin ariadne drew: as wide as the spaces before the heading's
    // corner (a line number ends one space before the box character).
    let Some(narrow) = report.lines().find_map(|l| {
        let body = skip_escapes(l);
        body.find("╭─[")
            .filter(|&i| i > 0 && body[..i].bytes().all(|b| b == b' '))
            .map(|i| i - 1)
    }) else {
        return report.to_string();
    };
    let mut shift = 0;
    let mut out = String::with_capacity(report.len() + 64);
    for (n, line) in report.split_inclusive('\n').enumerate() {
        let body = skip_escapes(line);
        let pre = &line[..line.len() - body.len()];
        // The footer, `─…─╯`, is as wide as the margin plus one.
        if n > 0 && body.starts_with('─') && body.trim_start_matches('─').starts_with('╯') {
            out.push_str(pre);
            out.push_str(&"─".repeat(grow));
            out.push_str(body);
            continue;
        }
        let margin = body.get(..narrow + 1);
        let drawn = body.get(narrow + 1..).and_then(|r| r.chars().next());
        let boxed = drawn.is_some_and(|c| "│╭├╰·┆─╯┤┬┴".contains(c));
        if n == 0 || !boxed || margin.is_none() {
            out.push_str(line);
            continue;
        }
        let margin = margin.unwrap_or_default();
        let mut rest = Cow::Borrowed(&body[narrow + 1..]);
        for heading in ["╭─[ ", "├─[ "] {
            if let Some(named) = rest.strip_prefix(heading) {
                let f = files
                    .iter()
                    .filter(|f| named.starts_with(&format!("{}:", f.0)))
                    .max_by_key(|f| f.0.len());
                shift = f.map_or(0, |f| f.1.first_line);
                if let Some((name, e)) = f
                    && let Some(place) = heading_place(&named[name.len() + 1..], e, sources)
                {
                    rest = Cow::Owned(format!("{heading}{name}:{place}"));
                }
                break;
            }
        }
        out.push_str(pre);
        let number = margin.trim();
        match number.parse::<usize>() {
            Ok(k) if !number.is_empty() => {
                let shown = (k + shift).to_string();
                out.push_str(&" ".repeat((narrow + 1 + grow).saturating_sub(shown.len() + 1)));
                out.push_str(&shown);
                out.push(' ');
            }
            _ => {
                out.push_str(&" ".repeat(grow));
                out.push_str(margin);
            }
        }
        out.push_str(&rest);
    }
    out
}

/// A heading's `LINE:COL ]…` (the excerpt's column) as the file's.
fn heading_place(tail: &str, e: &Excerpt, sources: &SourceMap) -> Option<String> {
    let (line, rest) = tail.split_once(':')?;
    let (col, rest) = rest.split_once(' ')?;
    let (line, col): (usize, usize) = (line.parse().ok()?, col.parse().ok()?);
    let idx = line.checked_sub(1 + e.first_line)?;
    let start = if idx == 0 {
        0
    } else {
        e.text.match_indices('\n').nth(idx - 1)?.0 + 1
    };
    let at = start
        + e.text[start..]
            .chars()
            .take(col.saturating_sub(1))
            .map(char::len_utf8)
            .sum::<usize>();
    let p = e.back(at);
    let text = &sources.get(e.file).text;
    // The end of a file that ends with a line feed: just past that line's
    // end, as ariadne places it.
    let (l, c) = if p > 0 && p >= text.len() && text.ends_with('\n') {
        let (l, c) = sources.line_col(e.file, text.len() - 1);
        (l, c + 1)
    } else {
        sources.line_col(e.file, p)
    };
    Some(format!("{l}:{c} {rest}"))
}

/// `line` after the colour escapes (`ESC [ … letter`) it starts with.
fn skip_escapes(mut line: &str) -> &str {
    while let Some(r) = line.strip_prefix("\u{1b}[") {
        match r.find(|c: char| c.is_ascii_alphabetic()) {
            Some(i) => line = &r[i + 1..],
            None => break,
        }
    }
    line
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
    // Spans as offsets into the whole file (a part starts further in).
    let at = |file: FileId, span: lensc_grammar::Span| {
        let base = sources.get(file).first_byte;
        json!({ "start": base + span.start as usize, "end": base + span.end as usize })
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
                "span": at(l.file, l.span),
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
        "span": at(p.file, p.span),
        "labels": labels,
        "help": d.help,
    })
}
