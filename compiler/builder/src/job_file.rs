//! A file a job names (a measurement to compensate from, a tool's edge
//! profile), read as the loader reads a `use`d file: relative to the
//! job's file, beneath the project root, a regular file, at most a stated
//! size; a failure is a diagnostic at the name.

use std::path::Path;

use lensc_grammar::Diagnostic;
use lensc_lang::check::CheckedJob;
use lensc_lang::sandbox;
use lensc_lang::value::Stated;

/// The bytes of the file `name` names for `job`; `what` says what the
/// file is in the message ("the measurement"), `limit` is its largest
/// size in bytes and `limit_words` says it in the help ("measurements of
/// at most 256 MiB are read").
pub(crate) fn read(
    job: &CheckedJob,
    name: &Stated<String>,
    what: &str,
    limit: u64,
    limit_words: &str,
) -> Result<Vec<u8>, Diagnostic> {
    let base = job
        .path
        .as_deref()
        .and_then(Path::parent)
        .unwrap_or(Path::new(""));
    let full = base.join(&name.value);
    let resolved = sandbox::resolve(&full);
    let root = job
        .root
        .as_ref()
        .map(|r| r.path().to_path_buf())
        .unwrap_or_else(|| sandbox::resolve(Path::new(".")));
    let e = if !sandbox::inside(&resolved, &root) {
        sandbox::ReadError::OutsideRoot {
            resolved: resolved.clone(),
            root,
        }
    } else {
        let read = match &job.root {
            Some(r) => r.read(&resolved, limit),
            None => sandbox::read_regular(&resolved, limit),
        };
        match read {
            Ok(b) => return Ok(b),
            Err(e) => e,
        }
    };
    Err(Diagnostic::error(
        e.code(),
        format!("cannot read {what} `{}`: {e}", full.display()),
        name.site.0,
        name.site.1,
    )
    .with_label("named here")
    .with_help(match e {
        sandbox::ReadError::OutsideRoot { .. } => {
            "a job reads only files under its project root (the directory of the file given on the command line unless `--root DIR`)"
        }
        sandbox::ReadError::TooLarge { .. } => limit_words,
        _ => "the path is relative to the job's file",
    }))
}
