//! How the command talks to people and tools: diagnostics rendered for a
//! terminal or as JSON lines, and the loading every subcommand starts with.

use std::io::Write;
use std::path::Path;

use lensc::render;
use lensc_build::driver::{self, Checked};
use lensc_lang::loader::{RealFs, plain_io_error};

use crate::MessageFormat;

pub struct Output {
    pub format: MessageFormat,
    pub color: bool,
}

impl Output {
    pub fn diagnostics(&self, c: &Checked, diags: &[lensc_grammar::Diagnostic]) {
        let result = match self.format {
            MessageFormat::Human => render::human(
                diags,
                &c.loaded.sources,
                self.color,
                &mut std::io::stderr().lock(),
            ),
            MessageFormat::Json => {
                render::json_lines(diags, &c.loaded.sources, &mut std::io::stdout().lock())
            }
        };
        // A closed pipe is no reason to fail the build.
        let _ = result;
        let _ = std::io::stdout().flush();
    }
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
    match driver::check_path(&RealFs, path) {
        Ok(c) => Some(c),
        Err(e) => {
            let msg = format!("cannot read {}: {}", path.display(), plain_io_error(&e));
            match out.format {
                MessageFormat::Human => {
                    eprintln!("error[{}]: {msg}", lensc_lang::codes::CANNOT_READ)
                }
                MessageFormat::Json => drop(writeln!(
                    std::io::stdout().lock(),
                    "{}",
                    serde_json::json!({"severity": "error", "code": lensc_lang::codes::CANNOT_READ, "message": msg,
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
