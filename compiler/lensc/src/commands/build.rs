//! `lensc build`: check a file and write a program and a report for each of its jobs.

use std::path::Path;

use lensc_build::driver::{self, Built};

use crate::output::{Output, cannot_write, load_jobs};
use crate::progress::Reporter;

/// Runs the subcommand; returns the exit code.
pub fn run(out: &Output, file: &Path, request: driver::Request, dir: &Path, quiet: bool) -> u8 {
    crate::interrupt::clean_temporaries(dir);
    let c = match load_jobs(out, file, request.job) {
        Ok(c) => c,
        Err(code) => return code,
    };
    let source = file.display().to_string();
    let reporter = Reporter::new(out, quiet, &source, jobs_asked(&c, request.job));
    let request = driver::Request {
        progress: reporter.observer(),
        ..request
    };
    let (programs, diags) = driver::plan_and_emit(&c, request, &source, Some(dir));
    out.diagnostics(&c, &diags);
    let code = if diags.iter().any(|d| d.is_error()) {
        1
    } else {
        programs
            .into_iter()
            .try_for_each(|built| write_job(built, dir, &reporter))
            .map_or_else(|code| code, |()| 0)
    };
    reporter.done(code == 0);
    code
}

/// The jobs of the file a run builds: `job` alone, or all.
pub fn jobs_asked(c: &driver::Checked, job: Option<&str>) -> usize {
    c.checked
        .jobs
        .iter()
        .filter(|j| job.is_none_or(|n| j.name.name == n))
        .count()
}

/// Puts one built job's files in `dir` as one unit (all written first,
/// then renamed together, the program last) and says what was written.
fn write_job(built: Built, dir: &Path, reporter: &Reporter) -> Result<(), u8> {
    let names = std::iter::once(&built.program_name)
        .chain([&built.report_name])
        .chain(built.beside.iter().map(|(name, _)| name));
    for name in names {
        if let Err(e) = driver::output_path(dir, name) {
            cannot_write(&dir.join(name), &e);
            return Err(1);
        }
    }
    let job = built.report.job.clone();
    let target = dir.join(&built.program_name);
    let report_path = dir.join(&built.report_name);
    let report = built.report.to_json_text();
    let lines = built.program.lines();
    let beside: Vec<String> = built
        .beside
        .iter()
        .map(|(name, text)| format!(", {} ({} lines)", dir.join(name).display(), text.lines()))
        .collect();
    let total = report.len() as u64
        + built.program.bytes()
        + built.beside.iter().map(|(_, t)| t.bytes()).sum::<u64>();
    reporter.writing(&job, total);
    let mut so_far = 0;
    let mut wrote = |bytes: u64| {
        so_far += bytes;
        reporter.wrote(&job, bytes, so_far);
    };
    // Every file whole in a temporary file beside its target first (the
    // program may already be: it was spooled there), then all put in
    // place as one unit: a failed write or a signal before that leaves the
    // previous files, and the unit is renamed whole (program last).
    let stage = |name: &str, text: driver::ProgramText| {
        let path = dir.join(name);
        let bytes = text.bytes();
        text.into_temp(dir)
            .map(|t| (t, path.clone(), bytes))
            .map_err(|e| (path, e))
    };
    let mut staged = Vec::new();
    let mut failed = None;
    let files = built
        .beside
        .into_iter()
        .chain([(
            built.report_name.clone(),
            driver::ProgramText::Memory(report),
        )])
        .chain([(built.program_name.clone(), built.program)]);
    for (name, text) in files {
        match stage(&name, text) {
            Ok((t, path, bytes)) => {
                wrote(bytes);
                staged.push((t, path));
            }
            Err(e) => {
                failed = Some(e);
                break;
            }
        }
    }
    let written = match failed {
        Some(e) => Err(e),
        None => driver::put_in_place(staged).map_err(|e| (target.clone(), e)),
    };
    if let Err((path, e)) = written {
        cannot_write(&path, &e);
        return Err(1);
    }
    reporter.written(&job, 2 + beside.len(), total);
    eprintln!(
        "wrote {} ({} lines, {} cut points, estimated cutting time {:.1} s){} and {}",
        target.display(),
        lines,
        built.cut_points,
        built.cutting_time,
        beside.concat(),
        report_path.display()
    );
    Ok(())
}
