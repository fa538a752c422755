//! `lensc check`: check files for errors without building anything: the
//! checker's findings and, once a file checks, every job lowered as `build`
//! lowers it (everything knowable without planning, the limits on its
//! points and program size and the warnings before planning included).

use crate::output::{Output, load};

/// Runs the subcommand; returns the exit code.
pub fn run(out: &Output, files: &[std::path::PathBuf], max_program_size: u64) -> u8 {
    let limits = lensc_build::job::Limits {
        max_program_size,
        ..Default::default()
    };
    let mut code = 0;
    for f in files {
        let Some(c) = load(out, f) else {
            code = 1;
            continue;
        };
        // Everything knowable without planning: each job lowered as
        // `build` lowers it, once the file checks.
        let mut diags = c.diags().to_vec();
        diags.extend(lensc_build::pipeline::findings_before_planning(&c, &limits));
        out.diagnostics(&c, &diags);
        if diags.iter().any(|d| d.is_error()) {
            code = 1;
        }
    }
    code
}
