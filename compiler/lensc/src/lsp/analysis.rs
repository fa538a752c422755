//! The open documents and what the checker makes of each: the texts the
//! editor holds (read in place of the files on disk, so a `use` of an
//! unsaved file sees its unsaved text), each document checked as `lensc
//! check` checks a file (its jobs lowered too when opened or saved), its
//! diagnostics in the protocol's terms, where a
//! name is declared, and the standard library's embedded files written out
//! to a cache directory so an editor can open them.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use lensc_grammar::ast::{ItemKind, Span};
use lensc_grammar::{Diagnostic, FileId, Severity};
use lensc_lang::loader::{FileSystem, Import, RealFs, Root, STDLIB};
use lensc_lang::sandbox::{MAX_FILE_BYTES, ReadError};
use lsp_types::{self as lsp, Uri};

use super::text::{LineIndex, path_to_uri, uri_to_path};

/// The open documents by their URI's text (a `Uri` caches parts of
/// itself in cells, so it is no map key).
pub type Docs = HashMap<String, Document>;

/// A document the editor has open.
pub struct Document {
    pub uri: Uri,
    pub text: String,
    /// Its file, resolved, for `file://` documents.
    pub path: Option<PathBuf>,
    /// The size of a text over the limit of what lensc reads
    /// (`sandbox::MAX_FILE_BYTES`, as `lensc check` refuses such a file):
    /// its text is not kept, and it is not checked.
    pub too_large: Option<u64>,
}

impl Document {
    pub fn new(uri: Uri, text: String) -> Document {
        let path = document_path(&uri);
        let mut d = Document {
            uri,
            text: String::new(),
            path,
            too_large: None,
        };
        d.set_text(text);
        d
    }

    /// Replaces the text, or drops it when it is over the limit.
    pub fn set_text(&mut self, text: String) {
        if text.len() as u64 > MAX_FILE_BYTES {
            self.too_large = Some(text.len() as u64);
            self.text = String::new();
        } else {
            self.too_large = None;
            self.text = text;
        }
    }

    fn refusal(&self) -> Option<ReadError> {
        self.too_large.map(|bytes| ReadError::TooLarge {
            bytes,
            limit: MAX_FILE_BYTES,
        })
    }
}

/// The documents open, read before the disk.
pub struct Overlay<'d> {
    pub docs: &'d Docs,
}

impl FileSystem for Overlay<'_> {
    fn read(&self, root: &Root, path: &Path) -> Result<Vec<u8>, ReadError> {
        match self.docs.values().find(|d| d.path.as_deref() == Some(path)) {
            Some(d) => match d.refusal() {
                Some(e) => Err(e),
                None => Ok(d.text.clone().into_bytes()),
            },
            None => RealFs.read(root, path),
        }
    }
    fn canonical(&self, path: &Path) -> PathBuf {
        RealFs.canonical(path)
    }
}

/// One document checked.
pub struct Analysis {
    pub checked: lensc_lang::Checked,
    /// What `lensc check` finds beyond the checker once the file checks
    /// (each job lowered: refusals, limits, warnings before planning),
    /// worked out when the document is opened or saved (`lower_jobs`);
    /// empty after a change, until the next save.
    pub before_planning: Vec<Diagnostic>,
    /// Why the document could not be checked at all (outside the root,
    /// over the size limit): its code and the reason.
    pub refused: Option<(&'static str, String)>,
}

/// Checks the document `uri`: with the workspace root as the project root
/// when the document lies inside it, else the document's directory.
pub fn analyse(docs: &Docs, root: Option<&Path>, uri: &str) -> Option<Analysis> {
    let doc = docs.get(uri)?;
    let fs = Overlay { docs };
    if let Some(e) = doc.refusal() {
        return Some(Analysis {
            checked: lensc_lang::check_text(&fs, uri, b"let unchecked = 0"),
            before_planning: Vec::new(),
            refused: Some((e.code(), e.to_string())),
        });
    }
    let Some(path) = &doc.path else {
        let c = lensc_lang::check_text(&fs, uri, doc.text.as_bytes());
        return Some(Analysis {
            checked: c,
            before_planning: Vec::new(),
            refused: None,
        });
    };
    let root = root
        .map(|r| fs.canonical(r))
        .filter(|r| path.starts_with(r));
    match lensc_lang::check_path_in(&fs, path, root.as_deref()) {
        Ok(c) => Some(Analysis {
            checked: c,
            before_planning: Vec::new(),
            refused: None,
        }),
        Err(e) => Some(Analysis {
            checked: lensc_lang::check_text(&fs, uri, b"let unchecked = 0"),
            before_planning: Vec::new(),
            refused: Some((e.code(), e.to_string())),
        }),
    }
}

impl Analysis {
    /// Lowers the document's jobs as `lensc check` does (the default
    /// limits), for what only lowering finds: it plans nothing, but takes
    /// longer than checking (a raster's contact search, a spiral's
    /// estimate), so it runs when a document is opened or saved, not on
    /// every keystroke.
    pub fn lower_jobs(&mut self) {
        if self.refused.is_none() {
            let limits = lensc_build::job::Limits::default();
            self.before_planning =
                lensc_build::pipeline::findings_before_planning(&self.checked, &limits);
        }
    }
}

/// Where the standard library's files are written for an editor to open:
/// `$XDG_CACHE_HOME/lensc/std-HASH/` (else `~/.cache`, else the temporary
/// directory), named by a hash of their text so two versions of lensc
/// never share one. Written once, read-only; looked for once a session.
pub fn stdlib_dir() -> Option<&'static Path> {
    static DIR: std::sync::OnceLock<Option<PathBuf>> = std::sync::OnceLock::new();
    DIR.get_or_init(|| match write_stdlib() {
        Ok(d) => Some(d),
        Err(e) => {
            eprintln!("lensc lsp: cannot write the standard library for the editor: {e}");
            None
        }
    })
    .as_deref()
}

fn write_stdlib() -> std::io::Result<PathBuf> {
    let base = std::env::var_os("XDG_CACHE_HOME")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))
        .unwrap_or_else(std::env::temp_dir);
    // FNV-1a over every module's name and text.
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    for (name, text) in STDLIB {
        for b in name.bytes().chain(text.bytes()) {
            hash = (hash ^ u64::from(b)).wrapping_mul(0x100_0000_01b3);
        }
    }
    let dir = base.join("lensc").join(format!("std-{hash:016x}"));
    std::fs::create_dir_all(&dir)?;
    for (name, text) in STDLIB {
        let file = dir.join(format!("{name}.lens"));
        if std::fs::read_to_string(&file).ok().as_deref() != Some(*text) {
            let tmp = dir.join(format!(".{name}.lens.{}", std::process::id()));
            std::fs::write(&tmp, text)?;
            let mut perms = std::fs::metadata(&tmp)?.permissions();
            perms.set_readonly(true);
            std::fs::set_permissions(&tmp, perms)?;
            std::fs::rename(&tmp, &file)?;
        }
    }
    Ok(dir)
}

/// The URI an editor opens for a loaded source: the document itself, a
/// file on disk, or the standard library's copy in the cache.
pub fn source_uri(a: &Analysis, doc_uri: &Uri, file: FileId) -> Option<Uri> {
    if file == FileId(0) {
        return Some(doc_uri.clone());
    }
    let src = a.checked.loaded.sources.get(file);
    match &src.path {
        Some(p) => Some(path_to_uri(&absolute(p))),
        None => {
            let module = src.name.strip_prefix("std/")?;
            Some(path_to_uri(&stdlib_dir()?.join(module)))
        }
    }
}

fn absolute(p: &Path) -> PathBuf {
    std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf())
}

/// Where `name`, as the root document sees it, is declared: its own
/// `let`s and declarations first, then what its `use`s bring, in order
/// (the dialects every file sees come last).
pub fn declaration(a: &Analysis, name: &str) -> Option<(FileId, Span)> {
    let loaded = &a.checked.loaded;
    let root = loaded.files.first()?;
    if let Some(span) = declared_in(a, root.id, name) {
        return Some((root.id, span));
    }
    root.imports.iter().find_map(|imp| match imp {
        Import::One { file, name: n } if n.name == name => {
            declared_in(a, *file, name).map(|s| (*file, s))
        }
        Import::All { file, .. } => declared_in(a, *file, name).map(|s| (*file, s)),
        Import::One { .. } => None,
    })
}

/// Where `name` is declared at the top level of `file`.
pub fn declared_in(a: &Analysis, file: FileId, name: &str) -> Option<Span> {
    a.checked
        .loaded
        .file(file)
        .ast
        .items
        .iter()
        .find_map(|item| match &item.kind {
            ItemKind::Let { name: n, .. } | ItemKind::Decl { name: n, .. } if n.name == name => {
                Some(n.span)
            }
            _ => None,
        })
}

/// The document's diagnostics in the protocol's terms. A diagnostic
/// whose place is in a file the document uses is shown on the `use` that
/// brings that file in (at the top when it came in through another file),
/// with its place as related information.
pub fn diagnostics(a: &Analysis, doc_uri: &Uri, text: &str) -> Vec<lsp::Diagnostic> {
    let ix = LineIndex::new(text);
    if let Some((code, why)) = &a.refused {
        return vec![lsp::Diagnostic {
            range: ix.range(0, 0),
            severity: Some(lsp::DiagnosticSeverity::ERROR),
            code: Some(lsp::NumberOrString::String(code.to_string())),
            source: Some("lensc".into()),
            message: format!("lensc cannot check this file: {why}"),
            ..Default::default()
        }];
    }
    a.checked
        .diags()
        .iter()
        .chain(&a.before_planning)
        .map(|d| to_lsp(a, doc_uri, &ix, d))
        .collect()
}

fn to_lsp(a: &Analysis, doc_uri: &Uri, ix: &LineIndex, d: &Diagnostic) -> lsp::Diagnostic {
    let primary = d.primary();
    let mut message = d.message.clone();
    if !primary.message.is_empty() {
        message = format!("{message}: {}", primary.message);
    }
    if let Some(help) = &d.help {
        message = format!("{message}\nhelp: {help}");
    }
    let mut related = Vec::new();
    let range = if primary.file == FileId(0) {
        ix.range(primary.span.start as usize, primary.span.end as usize)
    } else {
        if let Some(loc) = location(a, doc_uri, primary.file, primary.span) {
            related.push(lsp::DiagnosticRelatedInformation {
                location: loc,
                message: if primary.message.is_empty() {
                    d.message.clone()
                } else {
                    primary.message.clone()
                },
            });
        }
        let name = &a.checked.loaded.sources.get(primary.file).name;
        message = format!("in {name}: {message}");
        let at = use_of(a, primary.file).unwrap_or_default();
        ix.range(at.start as usize, at.end as usize)
    };
    for l in &d.labels[1..] {
        if let Some(loc) = location(a, doc_uri, l.file, l.span) {
            related.push(lsp::DiagnosticRelatedInformation {
                location: loc,
                message: l.message.clone(),
            });
        }
    }
    lsp::Diagnostic {
        range,
        severity: Some(match d.severity {
            Severity::Error => lsp::DiagnosticSeverity::ERROR,
            Severity::Warning => lsp::DiagnosticSeverity::WARNING,
        }),
        code: Some(lsp::NumberOrString::String(d.code.to_string())),
        source: Some("lensc".into()),
        message,
        related_information: (!related.is_empty()).then_some(related),
        ..Default::default()
    }
}

/// The root document's `use` that brings `file` in directly.
fn use_of(a: &Analysis, file: FileId) -> Option<Span> {
    let root = a.checked.loaded.files.first()?;
    root.imports.iter().find_map(|imp| match imp {
        Import::All { file: f, span } if *f == file && span.end > span.start => Some(*span),
        Import::One { file: f, name } if *f == file => Some(name.span),
        _ => None,
    })
}

/// A span of a loaded source as a protocol location.
pub fn location(a: &Analysis, doc_uri: &Uri, file: FileId, span: Span) -> Option<lsp::Location> {
    let uri = source_uri(a, doc_uri, file)?;
    let text = &a.checked.loaded.sources.get(file).text;
    let ix = LineIndex::new(text);
    Some(lsp::Location::new(
        uri,
        ix.range(span.start as usize, span.end as usize),
    ))
}

/// The document's path, resolved, for a `file://` URI.
pub fn document_path(uri: &Uri) -> Option<PathBuf> {
    uri_to_path(uri).map(|p| RealFs.canonical(&p))
}
