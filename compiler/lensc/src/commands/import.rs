//! `lensc import FILE [-o OUT.lens]`: reads a lens designer's prescription
//! (a Zemax `.zmx` or an optiland JSON export, `lensc_lang::import`) and
//! writes its surfaces as a `.lens` file in the canonical layout, to `OUT`
//! (atomically) or to stdout. Warnings (what is not carried over) go to
//! stderr; the written text is checked by the checker before anything is
//! written, so a file that would not check is never written.

use std::io::Write;
use std::path::Path;

use lensc::render;
use lensc_build::temps::TempFile;
use lensc_grammar::Diagnostic;
use lensc_lang::loader::RealFs;
use lensc_lang::sandbox;
use lensc_lang::source::SourceMap;

use crate::MessageFormat;
use crate::output::{Output, cannot_write};

/// Runs the subcommand; returns the exit code: 1 if the file could not be
/// read or imported, or the output written.
pub fn run(out: &Output, file: &Path, output: Option<&Path>) -> u8 {
    let name = file.display().to_string();
    let bytes = match sandbox::read_regular(file, sandbox::MAX_FILE_BYTES) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("error[{}]: cannot read {name}: {e}", e.code());
            return 1;
        }
    };
    let imported = lensc_lang::import::import(&name, &bytes);
    let mut sources = SourceMap::default();
    sources.add(name.clone(), Some(file.to_path_buf()), imported.source_text);
    // With the .lens text on stdout, JSON diagnostics go to stderr.
    report(out, &imported.diags, &sources, output.is_none());
    let Some(lens) = imported.lens else {
        return 1;
    };
    let out_name = output.map_or("imported.lens".to_string(), |p| p.display().to_string());
    let checked = lensc_lang::check_text(&RealFs, &out_name, lens.as_bytes());
    if checked.has_errors() {
        eprintln!(
            "error: the .lens text imported from {name} does not check (a bug in `lensc import`; nothing was written):"
        );
        let errors: Vec<Diagnostic> = checked
            .diags()
            .iter()
            .filter(|d| d.is_error())
            .cloned()
            .collect();
        report(out, &errors, &checked.loaded.sources, true);
        return 1;
    }
    match output {
        None => {
            let mut stdout = std::io::stdout().lock();
            let _ = stdout
                .write_all(lens.as_bytes())
                .and_then(|_| stdout.flush());
            0
        }
        Some(path) => match write_atomically(path, &lens) {
            Ok(()) => 0,
            Err(e) => {
                cannot_write(path, &e);
                1
            }
        },
    }
}

fn report(out: &Output, diags: &[Diagnostic], sources: &SourceMap, json_to_stderr: bool) {
    // A closed pipe is no reason to fail.
    let _ = match (out.format, json_to_stderr) {
        (MessageFormat::Human, _) => {
            render::human(diags, sources, out.color, &mut std::io::stderr().lock())
        }
        (MessageFormat::Json, true) => {
            render::json_lines(diags, sources, &mut std::io::stderr().lock())
        }
        (MessageFormat::Json, false) => {
            render::json_lines(diags, sources, &mut std::io::stdout().lock())
        }
    };
}

/// Writes `text` to `path` through a temporary file beside it, renamed
/// into place once whole.
fn write_atomically(path: &Path, text: &str) -> std::io::Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut tmp = TempFile::create_in(dir)?;
    tmp.write_all(text.as_bytes())?;
    tmp.as_file().sync_all()?;
    tmp.persist(path)
}
