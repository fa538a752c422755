//! Fanuc's NURBS interpolation (G06.2) as the control reads and moves it,
//! from *FANUC Series 15i/150i-MA Operator's Manual (Programming)*, §4.17,
//! pp. 143–144 and 158 (docs/controllers/fanuc.md): `G06.2 [P] K X Y Z
//! [R] [F]` starts the mode, one block per control point `K X Y Z [R]`
//! follows, then as many blocks holding only a knot as the rank P (2 to
//! 4, default 4). The rules checked: P in 2..4 and only in the first block;
//! a knot in every block (alarm 1002); as many knots as control points
//! plus the rank, the first rank knots equal and the last rank equal
//! (alarm 1007); no knot value more than rank times (alarm 1008); knots
//! never decreasing and weights above zero (Mitsubishi's rules for the
//! same format, an assumption for Fanuc); the first control point where
//! the tool is; absolute coordinates (lensc's policy: the reader does not
//! read incremental control points). The curve is evaluated by the
//! manual's definition: P(t) = Σ N_i,k(t) w_i P_i / Σ N_i,k(t) w_i, the
//! basis by de Boor–Cox's recursion, and handed over as straight moves
//! within [`super::spline::SPLINE_TOLERANCE`] of it. This shares no code
//! with the fitter (`plan/spline.rs`). The curve read into the modal
//! state and moved along is `nurbs_moves.rs`.

/// The most straight moves one span of a curve is sampled into.
const MOST_PIECES_PER_SPAN: usize = 4096;

/// The highest rank a curve is read with: Fanuc's P4 (Siemens' SD=3).
pub(crate) const MOST_RANK: usize = 4;

/// A NURBS curve being read, block by block.
#[derive(Clone, Debug, Default)]
pub(crate) struct Nurbs {
    /// The rank (order): degree + 1.
    pub order: usize,
    pub points: Vec<[f64; 3]>,
    pub weights: Vec<f64>,
    pub knots: Vec<f64>,
    /// Blocks holding only a knot, read so far.
    pub end_knots: usize,
    /// Where the tool was when the curve began.
    pub start: [Option<f64>; 4],
}

impl Nurbs {
    /// What the control refuses in the whole curve, if anything.
    pub(crate) fn refusal(&self) -> Option<String> {
        let k = self.order;
        let n = self.points.len();
        if !(2..=MOST_RANK).contains(&k) {
            return Some(format!(
                "a NURBS curve of rank {k}: the control takes ranks 2 to {MOST_RANK}"
            ));
        }
        if n < k {
            return Some(format!(
                "a NURBS curve of rank {k} needs at least {k} control points; this one has {n}"
            ));
        }
        if self.knots.windows(2).any(|w| w[1] < w[0]) {
            return Some("the knots of a NURBS curve may not decrease".into());
        }
        let (first, last) = (self.knots[0], self.knots[self.knots.len() - 1]);
        if self.knots[..k].iter().any(|&v| v != first)
            || self.knots[self.knots.len() - k..]
                .iter()
                .any(|&v| v != last)
        {
            return Some(format!(
                "the first {k} knots and the last {k} knots of a NURBS curve of rank {k} must each be equal (the curve runs from its first control point to its last; Fanuc alarm 1007)"
            ));
        }
        if last <= first {
            return Some("a NURBS curve's last knot must be above its first".into());
        }
        let mut run = 1;
        for w in self.knots.windows(2) {
            run = if w[1] == w[0] { run + 1 } else { 1 };
            if run > k {
                return Some(format!(
                    "a knot value repeated more than the rank ({k}) times (Fanuc alarm 1008)"
                ));
            }
        }
        if let Some(w) = self.weights.iter().find(|w| **w <= 0.0) {
            return Some(format!("a NURBS weight R{w}: weights must be above zero"));
        }
        None
    }

    /// The curve at `t`, by the manual's rational form with the basis by
    /// de Boor–Cox's recursion over the span holding `t` (a rank of at
    /// most [`MOST_RANK`], as [`Nurbs::refusal`] holds it; knots never
    /// decreasing).
    pub(crate) fn at(&self, t: f64) -> [f64; 3] {
        let k = self.order;
        let n = self.points.len();
        let x = &self.knots;
        // The span i with x[i] <= t < x[i+1], among the curve's (k-1 .. n-1):
        // past every knot x[k..n] at or before t.
        let s = k - 1 + x[k..n].partition_point(|v| *v <= t);
        // N[j] for the basis functions i = s-k+1+j of rank r, built up
        // from rank 1 (1 on span s only).
        let mut basis = [0.0; MOST_RANK];
        basis[k - 1] = 1.0;
        for r in 2..=k {
            let mut next = [0.0; MOST_RANK];
            for (j, slot) in next[..k].iter_mut().enumerate() {
                let i = s + 1 + j - k;
                let a = ratio(t - x[i], x[i + r - 1] - x[i]) * basis[j];
                let right = if j + 1 < k { basis[j + 1] } else { 0.0 };
                let b = ratio(x[i + r] - t, x[i + r] - x[i + 1]) * right;
                *slot = a + b;
            }
            basis = next;
        }
        let (mut num, mut den) = ([0.0; 3], 0.0);
        for (j, nb) in basis[..k].iter().enumerate() {
            let i = s + 1 + j - k;
            let w = nb * self.weights[i];
            den += w;
            for (v, p) in num.iter_mut().zip(self.points[i]) {
                *v += w * p;
            }
        }
        [num[0] / den, num[1] / den, num[2] / den]
    }

    /// The curve as points whose chords stay within the reader's spline
    /// tolerance of it: each knot span halved until the chord's middle
    /// and quarters lie that close to the curve. The spans are sampled in
    /// parallel (rayon), each alone, and put together in order: the
    /// points are the same whatever the threads.
    pub(crate) fn sampled(&self) -> Vec<[f64; 3]> {
        use rayon::prelude::*;
        let x = &self.knots;
        let (first, last) = (x[0], x[x.len() - 1]);
        let mut ends = vec![first];
        ends.extend(x.iter().copied().filter(|v| *v > first));
        ends.dedup();
        let spans: Vec<Vec<[f64; 3]>> = ends
            .par_windows(2)
            .map(|w| self.span_sampled(w[0], w[1], last))
            .collect();
        let mut out = Vec::with_capacity(1 + spans.iter().map(Vec::len).sum::<usize>());
        out.push(self.at(first));
        for s in spans {
            out.extend(s);
        }
        out
    }

    /// The points after `from` to `to` (a knot span) of `sampled`: the span
    /// halved until its chords lie within the tolerance.
    fn span_sampled(&self, from: f64, to: f64, last: f64) -> Vec<[f64; 3]> {
        let mut pieces = 1;
        while pieces < MOST_PIECES_PER_SPAN && !self.within(from, to, pieces) {
            pieces *= 2;
        }
        (1..=pieces)
            .map(|p| {
                let t = if p == pieces {
                    to
                } else {
                    from + (to - from) * p as f64 / pieces as f64
                };
                if t == last {
                    self.end_point()
                } else {
                    self.at(t)
                }
            })
            .collect()
    }

    /// The last control point: where a clamped curve ends (the basis at
    /// the last knot, whose half-open span is empty, taken as its limit).
    fn end_point(&self) -> [f64; 3] {
        self.points[self.points.len() - 1]
    }

    /// Whether `pieces` equal chords of [a, b] lie within the tolerance
    /// (a chord's end is the next chord's start, evaluated once).
    fn within(&self, a: f64, b: f64, pieces: usize) -> bool {
        let h = (b - a) / pieces as f64;
        let mut p1 = self.at(a + h * 0.0);
        (0..pieces).all(|p| {
            let (t0, t1) = (a + h * p as f64, a + h * (p + 1) as f64);
            let p0 = p1;
            p1 = self.at(t1);
            [0.25, 0.5, 0.75].iter().all(|f| {
                let c = self.at(t0 + (t1 - t0) * f);
                let chord = [
                    p0[0] + f * (p1[0] - p0[0]),
                    p0[1] + f * (p1[1] - p0[1]),
                    p0[2] + f * (p1[2] - p0[2]),
                ];
                let d = ((c[0] - chord[0]).powi(2)
                    + (c[1] - chord[1]).powi(2)
                    + (c[2] - chord[2]).powi(2))
                .sqrt();
                d <= super::spline::SPLINE_TOLERANCE / 2.0
            })
        })
    }
}

/// a / b, and 0 for 0 / 0 (the recursion's convention for repeated knots).
fn ratio(a: f64, b: f64) -> f64 {
    if b == 0.0 { 0.0 } else { a / b }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn curve(order: usize, points: &[[f64; 3]], weights: &[f64], knots: &[f64]) -> Nurbs {
        Nurbs {
            order,
            points: points.to_vec(),
            weights: weights.to_vec(),
            knots: knots.to_vec(),
            ..Nurbs::default()
        }
    }

    /// A quarter circle as a rational quadratic (rank 3) with weights 1,
    /// √2/2, 1: every sampled point on the unit circle, within the
    /// sampling's own rounding.
    #[test]
    fn a_rational_quadratic_quarter_circle_lies_on_the_circle() {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let c = curve(
            3,
            &[[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
            &[1.0, h, 1.0],
            &[0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        );
        assert_eq!(c.refusal(), None);
        let pts = c.sampled();
        assert_eq!(pts[0], [1.0, 0.0, 0.0]);
        assert_eq!(pts[pts.len() - 1], [0.0, 1.0, 0.0]);
        for p in &pts {
            assert!((p[0].hypot(p[1]) - 1.0).abs() < 1e-12, "{p:?}");
        }
        // Sampled finely enough for 1 nm chords, not needlessly finer.
        assert!(pts.len() > 100 && pts.len() < 5000, "{}", pts.len());
    }

    /// A clamped cubic with one interior knot against its Bézier pieces,
    /// worked by hand: knots 0 0 0 0 1 2 2 2 2 and control points on a
    /// line x = 0, 1, 2, 3, 4 make x(t) = 2t (a linear function is
    /// reproduced by the Greville abscissae 0, 1/3, 1, 5/3, 2 … here the
    /// points are chosen at them).
    #[test]
    fn a_cubic_reproduces_a_straight_line_at_its_greville_points() {
        let g = [0.0, 1.0 / 3.0, 1.0, 5.0 / 3.0, 2.0];
        let pts: Vec<[f64; 3]> = g.iter().map(|x| [*x, 0.0, 2.0 * x]).collect();
        let c = curve(
            4,
            &pts,
            &[1.0; 5],
            &[0.0, 0.0, 0.0, 0.0, 1.0, 2.0, 2.0, 2.0, 2.0],
        );
        assert_eq!(c.refusal(), None);
        for i in 0..=20 {
            let t = i as f64 / 10.0;
            let p = c.at(t.min(2.0 - 1e-15));
            assert!((p[0] - t).abs() < 1e-12 && (p[2] - 2.0 * t).abs() < 1e-12);
        }
        // A straight line needs one chord per span.
        assert_eq!(c.sampled().len(), 3);
    }

    /// A cubic of many spans sampled with its spans in parallel: the
    /// same points, to the bit, on one thread or four, each span's points
    /// those of the span sampled alone, in order.
    #[test]
    fn spans_sampled_in_parallel_are_the_spans_in_order() {
        let n = 40;
        let pts: Vec<[f64; 3]> = (0..n)
            .map(|i| {
                let a = i as f64 * 0.1;
                [a.cos(), a.sin(), 0.01 * a * a]
            })
            .collect();
        let mut knots = vec![0.0; 4];
        knots.extend((1..n - 3).map(|j| j as f64 * 0.25));
        knots.extend([(n - 3) as f64 * 0.25; 4]);
        let c = curve(4, &pts, &vec![1.0; n], &knots);
        assert_eq!(c.refusal(), None);
        let last = knots[knots.len() - 1];
        let mut serial = vec![c.at(0.0)];
        for j in 0..n - 3 {
            let (a, b) = (j as f64 * 0.25, (j + 1) as f64 * 0.25);
            serial.extend(c.span_sampled(a, b, last));
        }
        assert!(serial.len() > 10 * (n - 3), "{}", serial.len());
        for threads in [1, 4] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("a pool");
            let sampled = pool.install(|| c.sampled());
            let bits =
                |v: &[[f64; 3]]| -> Vec<u64> { v.iter().flatten().map(|x| x.to_bits()).collect() };
            assert_eq!(bits(&sampled), bits(&serial), "{threads} threads");
        }
    }

    #[test]
    fn curves_the_control_refuses_are_refused() {
        let pts = [[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [3.0, 0.0, 0.0]];
        let ok = [0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0];
        assert_eq!(curve(4, &pts, &[1.0; 4], &ok).refusal(), None);
        for (knots, weights, what) in [
            (
                vec![0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0, 1.0],
                [1.0; 4],
                "equal",
            ),
            (
                vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 0.5],
                [1.0; 4],
                "decrease",
            ),
            (ok.to_vec(), [1.0, 0.0, 1.0, 1.0], "above zero"),
            (vec![0.0; 8], [1.0; 4], "above its first"),
        ] {
            let r = curve(4, &pts, &weights, &knots).refusal();
            assert!(r.as_deref().is_some_and(|m| m.contains(what)), "{r:?}");
        }
        let five = [
            [0.0; 3],
            [1.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [3.0, 0.0, 0.0],
            [4.0, 0.0, 0.0],
            [5.0, 0.0, 0.0],
        ];
        let r = curve(
            2,
            &five,
            &[1.0; 6],
            &[0.0, 0.0, 0.5, 0.5, 0.5, 1.0, 1.0, 1.0],
        )
        .refusal();
        assert!(r.as_deref().is_some_and(|m| m.contains("1008")), "{r:?}");
        let r = curve(
            4,
            &pts[..3],
            &[1.0; 3],
            &[0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        )
        .refusal();
        assert!(
            r.as_deref().is_some_and(|m| m.contains("at least")),
            "{r:?}"
        );
    }
}
