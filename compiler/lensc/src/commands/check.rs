//! `lensc check`: check files for errors without building anything.

use crate::output::{Output, load};

/// Runs the subcommand; returns the exit code.
pub fn run(out: &Output, files: &[std::path::PathBuf]) -> u8 {
    let mut code = 0;
    for f in files {
        let Some(c) = load(out, f) else {
            code = 1;
            continue;
        };
        out.diagnostics(&c, c.diags());
        if c.has_errors() {
            code = 1;
        }
    }
    code
}
