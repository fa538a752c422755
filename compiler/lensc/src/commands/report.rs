//! `lensc report`: plan and simulate a file's jobs and write SVG plots of what each program will cut.

use std::path::Path;

use lensc_build::driver;

use crate::commands::build::jobs_asked;
use crate::output::{Output, cannot_write, load_jobs};
use crate::progress::Reporter;

/// Runs the subcommand; returns the exit code.
pub fn run(
    out: &Output,
    file: &Path,
    (job, dialect): (Option<&str>, Option<&str>),
    dir: &Path,
    max_program_size: u64,
    quiet: bool,
) -> u8 {
    crate::interrupt::clean_temporaries(dir);
    let c = match load_jobs(out, file, job) {
        Ok(c) => c,
        Err(code) => return code,
    };
    let source = file.display().to_string();
    let reporter = Reporter::new(out, quiet, &source, jobs_asked(&c, job));
    let code = plot(
        out,
        &c,
        (&source, job, dialect),
        dir,
        max_program_size,
        &reporter,
    );
    reporter.done(code == 0);
    code
}

/// Plans and simulates the jobs, the reporter following, and writes
/// their plots; returns the exit code.
fn plot(
    out: &Output,
    c: &driver::Checked,
    (source, job, dialect): (&str, Option<&str>, Option<&str>),
    dir: &Path,
    max_program_size: u64,
    reporter: &Reporter,
) -> u8 {
    // The jobs are planned and simulated as `build` does them; no program
    // is formatted (only the plots are kept), a part that misses its
    // acceptance criteria plotted all the same (warned): the plots show
    // where.
    let (built, diags) = driver::plan_and_simulate(
        c,
        driver::Request {
            job,
            dialect,
            max_program_size: Some(max_program_size),
            accept: lensc_build::accept::Mode::Warn,
            progress: reporter.observer(),
        },
        source,
    );
    out.diagnostics(c, &diags);
    if diags.iter().any(|d| d.is_error()) {
        return 1;
    }
    // Every plot is drawn before any is written.
    let mut plots = Vec::new();
    for b in built {
        let name = b.report.job.clone();
        match lensc_build::plots::render(&name, &b.plots) {
            Ok(files) if files.is_empty() => eprintln!(
                "note: job `{name}` has nothing to plot: its simulation was skipped ({})",
                match &b.report.simulation {
                    lensc_build::report::Simulation::Skipped(s) => s.skipped,
                    _ => "no simulation",
                }
            ),
            Ok(files) => plots.push((name, files)),
            Err(e) => {
                eprintln!("error: job `{name}`: {e}");
                return 101;
            }
        }
    }
    for (job, files) in plots {
        let total = files.iter().map(|(_, svg)| svg.len() as u64).sum();
        reporter.writing(&job, total);
        let mut so_far = 0;
        let mut lines = Vec::new();
        for (name, svg) in &files {
            let path = dir.join(name);
            if let Err(e) =
                driver::output_path(dir, name).and_then(|p| driver::write_atomic(&p, svg))
            {
                cannot_write(&path, &e);
                return 1;
            }
            so_far += svg.len() as u64;
            reporter.wrote(&job, svg.len() as u64, so_far);
            lines.push(format!("wrote {} ({} bytes)", path.display(), svg.len()));
        }
        reporter.written(&job, files.len(), total);
        for line in lines {
            eprintln!("{line}");
        }
    }
    0
}
