//! `lensc analyse`: analyse a surface over its aperture, as JSON on stdout.

use std::io::Write;
use std::path::Path;

use lensc_build::driver;

use crate::output::{Output, load};

/// Runs the subcommand; returns the exit code.
pub fn run(out: &Output, file: &Path, surface: &str, grid: usize) -> u8 {
    let Some(c) = load(out, file) else { return 1 };
    // A surface with no value over part of its aperture is a warning
    // here (W0022; `check` and `build` refuse it): its points are NaN.
    let mut diags = c.diags().to_vec();
    if !c.has_errors() {
        diags.extend(lensc_build::evaluate::undefined_surfaces(
            &c,
            lensc_grammar::Severity::Warning,
            Some(surface),
        ));
    }
    out.diagnostics(&c, &diags);
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
            let v = driver::surface_analysis(surface, kind, &l, grid.max(2));
            // A closed pipe (`| head`) is not an error.
            let _ = write!(
                std::io::stdout().lock(),
                "{}",
                lensc_build::report::json_text(&v)
            );
            0
        }
        Err(e) => {
            eprintln!("error: {e}");
            2
        }
    }
}
