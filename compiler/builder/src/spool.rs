//! Spooling a program as it is written: in memory, or in a temporary file
//! in the output directory (the programs of spiral and roller jobs run to
//! millions of lines), so memory stays bounded however long it is, or
//! nowhere (`lensc report` formats none); and the first error met writing
//! it, kept until the program is done.

use crate::job::JobHead;
use lensc_grammar::{Diagnostic, FileId, Span};
use lensc_runtime::post::ProgramError;

use crate::output::{Destination, ProgramText};
use crate::progress::Meter;
use crate::read_along::ReadAlong;
use crate::read_back::ReadBack;

/// Where a text goes as it is written: memory, a spool file, or nowhere.
pub(crate) enum Sink {
    Memory(String),
    File(Spool),
    Nowhere,
}

/// A spool file being written, with what it holds so far and the first
/// error writing it met.
pub(crate) struct Spool {
    writer: std::io::BufWriter<crate::temps::TempFile>,
    lines: usize,
    bytes: u64,
    error: Option<std::io::Error>,
    /// The program read back as it is spooled, if it is to be.
    reader: Option<ReadAlong>,
}

impl Sink {
    /// A sink for `to`; E0151 at `site` if the spool file cannot be made.
    pub(crate) fn new(to: Destination, site: (FileId, Span)) -> Result<Sink, Vec<Diagnostic>> {
        Sink::open(to, None).map_err(|e| vec![cannot_spool(&e, site)])
    }

    /// A sink for `to` whose text, if spooled, is read back (`read`) on a
    /// thread of its own as it is spooled.
    fn open(to: Destination, read: Option<&ReadBack>) -> std::io::Result<Sink> {
        Ok(match to {
            Destination::Memory => Sink::Memory(String::new()),
            Destination::Nowhere => Sink::Nowhere,
            Destination::Spool(dir) => {
                std::fs::create_dir_all(dir)?;
                let file = crate::temps::TempFile::create_in(dir)?;
                Sink::File(Spool {
                    writer: std::io::BufWriter::with_capacity(1 << 20, file),
                    lines: 0,
                    bytes: 0,
                    error: None,
                    reader: read.map(|r| ReadAlong::start(&r.dialect, &r.machine)),
                })
            }
        })
    }

    pub(crate) fn push(&mut self, text: String) {
        match self {
            Sink::Memory(all) => all.push_str(&text),
            Sink::File(spool) => spool.push(text),
            Sink::Nowhere => {}
        }
    }

    /// The whole text; E0151 at `site` if the spool file could not be
    /// written.
    pub(crate) fn finish(self, site: (FileId, Span)) -> Result<ProgramText, Vec<Diagnostic>> {
        match self {
            Sink::Memory(text) => Ok(ProgramText::Memory(text)),
            Sink::File(spool) => spool.finish().map_err(|e| vec![cannot_spool(&e, site)]),
            Sink::Nowhere => Ok(ProgramText::Memory(String::new())),
        }
    }
}

/// The line breaks in `text`, counted 255 bytes at a time into a byte
/// (so the comparison runs on whole vectors of bytes: about ten times
/// `filter(..).count()`'s speed, which widens every byte to a `usize`).
fn line_breaks(text: &[u8]) -> usize {
    text.chunks(255)
        .map(|chunk| {
            let mut n: u8 = 0;
            for &b in chunk {
                n += u8::from(b == b'\n');
            }
            usize::from(n)
        })
        .sum()
}

impl Spool {
    fn push(&mut self, text: String) {
        if self.error.is_none() {
            use std::io::Write;
            self.lines += line_breaks(text.as_bytes());
            self.bytes += text.len() as u64;
            if let Err(e) = self.writer.write_all(text.as_bytes()) {
                self.error = Some(e);
            } else if let Some(r) = self.reader.as_mut() {
                r.read(text);
            }
        }
    }

    fn finish(self) -> std::io::Result<ProgramText> {
        if let Some(e) = self.error {
            return Err(e);
        }
        let file = self.writer.into_inner().map_err(|e| e.into_error())?;
        Ok(ProgramText::Spooled {
            file,
            lines: self.lines,
            bytes: self.bytes,
            read: self.reader,
        })
    }
}

/// A program streamed into a sink piece by piece as it is planned: the
/// first error met writing it is kept, and no more is written after it.
pub(crate) struct ProgramSink<'a> {
    sink: Sink,
    error: Option<ProgramError>,
    /// Counts the points planned and the bytes formatted, for the
    /// build's observer.
    meter: Meter<'a>,
}

impl<'a> ProgramSink<'a> {
    /// A program's sink for `to`; spooled, it is read back (`read`) as
    /// it is spooled.
    pub(crate) fn new(
        to: Destination,
        site: (FileId, Span),
        meter: Meter<'a>,
        read: Option<&ReadBack>,
    ) -> Result<ProgramSink<'a>, Vec<Diagnostic>> {
        Ok(ProgramSink {
            sink: Sink::open(to, read).map_err(|e| vec![cannot_spool(&e, site)])?,
            error: None,
            meter,
        })
    }

    /// `n` more points planned (a revolution's or a pass's at a time).
    pub(crate) fn planned(&mut self, n: usize) {
        self.meter.points(n);
    }

    /// Extends the program with `extend`, unless writing it has failed or
    /// it goes nowhere (then nothing is formatted).
    pub(crate) fn extend(&mut self, extend: impl FnOnce() -> Result<(), ProgramError>) {
        if self.error.is_none()
            && !matches!(self.sink, Sink::Nowhere)
            && let Err(e) = extend()
        {
            self.error = Some(e);
        }
    }

    /// Pushes the text the program has written so far.
    pub(crate) fn push(&mut self, text: Result<String, ProgramError>) {
        match text {
            Ok(t) => {
                self.meter.bytes(t.len());
                self.sink.push(t);
            }
            Err(e) => {
                self.error.get_or_insert(e);
            }
        }
    }

    /// The sink with the whole program in it, or E0150 for the first error
    /// met writing it.
    pub(crate) fn written(self, head: &JobHead) -> Result<Sink, Vec<Diagnostic>> {
        match self.error {
            Some(e) => Err(vec![
                crate::diagnostics::RuntimeError::Program(e).at(head.site),
            ]),
            None => Ok(self.sink),
        }
    }
}

/// E0151: the spool file could not be written.
fn cannot_spool(e: &std::io::Error, site: (FileId, Span)) -> Diagnostic {
    crate::diagnostics::RuntimeError::Spool(e).at(site)
}

#[cfg(test)]
mod tests {
    use super::*;
    use lensc_runtime::dialect::Dialect;
    use lensc_runtime::reader::{self, MachineLimits};

    /// Line breaks counted as `filter(..).count()` counts them: texts of
    /// every length around the 255-byte chunk, all breaks, none, and a
    /// piece of a program.
    #[test]
    fn line_breaks_are_counted() {
        let program = "G1 X3.071257 Z-2.999999 C0.025 F864000.\n".repeat(300);
        let mut texts = vec![String::new(), "\n".repeat(1000), "x".repeat(1000), program];
        for n in [1, 254, 255, 256, 509, 510, 511, 766] {
            texts.push(
                (0..n)
                    .map(|i| if i % 3 == 0 { '\n' } else { 'G' })
                    .collect(),
            );
            texts.push("\n".repeat(n));
        }
        for t in texts {
            let expected = t.bytes().filter(|&b| b == b'\n').count();
            assert_eq!(line_breaks(t.as_bytes()), expected, "{} bytes", t.len());
        }
    }

    /// A program spooled in pieces with its read-back: the file holds the
    /// whole text, and the reader that read it along finds what a reading
    /// of the whole text finds (here a feed over the machine's and no
    /// program end).
    #[test]
    fn a_spooled_program_is_read_as_it_is_written() {
        let read = ReadBack {
            dialect: Dialect::linuxcnc(),
            machine: MachineLimits {
                lathe: true,
                travel: [Some((-10.0, 150.0)), None, Some((-100.0, 100.0)), None],
                max_feed: Some(2000.0),
                max_spindle_rpm: Some(3000.0),
                servo: None,
            },
        };
        let pieces = [
            "G18 G21 G90 G8 G40 G49 G80\nT1 M6\nG97 S5",
            "00 M3\nG0 X3 Z1.5\n",
            "G94 G1 Z0.1 F5000\n",
            "G1 Z0.2\nM5\n",
        ];
        let whole: String = pieces.concat();
        let dir = tempfile::tempdir().expect("a directory");
        let mut sink = Sink::open(Destination::Spool(dir.path()), Some(&read)).expect("a spool");
        for p in pieces {
            sink.push(p.to_string());
        }
        let site = (FileId(0), Span { start: 0, end: 0 });
        let Ok(ProgramText::Spooled {
            file,
            read: Some(along),
            ..
        }) = sink.finish(site)
        else {
            panic!("a spooled program with its reader")
        };
        assert_eq!(std::fs::read_to_string(file.path()).expect("read"), whole);
        let want = reader::read(&whole, &read.dialect, &read.machine);
        let rules: Vec<_> = want.iter().map(|f| f.rule).collect();
        assert!(rules.contains(&reader::Rule::FeedTooHigh), "{want:?}");
        assert!(rules.contains(&reader::Rule::ProgramEnd), "{want:?}");
        assert_eq!(along.finish(), want);
    }
}
