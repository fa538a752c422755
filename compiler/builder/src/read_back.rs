//! Every program a build makes is read back from its text before it is
//! put in place, by the rules of `lensc verify` (`lensc_runtime::reader`):
//! a program the reader refuses is never written, and its job fails with
//! the reader's findings, at the job, each naming the program's line. A
//! spooled program (millions of lines) is read on a thread of its own as
//! its text is spooled (`ReadAlong`), from the pieces in memory: it is
//! not read from the disk again, and it is read while the next pieces are
//! planned; the spool file is still renamed into place only once the
//! reader has passed it.

use std::io::BufReader;
use std::sync::mpsc::{SyncSender, sync_channel};
use std::thread::JoinHandle;

use crate::job::JobHead;
use lensc_grammar::Diagnostic;
use lensc_lang::check::CheckedJob;
use lensc_lang::lower::read_back::job_machine;
use lensc_runtime::dialect::Dialect;
use lensc_runtime::reader::{self, Finding, MachineLimits, Reader};

use crate::output::ProgramText;

/// Whether builds read their programs back before writing them (on since
/// every program is complete: issue 14, item 1). `LENSC_READ_BACK=1`
/// turns it on where this is off.
pub const READ_BACK_BY_DEFAULT: bool = true;

/// Whether this run reads its programs back.
pub fn enabled() -> bool {
    READ_BACK_BY_DEFAULT || std::env::var_os("LENSC_READ_BACK").is_some_and(|v| v == "1")
}

/// What reading a job's program back takes beside its text: the dialect
/// it is written in and the job's machine, as data.
#[derive(Clone, Debug)]
pub struct ReadBack {
    pub dialect: Dialect,
    pub machine: MachineLimits,
}

impl ReadBack {
    /// The read-back of `job`'s program (lowered with `head`).
    pub fn of(job: &CheckedJob, head: &JobHead) -> ReadBack {
        ReadBack {
            dialect: head.dialect.clone(),
            machine: job_machine(job),
        }
    }
}

/// The reader's findings in `program` as errors at the job; none if it
/// reads clean. A program read as it was spooled is not read again: its
/// reader's findings are taken once it has read the whole text.
pub(crate) fn findings(
    job: &CheckedJob,
    head: &JobHead,
    program: &mut ProgramText,
) -> Vec<Diagnostic> {
    let machine = job_machine(job);
    let found = match program {
        ProgramText::Memory(text) => Ok(reader::read(text, &head.dialect, &machine)),
        ProgramText::Spooled {
            read: read @ Some(_),
            ..
        } => Ok(read.take().map(ReadAlong::finish).unwrap_or_default()),
        ProgramText::Spooled { file, .. } => std::fs::File::open(file.path())
            .and_then(|f| reader::read_from(BufReader::new(f), &head.dialect, &machine)),
    };
    let name = head.program_name();
    match found {
        Ok(found) => found
            .iter()
            .map(|f| {
                let d = head.error(
                    lensc_lang::codes::program_rule(f.rule),
                    format!(
                        "{name}, line {}, read back as the controller reads it: {}",
                        f.line, f.message
                    ),
                );
                let help =
                    "no program was written; `lensc verify` reads a program by the same rules";
                d.with_help(match &f.hint {
                    Some(h) => format!("{h}; {help}"),
                    None => help.to_string(),
                })
            })
            .collect(),
        Err(e) => vec![head.error(
            lensc_lang::codes::CANNOT_WRITE,
            format!("{name} could not be read back before writing: {e}"),
        )],
    }
}

/// Pieces of text spooled and not yet read that may wait for the reader:
/// enough to keep it busy while the spooler takes the next revolution, few
/// enough that memory stays flat (a roller revolution is about 0.5 MB).
const READ_AHEAD: usize = 4;

/// A program read back on a thread of its own, piece by piece as its text
/// is spooled, by the same `Reader` and so with the same findings as a
/// reading of the whole text (pieces need not end at a line's end).
pub struct ReadAlong {
    /// `None` once the text has ended.
    pieces: Option<SyncSender<String>>,
    /// `None` once joined.
    thread: Option<JoinHandle<Vec<Finding>>>,
}

impl ReadAlong {
    /// Starts reading a program in `read.dialect` on `read.machine`.
    pub(crate) fn start(read: &ReadBack) -> ReadAlong {
        let (tx, rx) = sync_channel::<String>(READ_AHEAD);
        let ReadBack { dialect, machine } = read.clone();
        let thread = std::thread::spawn(move || {
            let mut r = Reader::new(&dialect, &machine);
            // The start of a line whose end is in a later piece, and the
            // byte offset of each line in the whole text.
            let (mut partial, mut offset) = (String::new(), 0);
            for piece in rx {
                let mut rest = piece.as_str();
                if !partial.is_empty() {
                    let Some(end) = rest.find('\n') else {
                        partial.push_str(rest);
                        continue;
                    };
                    partial.push_str(&rest[..=end]);
                    rest = &rest[end + 1..];
                    r.line(&partial, offset);
                    offset += partial.len();
                    partial.clear();
                }
                // The whole lines; the last one's end is in a later piece.
                let whole = rest.rfind('\n').map_or(0, |end| end + 1);
                offset = r.lines(&rest[..whole], offset);
                partial.push_str(&rest[whole..]);
            }
            if !partial.is_empty() {
                r.line(&partial, offset);
            }
            r.finish()
        });
        ReadAlong {
            pieces: Some(tx),
            thread: Some(thread),
        }
    }

    /// Hands the reader the next piece of the text (it waits while
    /// `READ_AHEAD` pieces are unread).
    pub(crate) fn read(&mut self, piece: String) {
        if let Some(tx) = &self.pieces
            && tx.send(piece).is_err()
        {
            // The reader has stopped: `finish` says why.
            self.pieces = None;
        }
    }

    /// Every finding, once the reader has read the whole text.
    pub(crate) fn finish(mut self) -> Vec<Finding> {
        self.pieces = None;
        match self.thread.take().map(JoinHandle::join) {
            Some(Ok(found)) => found,
            Some(Err(panic)) => std::panic::resume_unwind(panic),
            None => Vec::new(),
        }
    }
}

impl Drop for ReadAlong {
    /// A program abandoned half spooled: the reader stops at the end of
    /// what it was given, and its thread is not left behind.
    fn drop(&mut self) {
        self.pieces = None;
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A program split anywhere reads as the whole text reads: the same
    /// findings at the same lines and byte spans.
    #[test]
    fn pieces_read_as_the_whole_text() {
        let dialect = Dialect::linuxcnc();
        let machine = MachineLimits {
            lathe: true,
            travel: [Some((-10.0, 150.0)), None, Some((-100.0, 100.0)), None],
            max_feed: Some(2000.0),
            max_spindle_rpm: Some(3000.0),
        };
        // Out of travel, a feed too high (twice), an unknown word, a line
        // ending CR LF, and no program end.
        let text = "G18 G21 G90 G8 G40 G49 G80\nT1 M6\nG97 S500 M3\nG0 X3 Z151.5\r\n\
                    G95 G1 Z0.1 F5\nG1 Z0.2 F6 E3\nG0 Z1.5\nM5";
        let whole = reader::read(text, &dialect, &machine);
        let rules: Vec<_> = whole.iter().map(|f| f.rule).collect();
        for rule in [
            reader::Rule::OutsideTravel,
            reader::Rule::FeedTooHigh,
            reader::Rule::UnknownWord,
            reader::Rule::ProgramEnd,
        ] {
            assert!(rules.contains(&rule), "{rule:?} in {whole:?}");
        }
        let read = ReadBack { dialect, machine };
        for cut in [
            vec![],
            vec![1],
            vec![3, 4, 5],
            vec![26, 27, 57, 58, 62],
            (1..text.len()).collect(),
        ] {
            let mut along = ReadAlong::start(&read);
            let mut from = 0;
            for &to in cut.iter().chain(&[text.len()]) {
                along.read(text[from..to].to_string());
                from = to;
            }
            assert_eq!(along.finish(), whole, "cut at {cut:?}");
        }
    }
}
