//! lensc-lang: the `.lens` front end. The pipeline runs source text →
//! syntax tree (`lensc-grammar`) → checked values (here) → typed jobs and
//! surface IR (here) → toolpaths and programs (`lensc-build` driving
//! `lensc-runtime`) → the `lensc` binary's output.
//!
//! Here files are loaded with their `use`s (`loader`, `source`); names are
//! resolved and every value checked for its unit and range against the
//! schema (`check`: `scope`, `expr`, `params`, `rules`; `schema`, one file
//! per category of kind; `units`, `value`, `codes`); and checked jobs and
//! surfaces are lowered to what the runtime plans (`lower`, with
//! `lower::surface` one file per surface family). Errors are data
//! (`Diagnostic`s with codes and spans); nothing here plans, writes or
//! renders.

pub mod check;
pub mod codes;
pub mod domain;
pub mod loader;
pub mod lower;
pub mod schema;
pub mod source;
pub mod units;
pub mod value;

use std::path::Path;

use lensc_grammar::Diagnostic;
use loader::{FileSystem, Loaded};

/// The result of checking one file: its sources and everything found.
pub struct Checked {
    pub loaded: Loaded,
    pub checked: check::Checked,
}

impl Checked {
    pub fn diags(&self) -> &[Diagnostic] {
        &self.checked.diags
    }
    pub fn has_errors(&self) -> bool {
        self.checked.has_errors()
    }
}

/// Loads and checks `path`. An I/O error on the root file itself is the
/// caller's to report.
pub fn check_path(fs: &dyn FileSystem, path: &Path) -> std::io::Result<Checked> {
    let loaded = loader::load(fs, path)?;
    let checked = check::check(&loaded);
    Ok(Checked { loaded, checked })
}

/// Checks source text given directly.
pub fn check_text(fs: &dyn FileSystem, name: &str, text: &[u8]) -> Checked {
    let loaded = loader::load_text(fs, name, text);
    let checked = check::check(&loaded);
    Checked { loaded, checked }
}
