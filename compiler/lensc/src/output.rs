//! How the command talks to people and tools: diagnostics rendered for a
//! terminal or as JSON lines (at most `PER_CODE` of one code, the rest
//! counted), and the loading every subcommand starts with.

use std::collections::HashMap;
use std::io::Write;
use std::path::{Path, PathBuf};

use lensc::render;
use lensc_build::driver::{self, Checked};
use lensc_grammar::Diagnostic;
use lensc_lang::loader::{RealFs, plain_io_error};

use crate::MessageFormat;

/// Diagnostics of one code printed before the rest are only counted.
pub const PER_CODE: usize = 100;

pub struct Output {
    pub format: MessageFormat,
    pub color: bool,
    /// `--root`: the project root (default: each file's directory).
    pub root: Option<PathBuf>,
    /// `--all-diagnostics`: no limit per code.
    pub all_diagnostics: bool,
}

/// Diagnostics of one code left unprinted.
struct Suppressed {
    code: &'static str,
    severity: lensc_grammar::Severity,
    count: usize,
}

impl Output {
    /// Prints `diags`: the first `PER_CODE` of each code, then one summary
    /// line per code for the rest (every one with `--all-diagnostics`).
    pub fn diagnostics(&self, c: &Checked, diags: &[Diagnostic]) {
        let (shown, suppressed) = if self.all_diagnostics {
            (diags.to_vec(), Vec::new())
        } else {
            cap_per_code(diags)
        };
        let file = &c.loaded.sources.get(lensc_grammar::FileId(0)).name;
        let result = match self.format {
            MessageFormat::Human => {
                let mut err = std::io::stderr().lock();
                render::human(&shown, &c.loaded.sources, self.color, &mut err).and_then(|()| {
                    suppressed.iter().try_for_each(|s| {
                        writeln!(err, "{}[{}]: {}", s.severity.as_str(), s.code, summary(s))
                    })
                })
            }
            MessageFormat::Json => {
                let mut out = std::io::stdout().lock();
                render::json_lines(&shown, &c.loaded.sources, &mut out).and_then(|()| {
                    suppressed.iter().try_for_each(|s| {
                        let v = serde_json::json!({"severity": s.severity.as_str(), "code": s.code,
                            "message": summary(s), "suppressed": s.count, "file": file,
                            "line": 0, "column": 0, "span": {"start": 0, "end": 0},
                            "labels": [], "help": null});
                        writeln!(out, "{v}")
                    })
                })
            }
        };
        // A closed pipe is no reason to fail the build.
        let _ = result;
        let _ = std::io::stdout().flush();
    }
}

/// The first `PER_CODE` diagnostics of each code, in order, and the count
/// of the rest per code (in the order their codes were first cut short).
fn cap_per_code(diags: &[Diagnostic]) -> (Vec<Diagnostic>, Vec<Suppressed>) {
    let mut seen: HashMap<&str, usize> = HashMap::new();
    let mut shown = Vec::new();
    let mut suppressed: Vec<Suppressed> = Vec::new();
    for d in diags {
        let n = seen.entry(d.code).or_insert(0);
        *n += 1;
        if *n <= PER_CODE {
            shown.push(d.clone());
        } else if let Some(s) = suppressed.iter_mut().find(|s| s.code == d.code) {
            s.count += 1;
        } else {
            suppressed.push(Suppressed {
                code: d.code,
                severity: d.severity,
                count: 1,
            });
        }
    }
    (shown, suppressed)
}

fn summary(s: &Suppressed) -> String {
    format!(
        "{} more {} diagnostics not shown ({PER_CODE} are; --all-diagnostics shows every one)",
        s.count, s.code
    )
}

/// Whether the checked file has the job asked for (exit 2 if not) and any
/// job at all (exit 1, E-code NO_JOB, if not).
/// Loads and checks `file` for `build` and `report`, printing its
/// diagnostics: the checked file if it has the job(s) asked for, or the
/// exit code (1 for errors in the input, 2 for a `--job` naming no job).
pub fn load_jobs(out: &Output, file: &Path, job: Option<&str>) -> Result<Checked, u8> {
    let Some(c) = load(out, file) else {
        return Err(1);
    };
    out.diagnostics(&c, c.diags());
    if c.has_errors() {
        return Err(1);
    }
    has_jobs(out, &c, file, job)?;
    Ok(c)
}

fn has_jobs(out: &Output, c: &Checked, file: &Path, job: Option<&str>) -> Result<(), u8> {
    if let Some(name) = job
        && !c.checked.jobs.iter().any(|j| j.name.name == name)
    {
        let names: Vec<&str> = c
            .checked
            .jobs
            .iter()
            .map(|j| j.name.name.as_str())
            .collect();
        eprintln!(
            "error: {} has no job `{name}` (its jobs: {})",
            file.display(),
            if names.is_empty() {
                "none".into()
            } else {
                names.join(", ")
            }
        );
        return Err(2);
    }
    if c.checked.jobs.is_empty() {
        let d = lensc_grammar::Diagnostic::error(
            lensc_lang::codes::NO_JOB,
            "this file has no job to build",
            lensc_grammar::FileId(0),
            lensc_grammar::Span::new(0, 0),
        )
        .with_help("add `job NAME { surface: …, tool: …, machine: …, strategy: … }`");
        out.diagnostics(c, &[d]);
        return Err(1);
    }
    Ok(())
}

/// Loads and checks a root file; reports an unreadable file itself.
pub fn load(out: &Output, path: &Path) -> Option<Checked> {
    match driver::check_path_in(&RealFs, path, out.root.as_deref()) {
        Ok(c) => Some(c),
        Err(e) => {
            let msg = format!("cannot read {}: {e}", path.display());
            match out.format {
                MessageFormat::Human => eprintln!("error[{}]: {msg}", e.code()),
                MessageFormat::Json => drop(writeln!(
                    std::io::stdout().lock(),
                    "{}",
                    serde_json::json!({"severity": "error", "code": e.code(), "message": msg,
                        "file": path.display().to_string(), "line": 0, "column": 0,
                        "span": {"start": 0, "end": 0}, "labels": [], "help": null})
                )),
            }
            None
        }
    }
}

/// Reports a file that could not be written (E-code CANNOT_WRITE).
pub fn cannot_write(path: &Path, e: &std::io::Error) {
    eprintln!(
        "error[{}]: cannot write {}: {}",
        lensc_lang::codes::CANNOT_WRITE,
        path.display(),
        plain_io_error(e)
    );
}
