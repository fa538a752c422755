//! The common block read in one pass over its bytes: a feed move along a
//! line, `G1 X… Z… C… F…` (any of X, Y, Z, C and F once, the G1 left out
//! while G1 is in force), the form nearly every line of a large program
//! takes. Its words are lexed, held against the dialect's number format,
//! and its move checked and made straight from the bytes, with no block
//! built.
//!
//! Anything else — a comment, any other word or code, a word twice, a
//! tab, a number the format refuses, a move any rule refuses — is left to
//! the whole reader (`lexer`, `modal`, `motion`), which then reads the
//! line as if this path did not exist: this path changes the state only
//! for a line it has read whole and found clean, and then as the whole
//! reader would, with the same numbers (`lexer::number`) and the same
//! arithmetic (`State::outside_travel`, `State::over_limits`, `chord`).
//! The tests below read generated lines, valid and subtly not, both ways
//! and compare the findings and the state after every line.

use super::super::chord::chord;
use super::super::lexer::{Lexer, WordLimits, number};
use super::super::{Controller, Executed, Path};
use super::{Motion, State, g_tenths};

/// The letters read here, by their index: G, the axes X Y Z C (axis
/// `index - 1`), F.
const G: usize = 0;
const F: usize = 5;
/// The axes' bits in a set of letters seen.
const AXES: u8 = 0b1_1110;

/// What the fast path needs of the dialect, worked out once.
pub(crate) struct FastRules {
    /// Each letter's number format.
    limits: [WordLimits; 6],
    /// Whether the controller reads each letter at all.
    known: [bool; 6],
    max_line_length: Option<usize>,
    /// LinuxCNC: a C word puts the spindle in position mode.
    c_positions: bool,
}

impl FastRules {
    /// The rules, or `None` where the fast path never applies: a
    /// Klartext program, blocks closed by a mark (`*`) or numbered.
    pub(crate) fn of(
        lex: &Lexer,
        numbered: bool,
        known: impl Fn(char) -> bool,
    ) -> Option<FastRules> {
        if lex.controller == Controller::HeidenhainKlartext || !lex.open_ended() || numbered {
            return None;
        }
        let letters = ['G', 'X', 'Y', 'Z', 'C', 'F'];
        Some(FastRules {
            limits: letters.map(|l| lex.limits(l)),
            known: letters.map(|l| l == 'G' || known(l)),
            max_line_length: lex.max_line_length(),
            c_positions: lex.controller == Controller::LinuxCnc,
        })
    }
}

impl State {
    /// Reads `line` (without its line break) if it is a feed move along a
    /// line that reads clean, as the whole reader would; otherwise returns
    /// `false` with the state untouched.
    pub(super) fn fast_line(&mut self, line: &str) -> bool {
        let Some(rules) = self.fast.as_ref().filter(|_| self.fast_on) else {
            return false;
        };
        if self.ended
            || self.nurbs.is_some()
            || self.nurbs_block.is_some()
            || self.bspline.is_some()
            || rules.max_line_length.is_some_and(|max| line.len() > max)
        {
            return false;
        }
        // The words: each letter once, each number as the lexer reads it
        // (and ending where it does: `X1C2` is two words to it too).
        let bytes = line.as_bytes();
        let mut values = [0.0f64; 6];
        let mut seen = 0u8;
        let mut i = 0;
        loop {
            while i < bytes.len() && bytes[i] == b' ' {
                i += 1;
            }
            if i == bytes.len() {
                break;
            }
            let k = match bytes[i] {
                b'G' => G,
                b'X' => 1,
                b'Y' => 2,
                b'Z' => 3,
                b'C' => 4,
                b'F' => F,
                _ => return false,
            };
            if seen & (1 << k) != 0 || !rules.known[k] {
                return false;
            }
            let (Some((value, point, decimals)), end) = number(line, i + 1) else {
                return false;
            };
            if !rules.limits[k].allow(&bytes[i..end], point, decimals) {
                return false;
            }
            seen |= 1 << k;
            values[k] = value;
            i = end;
        }
        if seen & AXES == 0 {
            return false;
        }
        // The motion: G1 (as `classify` finds its group), or G1 in force.
        if seen & (1 << G) != 0 {
            if g_tenths(values[G]) != Some(10) {
                return false;
            }
        } else if self.motion != Some(Motion::Linear) {
            return false;
        }
        let has_f = seen & (1 << F) != 0;
        if has_f && values[F] <= 0.0 {
            return false;
        }
        let feed = if has_f { Some(values[F]) } else { self.feed };
        // The move (`move_block`, `end_point`, `travel`, `feed_move`).
        if self.metric.is_none() || self.absolute.is_none() {
            return false;
        }
        let start = self.pos;
        let mut end = self.pos;
        for axis in 0..4 {
            if seen & (2 << axis) == 0 {
                continue;
            }
            end[axis] = self.axis_end(axis, values[axis + 1]);
            if self.outside_travel(axis, end[axis]).is_some() {
                return false;
            }
        }
        let position_mode = self.position_mode || (rules.c_positions && seen & (1 << 4) != 0);
        if !self.tool_loaded
            || !(self.spindle_on || position_mode)
            || self.feed_mode.is_none()
            || feed.is_none()
            || (self.feed_mode == Some(super::FeedMode::InverseTime) && !has_f)
        {
            return false;
        }
        if let Some(length) = chord(&start, &end)
            && self.over_limits(feed, &start, &end, length) != (None, None)
        {
            return false;
        }
        // Clean: the block as the whole reader leaves it.
        self.motion = Some(Motion::Linear);
        self.feed = feed;
        self.position_mode = position_mode;
        // The tool tip: Z plus a servo on its own letter, which this
        // line (no word of its letter) leaves where it is.
        let (tip_start, tip_end) = (
            super::tip(start, self.servo_at),
            super::tip(end, self.servo_at),
        );
        if let Some(v) = tip_end[self.away] {
            self.top = Some(self.top.map_or(v, |t| t.max(v)));
        }
        if let Some(moves) = &mut self.moves {
            moves.push(Executed {
                from: tip_start,
                to: tip_end,
                path: Path::Line,
            });
        }
        self.pos = end;
        #[cfg(test)]
        {
            self.fast_taken += 1;
        }
        true
    }
}

#[cfg(test)]
mod tests;
