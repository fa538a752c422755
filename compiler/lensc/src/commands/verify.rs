//! `lensc verify PROGRAM [--machine NAME] [--dialect NAME]`: reads a
//! program back from its text as its controller would
//! (`lensc_runtime::reader`), against the machine and dialect its header
//! names (`(machine NAME: DIALECT …)`) unless told otherwise. The machine
//! is looked up in the source file the header names (when it can be read,
//! from the current directory or beside the program) or else the standard
//! library. Exit 0: nothing found; 1: findings (rendered over the
//! program's text) or no machine or dialect to read it by.

use std::io::{BufRead, Write};
use std::path::Path;

use lensc::render;
use lensc_lang::loader::RealFs;
use lensc_lang::lower::read_back;
use lensc_lang::source::SourceMap;
use lensc_runtime::reader;

use crate::MessageFormat;
use crate::output::Output;

/// Runs the subcommand; returns the exit code.
pub fn run(out: &Output, program: &Path, machine: Option<&str>, dialect: Option<&str>) -> u8 {
    let cannot_read = |e: std::io::Error| {
        eprintln!(
            "error[{}]: cannot read {}: {e}",
            lensc_lang::codes::CANNOT_READ,
            program.display()
        );
        1
    };
    let head = match head(program) {
        Ok(h) => h,
        Err(e) => return cannot_read(e),
    };
    let header = reader::header_names(&head);
    let machine_name = machine.or(header.as_ref().map(|h| h.machine.as_str()));
    let Some(machine_name) = machine_name else {
        eprintln!(
            "error: {} names no machine in its header (`machine NAME: DIALECT …`): give --machine and --dialect",
            program.display()
        );
        return 1;
    };
    let asked_dialect = dialect.or(header.as_ref().map(|h| h.dialect.as_str()));
    let declarations = declarations(&head, program, machine_name, asked_dialect);
    let Some((limits, offered)) = read_back::machine_named(&declarations, machine_name) else {
        eprintln!(
            "error: no machine `{}` is declared in the program's source or the standard library",
            render::escape(machine_name)
        );
        return 1;
    };
    let dialect_name = asked_dialect.or(offered.first().map(String::as_str));
    let Some(d) = dialect_name.and_then(|n| read_back::dialect_named(&declarations, n)) else {
        eprintln!(
            "error: no dialect `{}` is declared in the program's source or the standard library",
            render::escape(dialect_name.unwrap_or(""))
        );
        return 1;
    };
    let findings = match std::fs::File::open(program)
        .and_then(|f| reader::read_from(std::io::BufReader::new(f), &d, &limits))
    {
        Ok(f) => f,
        Err(e) => return cannot_read(e),
    };
    if findings.is_empty() {
        if out.format == MessageFormat::Human {
            eprintln!(
                "{}: read as {} on {}: nothing found",
                render::escape(&program.display().to_string()),
                render::escape(&d.name),
                render::escape(machine_name)
            );
        }
        return 0;
    }
    let (text, findings) = match excerpt(program, findings) {
        Ok(t) => t,
        Err(e) => return cannot_read(e),
    };
    let mut sources = SourceMap::default();
    let file = sources.add(
        program.display().to_string(),
        Some(program.to_path_buf()),
        text,
    );
    let diags: Vec<_> = findings
        .iter()
        .map(|f| read_back::finding_diagnostic(f, file))
        .collect();
    let written = match out.format {
        MessageFormat::Human => {
            render::human(&diags, &sources, out.color, &mut std::io::stderr().lock())
        }
        MessageFormat::Json => render::json_lines(&diags, &sources, &mut std::io::stdout().lock()),
    };
    if written.is_err() {
        let _ = writeln!(std::io::stderr(), "error: cannot print the diagnostics");
    }
    1
}

/// The program's first 200 lines, where its header is.
fn head(program: &Path) -> std::io::Result<String> {
    let mut r = std::io::BufReader::new(std::fs::File::open(program)?);
    let mut head = Vec::new();
    for _ in 0..200 {
        if r.read_until(b'\n', &mut head)? == 0 {
            break;
        }
    }
    Ok(String::from_utf8_lossy(&head).into_owned())
}

/// The program as the diagnostics show it: every line a finding is on,
/// the others left empty (a program of millions of lines keeps its line
/// numbers without being held whole), with the findings' spans moved to
/// match.
fn excerpt(
    program: &Path,
    mut findings: Vec<reader::Finding>,
) -> std::io::Result<(String, Vec<reader::Finding>)> {
    let wanted: std::collections::BTreeSet<usize> = findings.iter().map(|f| f.line).collect();
    let mut r = std::io::BufReader::new(std::fs::File::open(program)?);
    let (mut text, mut buf) = (String::new(), Vec::new());
    let (mut line, mut offset) = (0, 0);
    loop {
        buf.clear();
        let n = r.read_until(b'\n', &mut buf)?;
        if n == 0 {
            break;
        }
        line += 1;
        if wanted.contains(&line) {
            for f in findings.iter_mut().filter(|f| f.line == line) {
                let shift = |p: usize| p.saturating_sub(offset) + text.len();
                f.span = (shift(f.span.0), shift(f.span.1));
            }
            text.push_str(String::from_utf8_lossy(&buf).trim_end_matches(['\n', '\r']));
        }
        text.push('\n');
        offset += n;
    }
    Ok((text, findings))
}

/// The declarations of the source file the header names, if it can be
/// read and checks, with the standard library's machine `machine` and
/// dialect `dialect` should the file not declare them.
fn declarations(text: &str, program: &Path, machine: &str, dialect: Option<&str>) -> Declarations {
    let beside = program.parent().unwrap_or(Path::new("."));
    let mut found = Declarations::new();
    for candidate in reader::header_source(text)
        .iter()
        .flat_map(|s| [Path::new(s).to_path_buf(), beside.join(s)])
    {
        if candidate.is_file()
            && let Ok(c) = lensc_lang::check_path(&RealFs, &candidate)
            && !c.has_errors()
        {
            found = c.checked.declarations;
            break;
        }
    }
    let wanted = [("machines", Some(machine)), ("dialects", dialect)];
    for (module, name) in wanted {
        let Some(name) = name.filter(|n| !found.contains_key(*n)) else {
            continue;
        };
        if !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            continue;
        }
        let uses = format!("use std::{module}::{name}\n");
        let c = lensc_lang::check_text(&RealFs, "<standard library>", uses.as_bytes());
        found.extend(c.checked.declarations);
    }
    found
}

type Declarations = std::collections::HashMap<String, std::rc::Rc<lensc_lang::value::Object>>;
