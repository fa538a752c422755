//! A program read back on a thread of its own, piece by piece as its text
//! is spooled: the pieces are handed over as they are written and read in
//! the background, a few ahead at most, so a program of millions of lines
//! is read while the next pieces are planned and is never held whole in
//! memory or read from the disk again (`read_back` takes its findings).

use std::sync::mpsc::{SyncSender, sync_channel};
use std::thread::JoinHandle;

use lensc_runtime::dialect::Dialect;
use lensc_runtime::reader::{Finding, MachineLimits, Reader};

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
    /// Starts reading a program in `dialect` on `machine`.
    pub(crate) fn start(dialect: &Dialect, machine: &MachineLimits) -> ReadAlong {
        let (tx, rx) = sync_channel::<String>(READ_AHEAD);
        let (dialect, machine) = (dialect.clone(), machine.clone());
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
    use lensc_runtime::reader;

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
            servo: None,
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
        for cut in [
            vec![],
            vec![1],
            vec![3, 4, 5],
            vec![26, 27, 57, 58, 62],
            (1..text.len()).collect(),
        ] {
            let mut along = ReadAlong::start(&dialect, &machine);
            let mut from = 0;
            for &to in cut.iter().chain(&[text.len()]) {
                along.read(text[from..to].to_string());
                from = to;
            }
            assert_eq!(along.finish(), whole, "cut at {cut:?}");
        }
    }
}
