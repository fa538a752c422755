//! The writer's common block in one pass: a rapid or a linear move in a
//! G-code dialect that numbers no blocks, in the feed mode already set.
//! Every number is rounded first, then every number's digits are worked
//! out side by side, then the words are stored into one room at the
//! text's end: each number is a long chain of dependent operations, and
//! worked out together their chains overlap, where word after word they
//! ran one after the other. `write_all` hands it two moves at a time:
//! both blocks' numbers are rounded and all their digits worked out
//! before either line is stored, so the chains of two lines overlap too
//! (each stage a loop over the blocks, not a copy of the code per block:
//! the writer's speed is bound by how much code the processor's front end
//! has to fetch as much as by the chains). The second block's modal
//! tests are made against the state the first leaves, as they would be
//! were the first written alone. Anything else (an arc, a feed mode to
//! state, a C axis to switch on, a word a limit refuses, a line too long,
//! a value that cannot print) is left to the general path
//! (`ProgramWriter::motion`), which starts over from the same state: this
//! path keeps nothing unless it writes every block it was given. It
//! prints through the same formatter (`Decimals::units`,
//! `Decimals::digits`, `Digits::store`: what `Decimals::print` is) with
//! the same words, so the bytes are those of the general path;
//! `the_common_block_is_the_general_paths` holds the two to that, move
//! by move and in pairs.

use super::{
    BLOCK_ROOM, FEED_HEAD, FeedMode, INVERSE_TIME_FORMAT, ProgramWriter, SNIPPET_ROOM, Spindle,
    WORD_ROOM, Word, block_room, check_number,
};
use crate::moves::{Feed, Move};
use crate::post::format::{Digits, PRINTED_ROOM};
use std::f64::consts::PI;

/// The most blocks `common_blocks` takes at once.
pub(super) const BLOCKS: usize = 2;

/// A block's numbers: its four axes' (X, Y, Z, C) and its feed's.
const NUMBERS: usize = 5;

/// The feed's place among a block's numbers.
const FEED: usize = 4;

impl ProgramWriter {
    /// Whether this writer's dialect and words let its common blocks go
    /// the one-pass way: G-code without block numbers, the motion words
    /// of rapids and lines and the line end each short enough for a
    /// fixed-size copy.
    pub(super) fn common_blocks_apply(&self) -> bool {
        self.dialect.language == crate::dialect::Language::GCode
            && self.dialect.line_numbers.is_none()
            && self.motion_words[Word::Rapid as usize].len <= SNIPPET_ROOM
            && self.motion_words[Word::Linear as usize].len <= SNIPPET_ROOM
            && self.line_end.len <= SNIPPET_ROOM
    }

    /// Writes the first `count` (1 or 2) of `moves` as common blocks, one
    /// after the other, all or none (false: nothing changed, and the
    /// caller writes them one by one, the general way for a single one).
    /// True: the blocks are written; a single move that changes no
    /// printed axis is left out (as the general path leaves it), while a
    /// pair with such a move in it is not taken.
    #[inline(always)]
    pub(super) fn common_blocks(&mut self, moves: [&Move; BLOCKS], count: usize) -> bool {
        debug_assert!((1..=BLOCKS).contains(&count));
        let count = count.min(BLOCKS);
        if !self.common_blocks || self.start.is_none() {
            return false;
        }
        // Each block's motion word, end, its numbers' values, and which
        // of them it has (bit i: number i; an axis that does not move,
        // NaN, has none); whether its feed is in inverse time (written on
        // every block, with decimals and a limit of its own).
        let mut words = [Word::Rapid; BLOCKS];
        let mut ends = [[f64::NAN; 4]; BLOCKS];
        let mut values = [[0.0; NUMBERS]; BLOCKS];
        let mut has = [0u8; BLOCKS];
        let mut inverse = [false; BLOCKS];
        for k in 0..count {
            let Some((word, axes, feed)) = self.common_move(moves[k]) else {
                return false;
            };
            for i in 0..4 {
                values[k][i] = axes[i] * self.axis_scale[i];
                has[k] |= (!axes[i].is_nan() as u8) << i;
            }
            if let Some((value, inverse_time)) = feed {
                values[k][FEED] = value;
                inverse[k] = inverse_time;
                has[k] |= 1 << FEED;
            }
            words[k] = word;
            ends[k] = axes;
        }
        let [per_unit_limit, inverse_unit_limit] = self.feed_unit_limits;
        let format_of = |k: usize, i: usize| match (i, inverse[k]) {
            (FEED, true) => &INVERSE_TIME_FORMAT,
            (FEED, false) => &self.feed_format,
            _ => &self.axis_formats[i],
        };
        // Every number as a count of units, the blocks' roundings side by
        // side; an axis that cannot print, or that the machine lacks,
        // goes the general way (which refuses it). A feed that does not
        // print, or prints as zero, is refused only if its block is
        // written.
        let mut units = [[0i64; NUMBERS]; BLOCKS];
        let mut feed_prints = [true; BLOCKS];
        for k in 0..count {
            for i in 0..NUMBERS {
                if has[k] & 1 << i == 0 {
                    continue;
                }
                let n = format_of(k, i).units(values[k][i]);
                if i == FEED {
                    feed_prints[k] = n.is_some_and(|n| n > 0);
                } else if n.is_none() || self.letters[i].is_none() {
                    return false;
                }
                units[k][i] = n.unwrap_or(0);
            }
        }
        // The modal tests, block after block: an axis word is written
        // when its printed value changes, the feed word when it changes
        // or in inverse time; each block's values become the modal ones
        // for the next.
        let mut last = self.last;
        let mut last_feed = self.last_feed;
        let mut written = [0u8; BLOCKS];
        for k in 0..count {
            for i in 0..4 {
                if has[k] & 1 << i != 0 {
                    written[k] |= ((last[i] != Some(units[k][i])) as u8) << i;
                    last[i] = Some(units[k][i]);
                }
            }
            if written[k] == 0 {
                // No printed axis changes: a single block is left out
                // (nothing kept), a pair goes one by one.
                return count == 1;
            }
            if has[k] & 1 << FEED != 0 {
                if !feed_prints[k] {
                    return false;
                }
                let n = units[k][FEED];
                written[k] |= ((inverse[k] || last_feed != Some(n)) as u8) << FEED;
                last_feed = Some(n);
            }
        }
        // Every written number's digits, side by side, before any is
        // stored (an unchanged axis's too: which axes change is a coin
        // toss a branch would lose).
        let mut digits = [[Digits::default(); NUMBERS]; BLOCKS];
        for k in 0..count {
            for i in 0..NUMBERS {
                if has[k] & 1 << i != 0 {
                    digits[k][i] = format_of(k, i).digits(units[k][i]);
                }
            }
        }
        // The lines, each where the one before ends (within that one's
        // room, so a block's room follows it); a word over a limit, or a
        // line too long, and none is kept.
        let at = self.text.len();
        let room = block_room::<{ BLOCKS * BLOCK_ROOM }>(&mut self.text, &mut self.zeroed);
        let mut end = 0;
        for k in 0..count {
            let Some(block) = room
                .get_mut(end..)
                .and_then(|r| r.first_chunk_mut::<BLOCK_ROOM>())
            else {
                unreachable!("a block ends within its room")
            };
            let motion_word = &self.motion_words[words[k] as usize];
            block[..SNIPPET_ROOM].copy_from_slice(&motion_word.room);
            let mut pos = motion_word.len;
            let mut fits = true;
            for i in 0..NUMBERS {
                if written[k] & 1 << i != 0 {
                    let (head, limit) = if i < FEED {
                        (&self.axis_heads[i], self.axis_unit_limits[i])
                    } else {
                        let limit = match inverse[k] {
                            true => inverse_unit_limit,
                            false => per_unit_limit,
                        };
                        (&FEED_HEAD, limit)
                    };
                    let (word_end, count) =
                        store_word(block, pos, &head.bytes, head.len, &digits[k][i]);
                    fits &= count <= self.max_digits && units[k][i].unsigned_abs() < limit;
                    pos = word_end;
                }
            }
            // The line's length is where its words end (no prefix here).
            fits &= pos + self.line_end.len - 1 <= self.max_line_length;
            let line_end = block.get_mut(pos..pos + SNIPPET_ROOM);
            let (true, Some(line_end)) = (fits, line_end) else {
                self.text.truncate(at);
                return false;
            };
            line_end.copy_from_slice(&self.line_end.room);
            end += pos + self.line_end.len;
        }
        self.text.truncate(at + end);
        self.last_feed = last_feed;
        for k in 0..count {
            self.moved(&units[k][..4], written[k] & 0xf, ends[k]);
        }
        #[cfg(test)]
        {
            self.common_written += count;
            self.common_pairs += (count == 2) as usize;
        }
        true
    }

    /// A move's motion word, end (X, Y, Z, C) and feed (its value as
    /// printed, and whether it is in inverse time), if it is a rapid or
    /// a line the general path would start without a block of its own:
    /// the C axis switched on before its first move, no feed move with
    /// the spindle stopped (unless the C axis turns the part), and the
    /// feed in the mode already set (its word written before).
    #[inline(always)]
    fn common_move(&self, m: &Move) -> Option<(Word, [f64; 4], Option<(f64, bool)>)> {
        let (word, to, feed) = match m {
            Move::Linear { to, feed } => (Word::Linear, to, feed),
            Move::Rapid(to) => (Word::Rapid, to, &None),
            _ => return None,
        };
        if !to.c.is_nan() && !self.c_axis_on {
            return None;
        }
        if matches!(word, Word::Linear) && self.spindle == Spindle::Stopped && !self.c_axis_on {
            return None;
        }
        let feed = match *feed {
            None => None,
            Some(Feed::InverseTime(t)) if self.mode == Some(FeedMode::InverseTime) => {
                Some((60.0 / t, true))
            }
            Some(Feed::PerTime(v)) if self.mode == Some(FeedMode::PerMinute) => {
                Some((v * 60.0, false))
            }
            Some(Feed::PerRevolution(v)) if self.mode == Some(FeedMode::PerRevolution) => {
                Some((v * 2.0 * PI, false))
            }
            Some(_) => return None,
        };
        Some((word, to.axes(), feed))
    }
}

/// A word, its `head` (a space and its letter, `len` bytes of them) and
/// its number's `digits`, stored at `pos` of the room (which has room
/// for any word from any `pos` a block reaches): its end and its
/// number's count of digits.
#[inline(always)]
fn store_word(
    room: &mut [u8; BLOCK_ROOM],
    pos: usize,
    head: &[u8; 8],
    len: usize,
    digits: &Digits,
) -> (usize, usize) {
    let Some(word) = room
        .get_mut(pos..)
        .and_then(|r| r.first_chunk_mut::<WORD_ROOM>())
    else {
        unreachable!("a block's words fit its room")
    };
    word[..8].copy_from_slice(head);
    // A head is at most five bytes (a space and a letter of up to four).
    let Some(number) = word[len & 7..].first_chunk_mut::<PRINTED_ROOM>() else {
        unreachable!("a word's room holds the longest number")
    };
    let (n_len, count) = digits.store(number);
    debug_assert!(check_number(&number[..n_len]).is_ok());
    (pos + len + n_len, count)
}
