//! `lensc report`: plan and simulate a file's jobs and write SVG plots of what each program will cut.

use std::path::Path;

use lensc_build::driver;

use crate::output::{Output, cannot_write, load_jobs};

/// Runs the subcommand; returns the exit code.
pub fn run(out: &Output, file: &Path, job: Option<&str>, dir: &Path, max_program_size: u64) -> u8 {
    crate::interrupt::clean_temporaries(dir);
    let c = match load_jobs(out, file, job) {
        Ok(c) => c,
        Err(code) => return code,
    };
    // The programs are built as `build` builds them (spooled into
    // the output directory and dropped: only the plots are kept), a part
    // that misses its acceptance criteria plotted all the same (warned):
    // the plots show where.
    let (built, diags) = driver::plan_and_emit(
        &c,
        driver::Request {
            job,
            dialect: None,
            max_program_size: Some(max_program_size),
            accept: lensc_build::accept::Mode::Warn,
        },
        &file.display().to_string(),
        Some(dir),
    );
    out.diagnostics(&c, &diags);
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
            Ok(files) => plots.extend(files),
            Err(e) => {
                eprintln!("error: job `{name}`: {e}");
                return 101;
            }
        }
    }
    for (name, svg) in plots {
        let path = dir.join(&name);
        if let Err(e) = driver::output_path(dir, &name).and_then(|p| driver::write_atomic(&p, &svg))
        {
            cannot_write(&path, &e);
            return 1;
        }
        eprintln!("wrote {} ({} bytes)", path.display(), svg.len());
    }
    0
}
