//! One motion block as it is printed, straight into the program text:
//! room for the longest block the dialect's words allow is added to the
//! text and cut back to the block once it is done, and where the block
//! ends is a local count (in a register, not the text's length in
//! memory). Every piece goes in as a copy of fixed size (a word prefix's
//! 16 bytes, a number's 24) and the count moves on by the piece's length;
//! nothing written is read back (a copy of the block elsewhere would read
//! the pieces' overlapping stores back, which the processor cannot
//! forward: a stall per load).

use crate::post::format::{PRINTED_ROOM, print_units_at};

/// Bytes every short snippet is copied as.
pub(super) const SNIPPET_ROOM: usize = 16;

/// A short piece of program text (a word's letter, a motion word, a
/// block end), kept in a fixed array so appending it is a copy of fixed
/// size (no call to `memcpy`); longer pieces as they are.
pub(super) struct Snippet {
    room: [u8; SNIPPET_ROOM],
    len: usize,
    long: Box<[u8]>,
}

impl Snippet {
    pub(super) fn new(text: &str) -> Snippet {
        let b = text.as_bytes();
        let mut room = [0; SNIPPET_ROOM];
        if b.len() <= SNIPPET_ROOM {
            room[..b.len()].copy_from_slice(b);
        }
        Snippet {
            room,
            len: b.len(),
            long: if b.len() > SNIPPET_ROOM {
                b.into()
            } else {
                Box::default()
            },
        }
    }

    /// The room a block keeps for it: its length, at least a fixed copy.
    pub(super) fn room(&self) -> usize {
        self.len.max(SNIPPET_ROOM)
    }

    /// Appends it to the program text.
    #[inline]
    pub(super) fn push_to(&self, text: &mut Vec<u8>) {
        if self.len <= SNIPPET_ROOM {
            let at = text.len();
            text.extend_from_slice(&self.room);
            text.truncate(at + self.len);
        } else {
            text.extend_from_slice(&self.long);
        }
    }
}

/// The room a block keeps for a number (`print_units_at` writes a whole
/// `PRINTED_ROOM`, whatever the number's length).
pub(super) const NUMBER_ROOM: usize = PRINTED_ROOM;

/// A block being printed into the room at the end of the program text.
/// The room is sized for the longest block (`ProgramWriter::blank` adds
/// up every piece's room), so a piece past its end is a bug, caught by
/// the slices' bounds checks, never written over.
pub(super) struct Block<'a> {
    room: &'a mut [u8],
    len: usize,
}

impl<'a> Block<'a> {
    #[inline(always)]
    pub(super) fn new(room: &'a mut [u8]) -> Self {
        Block { room, len: 0 }
    }

    /// The block's text so far.
    #[inline(always)]
    pub(super) fn as_bytes(&self) -> &[u8] {
        &self.room[..self.len]
    }

    /// The block's length so far.
    #[inline(always)]
    pub(super) fn len(&self) -> usize {
        self.len
    }

    #[inline(always)]
    pub(super) fn push(&mut self, b: u8) {
        self.room[self.len] = b;
        self.len += 1;
    }

    #[inline(always)]
    pub(super) fn push_bytes(&mut self, b: &[u8]) {
        self.room[self.len..self.len + b.len()].copy_from_slice(b);
        self.len += b.len();
    }

    #[inline(always)]
    pub(super) fn push_snippet(&mut self, s: &Snippet) {
        if s.len <= SNIPPET_ROOM {
            self.room[self.len..self.len + SNIPPET_ROOM].copy_from_slice(&s.room);
            self.len += s.len;
        } else {
            self.push_bytes(&s.long);
        }
    }

    /// Appends `n` units of 10^−`decimals` as the formatter prints them;
    /// returns the number's bytes and its count of digits.
    #[inline(always)]
    pub(super) fn push_units(&mut self, n: i64, decimals: u32) -> (&[u8], usize) {
        let at = self.len;
        let room: &mut [u8; PRINTED_ROOM] = match self.room.get_mut(at..at + PRINTED_ROOM) {
            Some(r) => r.try_into().expect("a slice of the room's length"),
            None => panic!("a block longer than the room sized for it"),
        };
        let (len, digits) = print_units_at(room, n, decimals);
        self.len += len;
        (&self.room[at..at + len], digits)
    }
}
