//! `lensc build`: check a file and write a program and a report for each of its jobs.

use std::path::Path;

use lensc::summary::{Fate, Program, job_summary};
use lensc_build::driver::{self, Built};

use crate::output::{Output, cannot_write, load_jobs};
use crate::progress::Reporter;

/// Runs the subcommand; returns the exit code. Every job's files are
/// written as one unit when every job passes (all or nothing, the
/// default); with `keep_going`, the jobs that pass are written, as one
/// unit, and the exit code is still 1 if any failed. A summary of each
/// job follows.
pub fn run(
    out: &Output,
    file: &Path,
    request: driver::Request,
    dir: &Path,
    quiet: bool,
    keep_going: bool,
) -> u8 {
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
    let (outcomes, diags) = driver::plan_and_emit_outcomes(&c, request, &source, Some(dir));
    out.diagnostics(&c, &diags);
    let failed = diags.iter().any(|d| d.is_error()) || outcomes.iter().any(|o| !o.accepted);
    let write = !failed || keep_going;
    let mut summaries: Vec<Summary> = outcomes.into_iter().enumerate().map(Summary::of).collect();
    let to_write: Vec<usize> = (0..summaries.len())
        .filter(|&i| write && summaries[i].accepted)
        .collect();
    let written = write_unit(&mut summaries, &to_write, dir, &reporter);
    let code = if failed || written.is_err() { 1 } else { 0 };
    reporter.done(code == 0);
    for s in &summaries {
        let fate = match (&s.fate, s.accepted) {
            (Some((program, report, beside)), _) => Fate::Written {
                program,
                report,
                beside,
            },
            (None, true) if written.is_err() && to_write.contains(&s.index) => Fate::NotWritten,
            (None, true) => Fate::Held,
            (None, false) if s.built.is_some() => Fate::Refused { errors: &s.errors },
            (None, false) => Fate::NotBuilt { errors: &s.errors },
        };
        let built = s.built.as_ref().map(|(r, p)| (r, p));
        eprint!("{}", job_summary(&s.job, &fate, built));
    }
    code
}

/// One job's outcome, its built files taken out to be written.
struct Summary {
    index: usize,
    job: String,
    accepted: bool,
    errors: Vec<&'static str>,
    /// The report and program counts, if it was built.
    built: Option<(lensc_build::report::Report, Program)>,
    /// Its files, until they are written.
    files: Option<Built>,
    /// Where its program, report and the files beside them were written.
    fate: Option<(String, String, Vec<String>)>,
}

impl Summary {
    fn of((index, o): (usize, driver::Outcome)) -> Summary {
        Summary {
            index,
            job: o.job,
            accepted: o.accepted,
            errors: o.errors,
            built: o.built.as_ref().map(|b| {
                (
                    b.report.clone(),
                    Program {
                        lines: b.program.lines(),
                        bytes: b.program.bytes(),
                        cutting_time: b.cutting_time,
                    },
                )
            }),
            files: o.built,
            fate: None,
        }
    }
}

/// The jobs of the file a run builds: `job` alone, or all.
pub fn jobs_asked(c: &driver::Checked, job: Option<&str>) -> usize {
    c.checked
        .jobs
        .iter()
        .filter(|j| job.is_none_or(|n| j.name.name == n))
        .count()
}

/// Puts the files of the jobs `which` (indices into `jobs`) in `dir` as
/// one unit: every file whole in a temporary file beside its target
/// first (a program may already be: it was spooled there), then all
/// renamed together, each job's program last; a failed write or a signal
/// before that leaves the previous files. Records where each job's
/// program and report went.
fn write_unit(
    jobs: &mut [Summary],
    which: &[usize],
    dir: &Path,
    reporter: &Reporter,
) -> Result<(), ()> {
    let mut staged = Vec::new();
    let mut done = Vec::new();
    for &i in which {
        let Some(built) = jobs[i].files.take() else {
            continue;
        };
        let (files, total, placed) = stage_job(built, dir, reporter)?;
        staged.extend(files);
        done.push((i, total, placed));
    }
    if staged.is_empty() {
        return Ok(());
    }
    let first_program = done
        .first()
        .map(|(_, _, (p, _, _))| std::path::PathBuf::from(p))
        .unwrap_or_default();
    if let Err(e) = driver::put_in_place(staged) {
        cannot_write(&first_program, &e);
        return Err(());
    }
    for (i, total, (program, report, beside)) in done {
        reporter.written(&jobs[i].job, 2 + beside.len(), total);
        jobs[i].fate = Some((program, report, beside));
    }
    Ok(())
}

/// Staged temporary files of one job with their targets, its total bytes,
/// and its program's, report's and other files' paths.
type Staged = (
    Vec<(lensc_build::temps::TempFile, std::path::PathBuf)>,
    u64,
    (String, String, Vec<String>),
);

/// One built job's files, each whole in a temporary file in `dir`.
fn stage_job(built: Built, dir: &Path, reporter: &Reporter) -> Result<Staged, ()> {
    let names = std::iter::once(&built.program_name)
        .chain([&built.report_name])
        .chain(built.beside.iter().map(|(name, _)| name));
    for name in names {
        if let Err(e) = driver::output_path(dir, name) {
            cannot_write(&dir.join(name), &e);
            return Err(());
        }
    }
    let job = built.report.job.clone();
    let target = dir.join(&built.program_name);
    let report_path = dir.join(&built.report_name);
    let report = built.report.to_json_text();
    let beside_paths: Vec<String> = built
        .beside
        .iter()
        .map(|(name, _)| dir.join(name).display().to_string())
        .collect();
    let total = report.len() as u64
        + built.program.bytes()
        + built.beside.iter().map(|(_, t)| t.bytes()).sum::<u64>();
    reporter.writing(&job, total);
    let mut so_far = 0;
    let mut staged = Vec::new();
    let files = built
        .beside
        .into_iter()
        .chain([(
            built.report_name.clone(),
            driver::ProgramText::Memory(report),
        )])
        .chain([(built.program_name.clone(), built.program)]);
    for (name, text) in files {
        let path = dir.join(&name);
        let bytes = text.bytes();
        match text.into_temp(dir) {
            Ok(t) => {
                so_far += bytes;
                reporter.wrote(&job, bytes, so_far);
                staged.push((t, path));
            }
            Err(e) => {
                cannot_write(&path, &e);
                return Err(());
            }
        }
    }
    Ok((
        staged,
        total,
        (
            target.display().to_string(),
            report_path.display().to_string(),
            beside_paths,
        ),
    ))
}
