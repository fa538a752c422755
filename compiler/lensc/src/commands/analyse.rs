//! `lensc analyse`: analyse a surface over its aperture, as JSON on stdout.

use std::io::Write;
use std::path::Path;

use lensc_build::driver;

use crate::output::{Output, load};

/// Runs the subcommand; returns the exit code.
pub fn run(out: &Output, file: &Path, surface: &str, grid: usize) -> u8 {
    let Some(c) = load(out, file) else { return 1 };
    out.diagnostics(&c, c.diags());
    if c.has_errors() {
        return 1;
    }
    match driver::declared_surface(&c, surface) {
        Ok(l) => {
            let kind = c
                .checked
                .declarations
                .get(surface)
                .map_or("", |o| o.kind.name);
            let v = driver::analysis_json(surface, kind, &l, grid.max(2));
            // A closed pipe (`| head`) is not an error.
            let _ = writeln!(
                std::io::stdout().lock(),
                "{}",
                serde_json::to_string_pretty(&v).unwrap_or_default()
            );
            0
        }
        Err(e) => {
            eprintln!("error: {e}");
            2
        }
    }
}
