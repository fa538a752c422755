//! `lensc build`: check a file and write a program and a report for each of its jobs.

use std::path::Path;

use lensc_build::driver;

use crate::output::{Output, cannot_write, load_jobs};

/// Runs the subcommand; returns the exit code.
pub fn run(out: &Output, file: &Path, request: driver::Request, dir: &Path) -> u8 {
    crate::interrupt::clean_temporaries(dir);
    let c = match load_jobs(out, file, request.job) {
        Ok(c) => c,
        Err(code) => return code,
    };
    let (programs, diags) =
        driver::plan_and_emit(&c, request, &file.display().to_string(), Some(dir));
    out.diagnostics(&c, &diags);
    if diags.iter().any(|d| d.is_error()) {
        return 1;
    }
    for built in programs {
        let names = std::iter::once(&built.program_name)
            .chain([&built.report_name])
            .chain(built.beside.iter().map(|(name, _)| name));
        for name in names {
            if let Err(e) = driver::output_path(dir, name) {
                cannot_write(&dir.join(name), &e);
                return 1;
            }
        }
        let target = dir.join(&built.program_name);
        let report_path = dir.join(&built.report_name);
        let report = built.report.to_json_text();
        let lines = built.program.lines();
        let beside: Vec<String> = built
            .beside
            .iter()
            .map(|(name, text)| format!(", {} ({} lines)", dir.join(name).display(), text.lines()))
            .collect();
        // The report is written first: a program on disk always has
        // its report beside it.
        let mut written =
            driver::write_atomic(&report_path, &report).map_err(|e| (report_path.clone(), e));
        // Then what the program reads, then the program.
        for (name, text) in built.beside {
            let path = dir.join(&name);
            written = written.and_then(|()| text.write_to(&path).map_err(|e| (path, e)));
        }
        let written = written.and_then(|()| {
            built
                .program
                .write_to(&target)
                .map_err(|e| (target.clone(), e))
        });
        if let Err((path, e)) = written {
            cannot_write(&path, &e);
            return 1;
        }
        eprintln!(
            "wrote {} ({} lines, {} cut points, estimated cutting time {:.1} s){} and {}",
            target.display(),
            lines,
            built.cut_points,
            built.cutting_time,
            beside.concat(),
            report_path.display()
        );
    }
    0
}
