//! The writer's Klartext back end: a move as Heidenhain's conversational
//! blocks (`L X+1.5 Y-2 R0 F300`, `L Z+5 R0 FMAX`, `CC X+0 Y+0` then
//! `C X+1 Y+0 DR-`), every number through the same fixed-point formatter
//! as G-code, with the sign always written and no trailing point (as the
//! TNC itself writes them).

use super::{FeedMode, ProgramWriter, Spindle, Word};
use crate::moves::{Feed, Plane, Position};
use crate::post::ProgramError;
use crate::post::format::fixed_units;

impl ProgramWriter {
    /// A move as one `L` block (a line or, with `FMAX`, a rapid), or an
    /// arc as its circle centre `CC` (when it changes) and a `C` block.
    /// Axes are modal as in G-code: a coordinate whose printed value has
    /// not changed is left out, and a move that changes none is left out
    /// whole. `R0` (no radius compensation: the path is the tool
    /// centre's) is written in every `L` block, as the TNC writes it.
    /// `FMAX` holds for its own block only; the feed after a rapid is
    /// written again.
    pub(super) fn klartext_motion(
        &mut self,
        word: Word,
        to: Position,
        feed: Option<Feed>,
        arc: Option<(Plane, Position)>,
    ) -> Result<(), ProgramError> {
        if !to.c.is_nan() {
            return Err(ProgramError::Unsupported(format!(
                "C-axis moves ({} writes milling programs of X, Y and Z)",
                self.dialect.name
            )));
        }
        if !matches!(word, Word::Rapid) && self.spindle == Spindle::Stopped {
            return Err(ProgramError::Unsupported(
                "a feed move with the spindle stopped".into(),
            ));
        }
        let feed = match feed {
            None => None,
            Some(Feed::PerTime(v)) => Some(v * 60.0),
            Some(_) => {
                return Err(ProgramError::Unsupported(format!(
                    "feeds per revolution or in inverse time ({} feeds in mm/min)",
                    self.dialect.name
                )));
            }
        };
        let start = self.text.len();
        let block_at_start = self.block;
        let centre_at_start = self.circle_centre;
        let r = self.klartext_blocks(word, to, feed, arc);
        match r {
            Ok(true) => Ok(()),
            Ok(false) | Err(_) => {
                // Nothing to move, or refused: no CC either.
                self.text.truncate(start);
                self.block = block_at_start;
                self.circle_centre = centre_at_start;
                r.map(|_| ())
            }
        }
    }

    /// The blocks of one move; false if it changes no printed axis.
    fn klartext_blocks(
        &mut self,
        word: Word,
        to: Position,
        feed: Option<f64>,
        arc: Option<(Plane, Position)>,
    ) -> Result<bool, ProgramError> {
        if let Some((plane, centre)) = arc {
            if plane != Plane::Xy || !self.dialect.arc_planes.contains(&plane) {
                return Err(ProgramError::Unsupported(format!(
                    "arcs in the {} plane",
                    plane.name()
                )));
            }
            self.check_arc_radii(plane, to, centre)?;
            self.circle_centre_block(centre)?;
        }
        let start = self.text.len();
        self.begin_block();
        self.text
            .push(if matches!(word, Word::ArcCw | Word::ArcCcw) {
                b'C'
            } else {
                b'L'
            });
        let axes = to.axes();
        let mut printed = [0i64; 3];
        let mut changed = 0u8;
        for i in 0..3 {
            let v = axes[i];
            if v.is_nan() {
                continue;
            }
            let d = self.axis_decimals[i];
            let (Some(letter), Some(n)) = (self.letters[i], fixed_units(v, d)) else {
                return Err(self.not_printable(i, v));
            };
            if self.last[i] == Some(n) {
                continue;
            }
            self.text.extend_from_slice(&[b' ', letter as u8]);
            self.signed_number(letter, v, n, d)?;
            printed[i] = n;
            changed |= 1 << i;
        }
        if changed == 0 {
            self.text.truncate(start);
            return Ok(false);
        }
        match word {
            Word::ArcCw => self.text.extend_from_slice(b" DR-"),
            Word::ArcCcw => self.text.extend_from_slice(b" DR+"),
            _ => self.text.extend_from_slice(b" R0"),
        }
        match (word, feed) {
            (Word::Rapid, _) => {
                self.text.extend_from_slice(b" FMAX");
                // FMAX holds for its block only: state the feed again.
                self.last_feed = None;
            }
            (_, Some(f)) => self.klartext_feed(f)?,
            (_, None) => {}
        }
        self.end_block(start)?;
        for (i, n) in printed.into_iter().enumerate() {
            if changed & 1 << i != 0 {
                self.last[i] = Some(n);
            }
        }
        for (at, v) in self.at.iter_mut().zip(axes) {
            if !v.is_nan() {
                *at = v;
            }
        }
        self.moves += 1;
        Ok(true)
    }

    /// `CC X… Y…`, the circle centre of the arcs that follow, when it
    /// differs from the one in force (CC is modal on the TNC).
    fn circle_centre_block(&mut self, centre: Position) -> Result<(), ProgramError> {
        let d = self.decimals;
        let (Some(x), Some(y)) = (fixed_units(centre.x, d), fixed_units(centre.y, d)) else {
            return Err(ProgramError::NotPrintable {
                word: 'X',
                value: centre.x,
            });
        };
        if self.circle_centre == Some((x, y)) {
            return Ok(());
        }
        let start = self.text.len();
        self.begin_block();
        self.text.extend_from_slice(b"CC X");
        self.signed_number('X', centre.x, x, d)?;
        self.text.extend_from_slice(b" Y");
        self.signed_number('Y', centre.y, y, d)?;
        self.end_block(start)?;
        self.circle_centre = Some((x, y));
        Ok(())
    }

    /// The feed word (mm/min), written when its printed value changes or
    /// after a rapid.
    fn klartext_feed(&mut self, value: f64) -> Result<(), ProgramError> {
        let d = self.feed_decimals;
        let Some(n) = fixed_units(value, d).filter(|&n| n > 0) else {
            return Err(ProgramError::NotPrintable { word: 'F', value });
        };
        if self.last_feed != Some(n) {
            self.text.extend_from_slice(b" F");
            self.number('F', value, n, d)?;
            if self.text.last() == Some(&b'.') {
                self.text.pop();
            }
        }
        self.last_feed = Some(n);
        self.mode = Some(FeedMode::PerMinute);
        Ok(())
    }

    /// A coordinate as the TNC writes it: its sign always (`X+0`,
    /// `Y-1.25`), no trailing point.
    fn signed_number(&mut self, letter: char, v: f64, n: i64, d: u32) -> Result<(), ProgramError> {
        if n >= 0 {
            self.text.push(b'+');
        }
        self.number(letter, v, n, d)?;
        if self.text.last() == Some(&b'.') {
            self.text.pop();
        }
        Ok(())
    }
}
