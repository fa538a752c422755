//! LinuxCNC's NURBS block (G5.2 … G5.3) read block by block into the modal
//! state and, at its G5.3, moved along as the interpreter evaluates it.
//!
//! Sources: *LinuxCNC documentation 2.9*, 11.5.9 "G5.2 G5.3 NURBS Block",
//! pp. 870–871 (`G5.2 <P-> <X- Y-> <L->`, then `X- Y- <P->` per control
//! point, closed by `G5.3`; the current point is the first control point,
//! its weight set by a `G5.2 P-` without X Y; order L, 3 by default), and
//! what `rs274 -g` 2.9 runs and refuses (docs/controllers/linuxcnc.md,
//! each case in `tests/it/nurbs_linuxcnc.rs`), which differs from the page:
//!
//! - every control point after the first block needs a weight P above
//!   zero ("Must specify positive weight P for every Control Point"); in
//!   the first block an absent P is the interpreter's P of −1, kept as the
//!   weight (lensc's policy refuses a weight not above zero: E0338);
//! - X and Y both or neither; a P without X Y only in the first block;
//! - L above 3 sets the order, L of 3 or less leaves it at 3, a negative
//!   or fractional L is refused; at G5.3 the curve needs at least as many
//!   points (the current point counted) as its order;
//! - G5.3 only while G5.2 is in force; a curve left by another motion
//!   code, or by the program's end, is never cut (lensc's policy: E0337);
//! - control points in G91 are from the point where the curve starts
//!   (the interpreter's current point does not move until G5.3); Z and
//!   the other axes of a control point, and X Y of the G5.3 block, are
//!   not read; the plane in force is not checked (the curve is in X Y).
//!
//! The curve is the interpreter's (`nurbs_additional_functions.cc`):
//! rational, its basis by the de Boor–Cox recursion over the clamped
//! integer knot vector `knot_vector_creator` builds (0 repeated L times,
//! 1 … n−L+1, then n−L+2 repeated L times, for n+1 control points), which
//! is [`crate::reader::nurbs::Nurbs`]'s evaluation with those knots. It is handed
//! over as straight moves within [`crate::reader::spline::SPLINE_TOLERANCE`] of
//! the curve. LinuxCNC's motion controller cuts biarcs through 4(n+1)
//! points of it (`emccanon.cc`, `NURBS_FEED`); the biarcs' own departure
//! from the curve is not modelled (an assumption, in the controller page).

use super::{FeedMode, Motion, State};
use crate::reader::Rule;
use crate::reader::lexer::{Block, Found};
use crate::reader::nurbs::Nurbs;

/// A G5.2 curve being read.
#[derive(Clone, Debug)]
pub(crate) struct NurbsBlock {
    /// The order (LinuxCNC's L): degree + 1.
    pub order: usize,
    /// X, Y of each control point, the current point first.
    pub points: Vec<(f64, f64)>,
    pub weights: Vec<f64>,
    /// Where the tool was when the curve began.
    pub start: [Option<f64>; 4],
    /// A weight not above zero in the first block (found there).
    pub bad_weight: bool,
}

/// LinuxCNC's knot vector for `count` control points of order `k`
/// (`knot_vector_creator(n, k)`, n = count − 1).
pub(crate) fn knot_vector(count: usize, k: usize) -> Vec<f64> {
    let n = count - 1;
    (0..=n + k)
        .map(|i| {
            if i < k {
                0.0
            } else if i <= n {
                (i + 1 - k) as f64
            } else {
                (n + 2 - k) as f64
            }
        })
        .collect()
}

impl State {
    /// A LinuxCNC block that opens, adds to or closes a NURBS block, or
    /// that leaves one open (`opens`: it holds G5.2; `closes`: G5.3).
    /// Returns whether the block was the curve's (no other move in it).
    pub(crate) fn nurbs_block_line(
        &mut self,
        b: &Block,
        opens: bool,
        closes: bool,
        out: &mut Vec<Found>,
    ) -> bool {
        let Some(first) = b.words.iter().find(|w| w.letter != 'N') else {
            return false;
        };
        let span = (first.span.0, b.words.last().expect("a word").span.1);
        if closes {
            self.nurbs_block_close(b, span, out);
            return true;
        }
        let in_force = self.motion == Some(Motion::NurbsBlock);
        if !in_force {
            // Another motion code: a curve left open is never cut.
            self.nurbs_block_left(span, out);
            return false;
        }
        let word = |l: char| b.words.iter().find(|w| w.letter == l);
        let axes = b
            .words
            .iter()
            .any(|w| matches!(w.letter, 'X' | 'Y' | 'Z' | 'A' | 'B' | 'C'));
        if !opens && !axes {
            // `F20`, `M5` in the mode: not a block of the curve.
            return false;
        }
        let refuse = |msg: &str, out: &mut Vec<Found>| {
            out.push((Rule::SplineRefused, span, msg.to_string(), None));
        };
        let (x, y, p) = (word('X'), word('Y'), word('P'));
        if x.is_some() != y.is_some() {
            refuse(
                "a G5.2 control point needs both X and Y (the controller refuses one alone)",
                out,
            );
            self.nurbs_block = None;
            return true;
        }
        let started = self.nurbs_block.is_some();
        if started && x.is_none() && p.is_some_and(|p| p.value > 0.0) {
            refuse(
                "a P without X and Y sets the weight of the first control point only, in the first G5.2 block",
                out,
            );
            self.nurbs_block = None;
            return true;
        }
        if started && p.is_none_or(|p| p.value <= 0.0) {
            refuse(
                "every control point after the first G5.2 block needs a weight P above zero",
                out,
            );
            self.nurbs_block = None;
            return true;
        }
        let per_minute = !matches!(
            self.feed_mode,
            Some(FeedMode::PerRevolution | FeedMode::InverseTime)
        );
        let has_f = word('F').is_some_and(|f| f.value != 0.0);
        if per_minute && !has_f && self.feed.is_none_or(|f| f == 0.0) {
            out.push((
                Rule::NoFeedRate,
                span,
                "a NURBS block with no feed (F) stated: the controller cannot make it at feed 0"
                    .into(),
                None,
            ));
        }
        let curve = self.nurbs_block.get_or_insert_with(|| NurbsBlock {
            order: 3,
            points: Vec::new(),
            weights: Vec::new(),
            start: self.pos,
            bad_weight: false,
        });
        if curve.points.is_empty() {
            // The current point: the first control point, its weight a P
            // above zero given without X Y, else 1.
            let w = match (x, p) {
                (None, Some(p)) if p.value > 0.0 => p.value,
                _ => 1.0,
            };
            curve.points.push((
                curve.start[0].unwrap_or(f64::NAN),
                curve.start[1].unwrap_or(f64::NAN),
            ));
            curve.weights.push(w);
        }
        if let Some(l) = word('L') {
            if l.value < 0.0 || l.value.fract() != 0.0 {
                refuse(
                    &format!(
                        "NURBS order L{}: the controller takes a whole number",
                        l.value
                    ),
                    out,
                );
                self.nurbs_block = None;
                return true;
            }
            if l.value > 3.0 {
                curve.order = l.value as usize;
            }
        }
        if let (Some(xw), Some(yw)) = (x, y) {
            // The interpreter's current point stays where the curve began
            // until G5.3: incremental points are from there.
            let px = self.axis_end(0, xw.value);
            let py = self.axis_end(1, yw.value);
            let curve = self.nurbs_block.as_mut().expect("a curve");
            // The interpreter's P when none is given is −1.
            let w = p.map_or(-1.0, |p| p.value);
            if w <= 0.0 {
                curve.bad_weight = true;
                out.push((
                    Rule::NurbsWeight,
                    p.map_or(span, |p| p.span),
                    "a control point of the first G5.2 block with no weight P, or one not above zero: the controller takes it as written (no P is −1) and the curve turns away from its points".into(),
                    Some("give every control point a weight P above zero (P1 for a plain B-spline)".into()),
                ));
            }
            curve
                .points
                .push((px.unwrap_or(f64::NAN), py.unwrap_or(f64::NAN)));
            curve.weights.push(w);
        }
        true
    }

    /// A NURBS block left open (another motion code, or the program's
    /// end): the controller never cuts it.
    pub(crate) fn nurbs_block_left(&mut self, span: (usize, usize), out: &mut Vec<Found>) {
        if self.nurbs_block.take().is_some() {
            out.push((
                Rule::NurbsNotCut,
                span,
                "a NURBS block (G5.2) left without its G5.3: the controller never cuts the curve"
                    .into(),
                Some("close the curve with G5.3 before the next motion".into()),
            ));
        }
    }

    /// G5.3: the curve checked and moved along.
    fn nurbs_block_close(&mut self, b: &Block, span: (usize, usize), out: &mut Vec<Found>) {
        self.motion = None;
        let Some(curve) = self.nurbs_block.take() else {
            out.push((
                Rule::SplineRefused,
                span,
                "G5.3 without a NURBS block (G5.2) in force".into(),
                Some("open the curve with G5.2".into()),
            ));
            return;
        };
        if curve.points.len() < curve.order {
            out.push((
                Rule::SplineRefused,
                span,
                format!(
                    "a NURBS block of order L{} needs at least {} control points, the current point counted; this one has {}",
                    curve.order,
                    curve.order,
                    curve.points.len()
                ),
                None,
            ));
            return;
        }
        let (sx, sy) = curve.points[0];
        if sx.is_nan() || sy.is_nan() || curve.points.iter().any(|p| p.0.is_nan() || p.1.is_nan()) {
            out.push((
                Rule::PositionUnknown,
                span,
                "a NURBS block from a point the program never stated (its X or Y is unknown here)"
                    .into(),
                None,
            ));
            return;
        }
        let z = curve.start[2].unwrap_or(0.0);
        let nurbs = Nurbs {
            order: curve.order,
            knots: knot_vector(curve.points.len(), curve.order),
            points: curve.points.iter().map(|&(x, y)| [x, y, z]).collect(),
            weights: curve.weights.clone(),
            end_knots: 0,
            start: curve.start,
        };
        self.may_cut(b, span, out);
        let points = if curve.bad_weight {
            // Not sampled: a weight not above zero may divide by zero.
            vec![nurbs.points[0], nurbs.points[nurbs.points.len() - 1]]
        } else {
            nurbs.sampled()
        };
        self.curve_moves(points, 2, curve.start, b, span, out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `knot_vector_creator(4, 3)` (five points, order 3): 0 0 0 1 2 3 3 3.
    #[test]
    fn the_knot_vector_is_linuxcncs() {
        assert_eq!(
            knot_vector(5, 3),
            vec![0.0, 0.0, 0.0, 1.0, 2.0, 3.0, 3.0, 3.0]
        );
        assert_eq!(knot_vector(3, 3), vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0]);
        assert_eq!(
            knot_vector(5, 4),
            vec![0.0, 0.0, 0.0, 0.0, 1.0, 2.0, 2.0, 2.0, 2.0]
        );
    }
}
