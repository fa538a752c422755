//! `lensc verify PROGRAM [--machine NAME] [--dialect NAME] [--policy
//! fail|warn] [--source FILE]`: reads a program back from its text as its
//! controller would (`lensc_runtime::reader`), against the machine and
//! dialect its header names (`(machine NAME: DIALECT …)`) unless told
//! otherwise. The machine is looked up in the source file the header names
//! (when it can be read, from the current directory or beside the program)
//! or else the standard library. Each finding is of one of two classes:
//! the controller's rule (it refuses the program too) or lensc's own
//! policy (it would run it), named and with its reason. The header's
//! source hash is checked against that file (W0023 when they differ,
//! W0024 when it could not be checked). Exit 0: nothing found (or only
//! policy findings under `--policy warn`); 1: findings (rendered over the
//! program's text) or no machine or dialect to read it by.

use std::io::{BufRead, Write};
use std::path::Path;

use lensc::render;
use lensc_grammar::{Diagnostic, Severity};
use lensc_lang::loader::RealFs;
use lensc_lang::lower::read_back;
use lensc_lang::source::SourceMap;
use lensc_runtime::reader;

use crate::MessageFormat;
use crate::output::Output;

/// What the user asked besides the program.
pub struct Asked<'a> {
    pub machine: Option<&'a str>,
    pub dialect: Option<&'a str>,
    /// Whether a policy finding fails the program (exit 1).
    pub policy_fails: bool,
    /// The `.lens` file to check the header's hash against.
    pub source: Option<&'a Path>,
}

/// Runs the subcommand; returns the exit code.
pub fn run(out: &Output, program: &Path, asked: Asked) -> u8 {
    let Asked {
        machine,
        dialect,
        policy_fails,
        source,
    } = asked;
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
    // A main program that calls its parts (a program split for its
    // control's delivery) is read with each part in place of its call, as
    // the control runs it.
    let assembled = match split_set(program, &head, &d) {
        Ok(a) => a,
        Err(message) => {
            eprintln!(
                "error[{}]: {}: {message}",
                lensc_lang::codes::CANNOT_READ,
                program.display()
            );
            return 1;
        }
    };
    let findings = match &assembled {
        Some(text) => Ok(reader::read(text, &d, &limits)),
        None => std::fs::File::open(program)
            .and_then(|f| reader::read_from(std::io::BufReader::new(f), &d, &limits)),
    };
    let findings = match findings {
        Ok(f) => f,
        Err(e) => return cannot_read(e),
    };
    let stale = source_check(&head, program, source);
    let mut sources = SourceMap::default();
    let mut diags: Vec<_> = stale
        .iter()
        .map(|s| s.diagnostic(&head, program, &mut sources))
        .collect();
    let found = match lines_of_findings(program, assembled.as_deref(), &findings, &mut sources) {
        Ok(d) => d,
        Err(e) => return cannot_read(e),
    };
    diags.extend(findings.iter().zip(found).map(|(f, d)| {
        if f.rule.policy().is_some() && !policy_fails {
            Diagnostic {
                severity: Severity::Warning,
                ..d
            }
        } else {
            d
        }
    }));
    let written = match out.format {
        MessageFormat::Human => {
            render::human(&diags, &sources, out.color, &mut std::io::stderr().lock())
        }
        MessageFormat::Json => {
            let mut w = std::io::stdout().lock();
            let classes = stale
                .iter()
                .map(|_| ("source", None))
                .chain(findings.iter().map(|f| match f.rule.policy() {
                    Some(p) => ("policy", Some(p)),
                    None => ("controller", None),
                }));
            diags
                .iter()
                .zip(classes)
                .try_for_each(|(d, (class, policy))| {
                    let mut v = render::json_value(d, &sources);
                    v["class"] = class.into();
                    if let Some(p) = policy {
                        v["policy"] = serde_json::json!({ "name": p.name, "reason": p.reason });
                    }
                    writeln!(w, "{v}")
                })
        }
    };
    if written.is_err() {
        let _ = writeln!(std::io::stderr(), "error: cannot print the diagnostics");
    }
    let policy = findings
        .iter()
        .filter(|f| f.rule.policy().is_some())
        .count();
    let controller = findings.len() - policy;
    if out.format == MessageFormat::Human {
        let shown = program.display().to_string();
        let name = render::escape(&shown);
        let on = format!(
            "read as {} on {}",
            render::escape(&d.name),
            render::escape(machine_name)
        );
        if findings.is_empty() {
            eprintln!("{name}: {on}: nothing found");
        } else {
            let would_run = match policy {
                0 => "",
                1 => " (the controller would run it)",
                _ => " (the controller would run them)",
            };
            eprintln!(
                "{name}: {on}: {controller} finding{} of the controller's rules, {policy} of lensc's own policy{would_run}{}",
                if controller == 1 { "" } else { "s" },
                if policy > 0 && !policy_fails {
                    "; policy findings warn only (--policy warn)"
                } else {
                    ""
                }
            );
        }
    }
    u8::from(controller > 0 || (policy > 0 && policy_fails))
}

/// What the header's source hash check found: the hash differs (W0023)
/// or could not be checked (W0024), at the header's `source` line.
struct SourceCheck {
    code: &'static str,
    message: String,
    help: String,
    line: usize,
}

impl SourceCheck {
    /// The warning over the header's `source` line, a part of the program
    /// taken from its head (numbered as the program's line).
    fn diagnostic(&self, head: &str, program: &Path, sources: &mut SourceMap) -> Diagnostic {
        let start: usize = head
            .split_inclusive('\n')
            .take(self.line.saturating_sub(1))
            .map(str::len)
            .sum();
        let start = start.min(head.len());
        let text = head[start..]
            .split('\n')
            .next()
            .unwrap_or("")
            .trim_end_matches('\r')
            .to_string();
        let len = text.len();
        let file = sources.add_part(
            program.display().to_string(),
            Some(program.to_path_buf()),
            text,
            self.line.saturating_sub(1),
            start,
        );
        Diagnostic::warning(
            self.code,
            self.message.clone(),
            file,
            lensc_grammar::Span::new(0, len),
        )
        .with_label("the hash the program was written with")
        .with_help(self.help.clone())
    }
}

/// Checks the hash the header carries (`source PATH fnv1a64 HEX`) against
/// the `.lens` file: `source` if given, else the header's path from the
/// current directory, else beside the program. `None`: the hashes agree,
/// or the header carries none.
fn source_check(head: &str, program: &Path, source: Option<&Path>) -> Option<SourceCheck> {
    let (named, want, line) = reader::header_source_hash(head)?;
    let beside = program.parent().unwrap_or(Path::new("."));
    let candidates: Vec<std::path::PathBuf> = match source {
        Some(s) => vec![s.to_path_buf()],
        None => vec![Path::new(&named).to_path_buf(), beside.join(&named)],
    };
    let Some(path) = candidates.iter().find(|p| p.is_file()) else {
        return Some(SourceCheck {
            code: lensc_lang::codes::SOURCE_UNCHECKED_WARNING,
            message: format!(
                "the program's source `{}` is not at hand: whether the program is still what it says was not checked",
                render::escape(&candidates[0].display().to_string())
            ),
            help: "give the .lens file with --source FILE".into(),
            line,
        });
    };
    let path_text = path.display().to_string();
    let shown = render::escape(&path_text);
    match lensc_lang::loader::load(&RealFs, path) {
        Ok(loaded) if loaded.fnv1a64() == want => None,
        Ok(loaded) => Some(SourceCheck {
            code: lensc_lang::codes::SOURCE_CHANGED_WARNING,
            message: format!(
                "`{shown}` (with the files it uses) hashes to {:016x}, not the {want:016x} the program was written from: the file changed since",
                loaded.fnv1a64()
            ),
            help: format!(
                "build the program again from `{shown}`, or verify against the file it was built from"
            ),
            line,
        }),
        Err(e) => Some(SourceCheck {
            code: lensc_lang::codes::SOURCE_UNCHECKED_WARNING,
            message: format!(
                "`{shown}` could not be read ({e:?}): the program's hash was not checked"
            ),
            help: "give the .lens file with --source FILE".into(),
            line,
        }),
    }
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
/// The text of the split set `program` heads, its parts (beside it) in
/// place of their calls; `None` if it calls no parts (the program's name
/// without its extension names them, as the build named them).
fn split_set(
    program: &Path,
    head: &str,
    d: &lensc_runtime::dialect::Dialect,
) -> Result<Option<String>, String> {
    let job = program
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    if !reader::parts::calls_parts(head, d, &job) {
        return Ok(None);
    }
    let main = std::fs::read_to_string(program).map_err(|e| e.to_string())?;
    let beside = program.parent().unwrap_or(Path::new("."));
    let mut load =
        |name: &str| std::fs::read_to_string(beside.join(name)).map_err(|e| e.to_string());
    reader::parts::assemble(&main, d, &job, &mut load)
        .map(Some)
        .map_err(|e| e.message())
}

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
    assembled: Option<&str>,
    findings: &[reader::Finding],
    sources: &mut SourceMap,
) -> std::io::Result<Vec<lensc_grammar::Diagnostic>> {
    let wanted: std::collections::BTreeSet<usize> = findings.iter().map(|f| f.line).collect();
    let last = wanted.last().copied().unwrap_or(0);
    let mut parts = std::collections::HashMap::new();
    // A split set's lines are numbered as it is read: its parts in place
    // of their calls.
    let mut r: Box<dyn BufRead> = match assembled {
        Some(text) => Box::new(std::io::Cursor::new(text.as_bytes())),
        None => Box::new(std::io::BufReader::new(std::fs::File::open(program)?)),
    };
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
