//! A Siemens B spline (BSPLINE) read block by block into the modal state
//! and, once a block leaves the mode (or the program ends), moved along:
//! where it ends, whether it may be cut, its feed, its travel, and its
//! straight moves for the simulation. The curve and the control's rules
//! are `bspline.rs`'.

use super::bspline::{self, Bspline};
use super::lexer::{Block, Found, KeywordKind, SiemensWord};
use super::modal::State;
use super::{Executed, Path, Rule};

impl State {
    /// A block in B spline mode: a control point where it states an axis.
    pub(crate) fn bspline_block(&mut self, b: &Block, line: &str, out: &mut Vec<Found>) {
        let keyword = |w: SiemensWord| b.keywords.iter().find(|k| k.kind == KeywordKind::Word(w));
        let axes: Vec<_> = b
            .words
            .iter()
            .filter(|w| matches!(w.letter, 'X' | 'Y' | 'Z'))
            .collect();
        let whole = match (axes.first(), b.keywords.first()) {
            (Some(a), _) => (a.span.0, axes[axes.len() - 1].span.1),
            (None, Some(k)) => k.span,
            (None, None) => (0, line.len()),
        };
        let span_of = |w: SiemensWord| keyword(w).map_or(whole, |k| k.span);
        let refuse = |span: (usize, usize), msg: String, out: &mut Vec<Found>| {
            out.push((Rule::SplineRefused, span, msg, None));
        };
        if b.words.iter().any(|w| matches!(w.letter, 'C' | 'A' | 'B')) {
            refuse(
                whole,
                "a rotary axis in a B spline: lensc reads B splines in X, Y and Z only".into(),
                out,
            );
            self.bspline = None;
            return;
        }
        let sd = keyword(SiemensWord::Sd).and_then(|k| k.value);
        if self.bspline.is_some() && sd.is_some() {
            refuse(
                span_of(SiemensWord::Sd),
                "SD (the B spline's degree) in a block after its first: lensc reads one degree per curve".into(),
                out,
            );
        }
        if axes.is_empty() {
            // `BSPLINE` alone, or a block of other words in the mode: no
            // control point.
            return;
        }
        if self.bspline.is_none() {
            let degree = match bspline::degree(sd) {
                Ok(d) => d,
                Err(msg) => {
                    refuse(span_of(SiemensWord::Sd), msg, out);
                    return;
                }
            };
            if self.absolute != Some(true) {
                refuse(
                    whole,
                    "a B spline in incremental coordinates: lensc reads B spline control points in G90 only".into(),
                    out,
                );
                return;
            }
            let p0 = [0, 1, 2].map(|i| self.pos[i].unwrap_or(f64::NAN));
            self.bspline = Some(Bspline {
                degree,
                spacing: f64::NAN,
                points: vec![p0],
                weights: vec![1.0],
                start: self.pos,
            });
        }
        let curve = self.bspline.as_ref().expect("a curve");
        let known = (!curve.spacing.is_nan()).then_some(curve.spacing);
        let spacing = match bspline::spacing(keyword(SiemensWord::Pl).and_then(|k| k.value), known)
        {
            Ok(v) => v,
            Err(msg) => {
                refuse(span_of(SiemensWord::Pl), msg, out);
                self.bspline = None;
                return;
            }
        };
        let weight = match bspline::weight(keyword(SiemensWord::Pw).and_then(|k| k.value)) {
            Ok(v) => v,
            Err(msg) => {
                refuse(span_of(SiemensWord::Pw), msg, out);
                self.bspline = None;
                return;
            }
        };
        let end = self.end_point(b);
        let curve = self.bspline.as_mut().expect("a curve");
        let mut p = curve.points[curve.points.len() - 1];
        for w in &axes {
            let i = match w.letter {
                'X' => 0,
                'Y' => 1,
                _ => 2,
            };
            p[i] = end[i].unwrap_or(f64::NAN);
        }
        curve.spacing = spacing;
        curve.points.push(p);
        curve.weights.push(weight);
    }

    /// The B spline being read, if any, ended here: checked, then moved
    /// along. Findings are the ending block's (`line`, whole).
    pub(crate) fn bspline_end(&mut self, line: &str, out: &mut Vec<Found>) {
        let Some(curve) = self.bspline.take() else {
            return;
        };
        let span = (0, line.len());
        // An axis the program never stated stays so if the curve never
        // moves it (a lathe's Y); any other unknown is refused.
        let unknown: Vec<usize> = (0..3)
            .filter(|&i| curve.points.iter().any(|p| p[i].is_nan()))
            .collect();
        if unknown
            .iter()
            .any(|&i| curve.points.iter().any(|p| !p[i].is_nan()))
        {
            out.push((
                Rule::SplineRefused,
                span,
                "a B spline from a point the program never stated: the curve starts where the tool is, and an axis of it is unknown here".into(),
                Some("state every axis of the curve (a move to its start) before BSPLINE".into()),
            ));
            return;
        }
        let mut filled = curve.clone();
        for p in &mut filled.points {
            for &i in &unknown {
                p[i] = 0.0;
            }
        }
        let nurbs = match filled.curve() {
            Ok(n) => n,
            Err(msg) => {
                out.push((Rule::SplineRefused, span, msg, None));
                return;
            }
        };
        self.may_cut(&Block::default(), span, out);
        let points = nurbs.sampled();
        let length: f64 = points
            .windows(2)
            .map(|w| {
                ((w[1][0] - w[0][0]).powi(2)
                    + (w[1][1] - w[0][1]).powi(2)
                    + (w[1][2] - w[0][2]).powi(2))
                .sqrt()
            })
            .sum();
        let start = curve.start;
        let at = |p: &[f64; 3]| {
            let mut q = start;
            for i in 0..3 {
                if !unknown.contains(&i) {
                    q[i] = Some(p[i]);
                }
            }
            q
        };
        let end = at(&points[points.len() - 1]);
        self.feed_limit(&Block::default(), &start, &end, length, span, out);
        for (i, lim) in self.machine.travel.iter().enumerate().take(3) {
            if unknown.contains(&i) {
                continue;
            }
            if let Some((lo, hi)) = lim
                && let Some(p) = points.iter().find(|p| p[i] < lo - 1e-9 || p[i] > hi + 1e-9)
            {
                out.push((
                    Rule::OutsideTravel,
                    span,
                    format!(
                        "the B spline ending here takes {} to {} mm, outside the machine's travel {} .. {} mm",
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
        if self.away < 3 && !unknown.contains(&self.away) {
            let a = self.away;
            let high = points
                .iter()
                .map(|p| p[a])
                .fold(f64::NEG_INFINITY, f64::max);
            self.top = Some(self.top.map_or(high, |t| t.max(high)));
        }
        if let Some(moves) = &mut self.moves {
            for w in points.windows(2) {
                moves.push(Executed {
                    from: at(&w[0]),
                    to: at(&w[1]),
                    path: Path::Line,
                });
            }
        }
        self.pos = end;
    }
}
