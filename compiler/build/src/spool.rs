//! Spooling a program as it is written: in memory, or in a temporary file
//! in the output directory (the programs of spiral and roller jobs run to
//! millions of lines), so memory stays bounded however long it is.

use lensc_grammar::{Diagnostic, FileId, Span};
use std::path::Path;

use crate::output::ProgramText;

/// Where the program text goes as it is written: memory, or a spool file.
pub(crate) enum Sink {
    Memory(String),
    File {
        writer: std::io::BufWriter<crate::temps::TempFile>,
        lines: usize,
        bytes: u64,
        error: Option<std::io::Error>,
    },
}

impl Sink {
    pub(crate) fn new(spool_dir: Option<&Path>) -> std::io::Result<Sink> {
        Ok(match spool_dir {
            None => Sink::Memory(String::new()),
            Some(dir) => {
                std::fs::create_dir_all(dir)?;
                let file = crate::temps::TempFile::create_in(dir)?;
                Sink::File {
                    writer: std::io::BufWriter::with_capacity(1 << 20, file),
                    lines: 0,
                    bytes: 0,
                    error: None,
                }
            }
        })
    }

    pub(crate) fn push(&mut self, text: String) {
        match self {
            Sink::Memory(all) => all.push_str(&text),
            Sink::File {
                writer,
                lines,
                bytes,
                error,
            } => {
                if error.is_none() {
                    use std::io::Write;
                    *lines += text.bytes().filter(|&b| b == b'\n').count();
                    *bytes += text.len() as u64;
                    if let Err(e) = writer.write_all(text.as_bytes()) {
                        *error = Some(e);
                    }
                }
            }
        }
    }

    pub(crate) fn finish(self) -> std::io::Result<ProgramText> {
        match self {
            Sink::Memory(text) => Ok(ProgramText::Memory(text)),
            Sink::File {
                writer,
                lines,
                bytes,
                error,
            } => {
                if let Some(e) = error {
                    return Err(e);
                }
                let file = writer.into_inner().map_err(|e| e.into_error())?;
                Ok(ProgramText::Spooled { file, lines, bytes })
            }
        }
    }
}

/// E0151: the spool file could not be written.
pub(crate) fn cannot_spool(e: &std::io::Error, site: (FileId, Span)) -> Diagnostic {
    lensc_lang::lower::diagnostics::RuntimeError::Spool(e).at(site)
}
