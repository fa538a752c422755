//! `lensc view`: build a file's jobs as `build` does (programs read back,
//! parts simulated) and write one self-contained HTML page per job — the
//! backplot of the program as written, the simulated error map on the
//! design surface, the acceptance figures and the set-up — instead of the
//! programs.

use std::path::Path;

use lensc_build::driver;
use lensc_build::view;

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
    // Built as `build` builds them (long programs spooled in the output
    // directory and removed once read), a part that misses its criteria
    // viewed all the same: the page gives its verdict.
    let (outcomes, diags) = driver::plan_and_emit_outcomes(
        &c,
        driver::Request {
            job,
            dialect,
            max_program_size: Some(max_program_size),
            accept: lensc_build::accept::Mode::Warn,
            progress: reporter.observer(),
        },
        &source,
        Some(dir),
    );
    out.diagnostics(&c, &diags);
    if diags.iter().any(|d| d.is_error()) {
        reporter.done(false);
        return 1;
    }
    // Every page is made before any is written.
    let mut pages = Vec::new();
    for b in outcomes.iter().filter_map(|o| o.built.as_ref()) {
        let name = b.report.job.clone();
        let Some(read) = &b.read_back else {
            eprintln!(
                "error: job `{name}`: its program was not read back, so there is nothing to draw"
            );
            reporter.done(false);
            return 1;
        };
        let path = match view::backplot::read(&b.program, read, revolutions(&b.report)) {
            Ok(p) => p,
            Err(e) => {
                eprintln!("error: job `{name}`: cannot read its program back: {e}");
                reporter.done(false);
                return 1;
            }
        };
        let design = driver::declared_surface(&c, &b.report.surface.surface)
            .ok()
            .map(|s| driver::evaluator(&s.tape).0);
        let page = view::page(b, &path, design.as_deref().map(|d| d as _));
        pages.push((name, view::file_name(&b.report.job), page, path));
    }
    let mut code = 0;
    for (job, name, page, path) in pages {
        reporter.writing(&job, page.len() as u64);
        let target = dir.join(&name);
        if let Err(e) =
            driver::output_path(dir, &name).and_then(|p| driver::write_atomic(&p, &page))
        {
            cannot_write(&target, &e);
            code = 1;
            break;
        }
        reporter.wrote(&job, page.len() as u64, page.len() as u64);
        reporter.written(&job, 1, page.len() as u64);
        let thinned = if path.step > 0.0 {
            format!(", thinned to points {:.3} mm apart", path.step)
        } else {
            String::new()
        };
        eprintln!(
            "wrote {} ({} bytes; {} moves drawn as {} segments{thinned})",
            target.display(),
            page.len(),
            path.rapids + path.feeds,
            path.segments()
        );
    }
    reporter.done(code == 0);
    code
}

/// The spindle revolutions a job's cut turns, where its report gives them
/// (a spiral's).
fn revolutions(report: &lensc_build::report::Report) -> Option<usize> {
    report.to_json()["toolpath"]["revolutions"]
        .as_u64()
        .map(|n| n as usize)
}
