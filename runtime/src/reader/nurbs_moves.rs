//! A Fanuc NURBS curve (G06.2) read block by block into the modal state
//! and, once its last knot is read, checked by the control's rules
//! (`nurbs.rs`) and moved along: where it ends, whether it may be cut,
//! its feed, its travel, and its straight moves for the simulation.

use super::lexer::{Block, Found};
use super::modal::State;
use super::nurbs::Nurbs;
use super::{Executed, Path, Rule};

impl State {
    /// A block in NURBS mode (`starts`: it holds G06.2).
    pub(crate) fn nurbs_block(
        &mut self,
        b: &Block,
        starts: bool,
        line: &str,
        out: &mut Vec<Found>,
    ) {
        let Some(first) = b.words.iter().find(|w| w.letter != 'N') else {
            return;
        };
        let span = (first.span.0, b.words.last().expect("a word").span.1);
        let refuse = |msg: String, out: &mut Vec<Found>| {
            out.push((Rule::SplineRefused, span, msg, None));
        };
        let word = |l: char| b.words.iter().find(|w| w.letter == l);
        if starts {
            if self.nurbs.is_some() {
                refuse(
                    "G06.2 before the NURBS curve in force has its last knot".into(),
                    out,
                );
            }
            let order = word('P').map_or(4.0, |w| w.value);
            if !(2.0..=4.0).contains(&order) || order.fract() != 0.0 {
                refuse(
                    format!("NURBS rank P{order}: the control takes P2, P3 or P4"),
                    out,
                );
                self.nurbs = None;
                self.motion = None;
                return;
            }
            if self.absolute != Some(true) {
                refuse(
                    "a NURBS curve in incremental coordinates: lensc reads NURBS control points in G90 only".into(),
                    out,
                );
            }
            self.nurbs = Some(Nurbs {
                order: order as usize,
                start: self.pos,
                ..Nurbs::default()
            });
        } else if word('P').is_some() {
            refuse(
                "P (the NURBS rank) is given only in the G06.2 block".into(),
                out,
            );
        }
        let has_axes = b.words.iter().any(|w| matches!(w.letter, 'X' | 'Y' | 'Z'));
        if word('K').is_none() && !has_axes && !starts && self.nurbs.is_none() {
            // No curve being read and nothing of one here (`M5` after a
            // curve, G06.2 still modal): not a NURBS block.
            return;
        }
        let Some(nurbs) = self.nurbs.as_mut() else {
            return;
        };
        let Some(k) = word('K') else {
            refuse(
                "a block of a NURBS curve without its knot K (Fanuc alarm 1002)".into(),
                out,
            );
            self.nurbs = None;
            return;
        };
        let unit = if self.metric == Some(false) {
            25.4
        } else {
            1.0
        };
        let axes: Vec<_> = b
            .words
            .iter()
            .filter(|w| matches!(w.letter, 'X' | 'Y' | 'Z'))
            .collect();
        if axes.is_empty() && !(starts && nurbs.points.is_empty()) {
            nurbs.knots.push(k.value);
            nurbs.end_knots += 1;
        } else {
            if nurbs.end_knots > 0 {
                refuse(
                    "a control point after the NURBS curve's end knots".into(),
                    out,
                );
                self.nurbs = None;
                return;
            }
            // Axes left out keep the previous control point's (the first
            // one's: where the tool is).
            let mut p = match nurbs.points.last() {
                Some(p) => *p,
                None => [
                    nurbs.start[0].unwrap_or(f64::NAN),
                    nurbs.start[1].unwrap_or(f64::NAN),
                    nurbs.start[2].unwrap_or(f64::NAN),
                ],
            };
            for w in &axes {
                let i = match w.letter {
                    'X' => 0,
                    'Y' => 1,
                    _ => 2,
                };
                p[i] = w.value * unit;
            }
            nurbs.points.push(p);
            nurbs.weights.push(word('R').map_or(1.0, |w| w.value));
            nurbs.knots.push(k.value);
        }
        if nurbs.end_knots < nurbs.order {
            return;
        }
        let nurbs = self.nurbs.take().expect("a curve");
        self.nurbs_done(nurbs, b, span, line, out);
    }

    /// A curve read to its last knot: checked, then moved along.
    fn nurbs_done(
        &mut self,
        nurbs: Nurbs,
        b: &Block,
        span: (usize, usize),
        _line: &str,
        out: &mut Vec<Found>,
    ) {
        if let Some(msg) = nurbs.refusal() {
            // Found when its last knot is read: the span is that block's.
            out.push((Rule::SplineRefused, span, msg, None));
            return;
        }
        let start = nurbs.start;
        let p0 = nurbs.points[0];
        let known = (0..3).all(|i| start[i].is_some() || p0[i].is_nan());
        let off = (0..3).any(|i| match start[i] {
            Some(s) => (s - p0[i]).abs() > 1e-9,
            None => !p0[i].is_nan(),
        });
        if !known || off || p0.iter().any(|v| v.is_nan()) {
            out.push((
                Rule::SplineRefused,
                span,
                "the NURBS curve's first control point is not where the tool is: the curve must start from the current position".into(),
                Some("give the current position as the first control point, in the G06.2 block".into()),
            ));
            return;
        }
        self.may_cut(b, span, out);
        self.curve_moves(nurbs.sampled(), 3, start, b, span, out);
    }

    /// The tool moved along `points` (a curve sampled within the spline
    /// tolerance) from `start`: its first `axes` coordinates (X Y, or X Y
    /// Z) set, the others kept; the feed, the travel, the highest point
    /// cut and the straight moves for the simulation.
    pub(crate) fn curve_moves(
        &mut self,
        points: Vec<[f64; 3]>,
        axes: usize,
        start: [Option<f64>; 4],
        b: &Block,
        span: (usize, usize),
        out: &mut Vec<Found>,
    ) {
        let d = |a: &[f64; 3], b: &[f64; 3]| {
            (0..axes).map(|i| (b[i] - a[i]).powi(2)).sum::<f64>().sqrt()
        };
        let length: f64 = points.windows(2).map(|w| d(&w[0], &w[1])).sum();
        let last = points[points.len() - 1];
        let mut end = start;
        for i in 0..axes {
            end[i] = Some(last[i]);
        }
        self.feed_limit(b, &start, &end, length, span, out);
        for (i, lim) in self.machine.travel.iter().enumerate().take(axes) {
            if let Some((lo, hi)) = lim
                && let Some(p) = points.iter().find(|p| p[i] < lo - 1e-9 || p[i] > hi + 1e-9)
            {
                out.push((
                    Rule::OutsideTravel,
                    span,
                    format!(
                        "this NURBS curve takes {} to {} mm, outside the machine's travel {} .. {} mm",
                        ["X", "Y", "Z"][i],
                        p[i],
                        lo,
                        hi
                    ),
                    None,
                ));
                break;
            }
        }
        if self.away < axes {
            let a = self.away;
            let high = points
                .iter()
                .map(|p| p[a])
                .fold(f64::NEG_INFINITY, f64::max);
            self.top = Some(self.top.map_or(high, |t| t.max(high)));
        } else if self.away < 3
            && let Some(h) = start[self.away]
        {
            self.top = Some(self.top.map_or(h, |t| t.max(h)));
        }
        if let Some(moves) = &mut self.moves {
            for w in points.windows(2) {
                let mut from = start;
                let mut to = start;
                for i in 0..axes {
                    from[i] = Some(w[0][i]);
                    to[i] = Some(w[1][i]);
                }
                moves.push(Executed {
                    from,
                    to,
                    path: Path::Line,
                });
            }
        }
        self.pos = end;
    }
}
