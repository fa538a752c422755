//! `lensc fmt`: puts `.lens` files in the one canonical layout
//! (`lensc_lang::format`), each rewritten atomically and only if it
//! changes; with `--check`, writes nothing and lists the files that would
//! change. A file that does not parse is reported with the parser's
//! diagnostics and left as it is.

use std::io::Write;
use std::path::Path;

use lensc::render;
use lensc_build::temps::TempFile;
use lensc_lang::sandbox;
use lensc_lang::source::SourceMap;

use crate::MessageFormat;
use crate::output::{Output, cannot_write};

/// Runs the subcommand; returns the exit code: 1 if a file could not be
/// read, parsed or written, or (`--check`) would change.
pub fn run(out: &Output, files: &[std::path::PathBuf], check: bool) -> u8 {
    let mut code = 0;
    for path in files {
        let Some(text) = read(out, path) else {
            code = 1;
            continue;
        };
        let formatted = match lensc_lang::format::format_source(&text) {
            Ok(f) => f,
            Err(diags) => {
                let mut sources = SourceMap::default();
                sources.add(path.display().to_string(), Some(path.clone()), text);
                report(out, &diags, &sources);
                code = 1;
                continue;
            }
        };
        if formatted == text {
            continue;
        }
        if check {
            println!("{}", path.display());
            code = 1;
        } else if let Err(e) = write_in_place(path, &formatted) {
            cannot_write(path, &e);
            code = 1;
        }
    }
    let _ = std::io::stdout().flush();
    code
}

/// The file's text, or `None` once its refusal is reported.
fn read(out: &Output, path: &Path) -> Option<String> {
    let (code, why) = match sandbox::read_regular(path, sandbox::MAX_FILE_BYTES) {
        Ok(bytes) => match String::from_utf8(bytes) {
            Ok(text) => return Some(text),
            Err(_) => (
                lensc_grammar::diagnostic::codes::NOT_UTF8,
                "it is not valid UTF-8".to_string(),
            ),
        },
        Err(e) => (e.code(), e.to_string()),
    };
    let msg = format!("cannot format {}: {why}", path.display());
    match out.format {
        MessageFormat::Human => eprintln!("error[{code}]: {msg}"),
        MessageFormat::Json => println!(
            "{}",
            serde_json::json!({"severity": "error", "code": code, "message": msg,
                "file": path.display().to_string(), "line": 0, "column": 0,
                "span": {"start": 0, "end": 0}, "labels": [], "help": null})
        ),
    }
    None
}

fn report(out: &Output, diags: &[lensc_grammar::Diagnostic], sources: &SourceMap) {
    // A closed pipe is no reason to fail.
    let _ = match out.format {
        MessageFormat::Human => {
            render::human(diags, sources, out.color, &mut std::io::stderr().lock())
        }
        MessageFormat::Json => render::json_lines(diags, sources, &mut std::io::stdout().lock()),
    };
}

/// Replaces the file the path names (through a symbolic link, if it is
/// one) by `text`: a temporary file beside it with its permissions,
/// flushed, then renamed over it, so the file is whole before or after.
fn write_in_place(path: &Path, text: &str) -> std::io::Result<()> {
    let target = std::fs::canonicalize(path)?;
    let dir = target.parent().unwrap_or(Path::new("."));
    let permissions = std::fs::metadata(&target)?.permissions();
    let mut tmp = TempFile::create_in(dir)?;
    tmp.write_all(text.as_bytes())?;
    tmp.as_file().set_permissions(permissions)?;
    tmp.as_file().sync_all()?;
    tmp.persist(&target)
}
