//! The writer's common block in one pass: a rapid or a linear move in a
//! G-code dialect that numbers no blocks, in the feed mode already set.
//! Every number is rounded first, then every number's digits are worked
//! out side by side, then the words are stored into one room at the
//! text's end: each number is a long chain of dependent operations, and
//! worked out together their chains overlap, where word after word they
//! ran one after the other. Anything else (an arc, a feed mode to state,
//! a C axis to switch on, a word a limit refuses, a line too long, a
//! value that cannot print) is left to the general path
//! (`ProgramWriter::motion`), which starts over from the same state: this
//! path keeps nothing unless it writes the block. It prints through the
//! same formatter (`Decimals::units`, `Decimals::digits`,
//! `Digits::store`: what `Decimals::print` is) with the same words, so
//! the bytes are those of the general path;
//! `the_common_block_is_the_general_paths` holds the two to that.

use super::{
    BLOCK_ROOM, FeedMode, INVERSE_TIME_FORMAT, ProgramWriter, SNIPPET_ROOM, Spindle, WORD_ROOM,
    Word, block_room, check_number,
};
use crate::moves::{Feed, Position};
use crate::post::format::{Digits, PRINTED_ROOM};
use std::f64::consts::PI;

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

    /// Writes a rapid (`word` `Rapid`, no feed) or a linear move as a
    /// common block, or leaves it to the general path (false: nothing
    /// changed). True: the block is written, or left out because it
    /// changes no printed axis, as the general path would.
    #[inline(always)]
    pub(super) fn common_block(&mut self, word: Word, to: Position, feed: Option<Feed>) -> bool {
        // The general path's checks before a block: the tool called, the
        // C axis switched on before its first move, no feed move with
        // the spindle stopped (unless the C axis turns the part).
        // (A length offset waiting for its first Z move turns
        // `common_blocks` off until the general path has written it.)
        if !self.common_blocks || self.start.is_none() || (!to.c.is_nan() && !self.c_axis_on) {
            return false;
        }
        if matches!(word, Word::Linear) && self.spindle == Spindle::Stopped && !self.c_axis_on {
            return false;
        }
        // The feed in the mode already set (its word written before);
        // a mode to state goes the general way.
        let [per_unit_limit, inverse_unit_limit] = self.feed_unit_limits;
        let feed = match feed {
            None => None,
            Some(Feed::InverseTime(t)) if self.mode == Some(FeedMode::InverseTime) => {
                Some((60.0 / t, INVERSE_TIME_FORMAT, inverse_unit_limit, true))
            }
            Some(Feed::PerTime(v)) if self.mode == Some(FeedMode::PerMinute) => {
                Some((v * 60.0, self.feed_format, per_unit_limit, false))
            }
            Some(Feed::PerRevolution(v)) if self.mode == Some(FeedMode::PerRevolution) => {
                Some((v * 2.0 * PI, self.feed_format, per_unit_limit, false))
            }
            Some(_) => return false,
        };
        // Every number as a count of units (their roundings side by
        // side), and whether its word is written: an axis word when its
        // printed value changes (axes are modal).
        let axes = to.axes();
        let mut units = [0i64; 4];
        let mut changed = 0u8;
        for i in 0..4 {
            let v = axes[i];
            if v.is_nan() {
                continue;
            }
            let Some(n) = self.axis_formats[i].units(v * self.axis_scale[i]) else {
                return false;
            };
            units[i] = n;
            changed |= ((self.last[i] != n) as u8) << i;
        }
        // An axis the machine has no letter for goes the general way (a
        // refusal): one test for all four.
        if changed & !self.lettered_axes != 0 {
            return false;
        }
        if changed == 0 {
            // No printed axis changes: no block, nothing kept.
            return true;
        }
        let mut last_feed = self.last_feed;
        let mut feed_word = None;
        if let Some((value, format, unit_limit, always)) = feed {
            let Some(n) = format.units(value).filter(|&n| n > 0) else {
                return false;
            };
            if always || last_feed != Some(n) {
                feed_word = Some((n, format, unit_limit));
            }
            last_feed = Some(n);
        }
        // Their digits, side by side, before any is stored (an axis that
        // does not move has none).
        let f = &self.axis_formats;
        let of = |i: usize| {
            if axes[i].is_nan() {
                Digits::default()
            } else {
                f[i].digits(units[i])
            }
        };
        let digits: [Digits; 4] = [of(0), of(1), of(2), of(3)];
        let feed_digits =
            feed_word.map(|(n, format, unit_limit)| (n, format.digits(n), unit_limit));
        // The block: the motion word, the words, the line end; a word
        // over a limit, or a line too long, goes the general way.
        let at = self.text.len();
        let max_digits = self.max_digits;
        let motion_word = &self.motion_words[word as usize];
        let heads = &self.axis_heads;
        let unit_limits = &self.axis_unit_limits;
        let room = block_room(&mut self.text, &mut self.zeroed);
        room[..SNIPPET_ROOM].copy_from_slice(&motion_word.room);
        let mut pos = motion_word.len;
        let mut fits = true;
        for i in 0..4 {
            if changed & 1 << i != 0 {
                let head = &heads[i];
                let (end, count) = store_word(room, pos, &head.bytes, head.len, &digits[i]);
                fits &= count <= max_digits && units[i].unsigned_abs() < unit_limits[i];
                pos = end;
            }
        }
        if let Some((n, d, unit_limit)) = feed_digits {
            let (end, count) = store_word(room, pos, b" F      ", 2, &d);
            fits &= count <= max_digits && n.unsigned_abs() < unit_limit;
            pos = end;
        }
        // The line's length is where its words end (no prefix here).
        fits &= pos + self.line_end.len - 1 <= self.max_line_length;
        let end = room.get_mut(pos..pos + SNIPPET_ROOM);
        let (true, Some(end)) = (fits, end) else {
            self.text.truncate(at);
            return false;
        };
        end.copy_from_slice(&self.line_end.room);
        self.text.truncate(at + pos + self.line_end.len);
        self.last_feed = last_feed;
        self.moved(&units, changed, axes);
        #[cfg(test)]
        {
            self.common_written += 1;
        }
        true
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
