//! lensc-lang: the `.lens` front end. The pipeline runs source text →
//! syntax tree (`lensc-grammar`) → checked values (here) → typed jobs and
//! surface IR (here) → toolpaths and programs (`lensc-build` driving
//! `lensc-runtime`) → the `lensc` binary's output.
//!
//! Here files are loaded with their `use`s (`loader`, `source`; `sandbox`
//! the files a job may read); names are
//! resolved and every value checked for its unit and range against the
//! schema (`check`: `scope`, `expr`, `params`, `rules`; `schema`, one file
//! per category of kind; `units`, `value`, `codes`; `stdlib` the standard
//! library's items and their documentation); and checked jobs and
//! surfaces are lowered to what the runtime plans (`lower`, with
//! `lower::surface` one file per surface family, `domain` the apertures both
//! share); `format` is `lensc fmt`'s canonical layout; `import` reads lens
//! designers' prescriptions (Zemax, optiland) and writes them as `.lens` text;
//! `reference` renders the book's language reference (docs/reference/) from
//! the schema, the standard library and the codes' explanations. Errors are data
//! (`Diagnostic`s with codes and spans; `lower::diagnostics` maps every runtime
//! error to one); nothing here plans, writes or renders.

pub mod check;
pub mod codes;
pub mod domain;
pub mod explain;
pub mod format;
pub mod import;
pub mod loader;
pub mod lower;
pub mod reference;
pub mod sandbox;
pub mod schema;
pub mod source;
pub mod stdlib;
pub mod units;
pub mod value;

use std::path::Path;

use lensc_grammar::Diagnostic;
use loader::{FileSystem, Loaded};
use sandbox::ReadError;

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

/// Loads and checks `path`, with the directory it is in as the project
/// root. An error reading the file itself is the caller's to report.
pub fn check_path(fs: &dyn FileSystem, path: &Path) -> Result<Checked, ReadError> {
    check_path_in(fs, path, None)
}

/// Loads and checks `path` with `root` as the project root (`None`: the
/// directory `path` is in); `path` must lie inside it.
pub fn check_path_in(
    fs: &dyn FileSystem,
    path: &Path,
    root: Option<&Path>,
) -> Result<Checked, ReadError> {
    let loaded = loader::load_in(fs, path, root)?;
    let checked = check::check(&loaded);
    Ok(Checked { loaded, checked })
}

/// Checks source text given directly.
pub fn check_text(fs: &dyn FileSystem, name: &str, text: &[u8]) -> Checked {
    let loaded = loader::load_text(fs, name, text);
    let checked = check::check(&loaded);
    Checked { loaded, checked }
}
