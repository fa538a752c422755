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
    if let Some(job) = servo_table_job(&head) {
        return verify_table(out, program, job);
    }
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
    let mut sources = SourceMap::default();
    let diags = match lines_of_findings(program, &findings, &mut sources) {
        Ok(d) => d,
        Err(e) => return cannot_read(e),
    };
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

/// The job of a fast-tool-servo table a build writes beside its program
/// (`# lensc VERSION fast-tool-servo table for job NAME`), if `head` is
/// one.
fn servo_table_job(head: &str) -> Option<&str> {
    let first = head.lines().next()?.strip_prefix("# lensc ")?;
    let (_, job) = first.split_once(" fast-tool-servo table for job ")?;
    Some(job.trim())
}

/// Reads a servo table as a table: every row after the `#` lines three
/// finite numbers `C X W`, C never running backwards. Exit 0 with what it
/// holds, 1 at the first row that is not (E0190).
fn verify_table(out: &Output, table: &Path, job: &str) -> u8 {
    let text = match std::fs::read_to_string(table) {
        Ok(t) => t,
        Err(e) => {
            eprintln!(
                "error[{}]: cannot read {}: {e}",
                lensc_lang::codes::CANNOT_READ,
                table.display()
            );
            return 1;
        }
    };
    let (mut rows, mut last_c) = (0usize, f64::NEG_INFINITY);
    let (mut x, mut w) = (
        (f64::INFINITY, f64::NEG_INFINITY),
        (f64::INFINITY, f64::NEG_INFINITY),
    );
    for (i, line) in text.lines().enumerate() {
        if line.starts_with('#') || line.trim().is_empty() {
            continue;
        }
        let figures: Vec<f64> = line
            .split_whitespace()
            .map_while(|f| f.parse::<f64>().ok().filter(|v| v.is_finite()))
            .collect();
        let whole = figures.len() == 3 && line.split_whitespace().count() == 3;
        if !whole || figures[0] < last_c {
            eprintln!(
                "error[{}]: {} line {}: a fast-tool-servo table row is three numbers `C X W` with C in order, not `{}`",
                lensc_lang::codes::SERVO_TABLE_ROW,
                table.display(),
                i + 1,
                line.trim()
            );
            return 1;
        }
        last_c = figures[0];
        x = (x.0.min(figures[1]), x.1.max(figures[1]));
        w = (w.0.min(figures[2]), w.1.max(figures[2]));
        rows += 1;
    }
    if out.format == MessageFormat::Human {
        let program = sibling_program(table, job);
        eprintln!(
            "{}: a fast-tool-servo table for job {job}, not a program: {rows} rows C X W, C 0 .. {} deg, X {} .. {} mm, W {} .. {} mm, every row three numbers in order; {}",
            table.display(),
            lensc_runtime::post::header::num(last_c.max(0.0)),
            lensc_runtime::post::header::num(x.0),
            lensc_runtime::post::header::num(x.1),
            lensc_runtime::post::header::num(w.0),
            lensc_runtime::post::header::num(w.1),
            match program {
                Some(p) => format!(
                    "the program that drives it is read by `lensc verify {}`",
                    p.display()
                ),
                None => format!(
                    "the program that drives it (job {job}) is read by `lensc verify PROGRAM`"
                ),
            }
        );
    }
    0
}

/// The program beside a servo table: the other file of the job's name that
/// is neither the table nor its report.
fn sibling_program(table: &Path, job: &str) -> Option<std::path::PathBuf> {
    let dir = table.parent()?;
    let mut found: Vec<_> = std::fs::read_dir(if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    })
    .ok()?
    .filter_map(|e| e.ok().map(|e| e.path()))
    .filter(|p| {
        p.file_stem().is_some_and(|s| s == job)
            && p.extension().is_some_and(|e| e != "json")
            && p.extension() != table.extension()
    })
    .collect();
    found.sort();
    found.into_iter().next().map(|p| {
        if dir.as_os_str().is_empty() {
            std::path::PathBuf::from(p.file_name().unwrap_or_default())
        } else {
            p
        }
    })
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

/// The findings as diagnostics, each over the one line of the program it
/// is on, added to `sources` as a part of the program (numbered as the
/// program's line): the program is read once more, a line at a time, and
/// only the lines with findings are kept (a handful: the reader reports
/// each rule once), so memory does not grow with the program.
fn lines_of_findings(
    program: &Path,
    findings: &[reader::Finding],
    sources: &mut SourceMap,
) -> std::io::Result<Vec<lensc_grammar::Diagnostic>> {
    let wanted: std::collections::BTreeSet<usize> = findings.iter().map(|f| f.line).collect();
    let last = wanted.last().copied().unwrap_or(0);
    let mut parts = std::collections::HashMap::new();
    let mut r = std::io::BufReader::new(std::fs::File::open(program)?);
    let mut buf = Vec::new();
    let (mut line, mut offset) = (0, 0);
    while line < last {
        buf.clear();
        let n = r.read_until(b'\n', &mut buf)?;
        if n == 0 {
            break;
        }
        line += 1;
        if wanted.contains(&line) {
            let text = String::from_utf8_lossy(&buf);
            let file = sources.add_part(
                program.display().to_string(),
                Some(program.to_path_buf()),
                text.trim_end_matches(['\n', '\r']).to_string(),
                line - 1,
                offset,
            );
            parts.insert(line, (file, offset));
        }
        offset += n;
    }
    let mut diags = Vec::with_capacity(findings.len());
    for f in findings {
        // A finding past the last line read (the file shrank): shown on
        // an empty part at its line.
        let (file, start) = *parts.entry(f.line).or_insert_with(|| {
            let file = sources.add_part(
                program.display().to_string(),
                Some(program.to_path_buf()),
                String::new(),
                f.line.saturating_sub(1),
                f.span.0,
            );
            (file, f.span.0)
        });
        let mut f = f.clone();
        f.span = (
            f.span.0.saturating_sub(start),
            f.span.1.saturating_sub(start),
        );
        diags.push(read_back::finding_diagnostic(&f, file));
    }
    Ok(diags)
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
