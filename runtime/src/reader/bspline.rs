//! Siemens' B spline (BSPLINE) as a curve: the control points read from
//! the blocks, checked by the control's rules, and the curve they define.
//! Source: *SINUMERIK 840D sl / 828D Programming Manual, Job planning*,
//! 12/2019, 6FC5398-2EP40-0BA0, §3.7 "Spline interpolation", pp. 594–600
//! (docs/controllers/siemens.md). The programmed positions are the
//! control points of a non-uniform rational B spline; `SD=` its degree,
//! 3 by default, 2 allowed (the 5-axis manual: "order max. 3"); `PW=` a
//! point's weight, 0 ≤ n ≤ 3 in steps of 0.0001; `PL=` the parameter
//! interval length, the knot spacing. What the manual leaves unstated,
//! and lensc assumes (docs/controllers/siemens.md): the curve starts at
//! the position the tool holds when BSPLINE starts (the first control
//! point, weight 1) and ends at the last programmed point (a clamped
//! knot vector, each end knot repeated degree + 1 times); which knot
//! interval a block's PL sets is unstated, so lensc reads only curves
//! whose blocks all state one and the same PL (then the interior knots
//! are equally spaced whichever it is), and refuses a PL left out ("the
//! distances between nodes are suitably calculated internally": by a
//! rule not published). The curve is then evaluated as the reader's
//! NURBS (`nurbs.rs`: P(t) = Σ N_i,k(t) w_i P_i / Σ N_i,k(t) w_i, de
//! Boor–Cox); no code is shared with the fitter (`plan/spline.rs`).

use super::nurbs::Nurbs;

/// A B spline being read, block by block.
#[derive(Clone, Debug, Default)]
pub(crate) struct Bspline {
    /// The degree (SD), from the curve's first block.
    pub degree: usize,
    /// The knot spacing (PL) every block states.
    pub spacing: f64,
    /// The control points: where the tool was, then one per block (an
    /// axis the program never stated: NaN, and never moved).
    pub points: Vec<[f64; 3]>,
    pub weights: Vec<f64>,
    /// Where the tool was when the curve began.
    pub start: [Option<f64>; 4],
}

/// The degree a block's `SD=` states, or why the control refuses it.
pub(crate) fn degree(sd: Option<f64>) -> Result<usize, String> {
    match sd {
        None => Ok(3),
        Some(v) if v == 2.0 || v == 3.0 => Ok(v as usize),
        Some(v) => Err(format!(
            "B spline degree SD={v}: the control takes SD=2 or SD=3 (order at most 3)"
        )),
    }
}

/// A block's weight `PW=`, or why the control refuses it.
pub(crate) fn weight(pw: Option<f64>) -> Result<f64, String> {
    match pw {
        None => Ok(1.0),
        Some(v) if v > 0.0 && v <= 3.0 => Ok(v),
        Some(0.0) => Err(
            "point weight PW=0: lensc reads weights above 0 (a zero weight leaves the point no pull, and a span of them no curve)"
                .into(),
        ),
        Some(v) => Err(format!("point weight PW={v}: the control takes 0 to 3")),
    }
}

/// A block's knot spacing `PL=` against the curve's, or why lensc does
/// not read it.
pub(crate) fn spacing(pl: Option<f64>, curve: Option<f64>) -> Result<f64, String> {
    let Some(v) = pl else {
        return Err(
            "a B spline block without its knot spacing PL: the control then places the knots by a rule its manual does not state, so lensc cannot read the curve as it runs"
                .into(),
        );
    };
    if v.is_nan() || v <= 0.0 {
        return Err(format!(
            "knot spacing PL={v}: a parameter interval is a length above 0"
        ));
    }
    match curve {
        Some(c) if c != v => Err(format!(
            "knot spacing PL={v} where the curve's earlier blocks state PL={c}: which knot interval a block's PL sets is not stated in the manual, so lensc reads only curves of one spacing"
        )),
        _ => Ok(v),
    }
}

impl Bspline {
    /// The curve as a NURBS of the reader's: order degree + 1, the knots
    /// clamped and `spacing` apart; or why the control refuses it.
    pub(crate) fn curve(&self) -> Result<Nurbs, String> {
        let p = self.degree;
        let n = self.points.len();
        if n < p + 1 {
            return Err(format!(
                "a B spline of degree {p} needs at least {} control points (the tool's position and {p} blocks); this one has {n}",
                p + 1
            ));
        }
        let spans = n - p;
        let mut knots = vec![0.0; p + 1];
        knots.extend((1..spans).map(|j| j as f64 * self.spacing));
        knots.extend(std::iter::repeat_n(spans as f64 * self.spacing, p + 1));
        Ok(Nurbs {
            order: p + 1,
            points: self.points.clone(),
            weights: self.weights.clone(),
            knots,
            end_knots: p + 1,
            start: self.start,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spline(degree: usize, spacing: f64, points: &[[f64; 3]], weights: &[f64]) -> Bspline {
        Bspline {
            degree,
            spacing,
            points: points.to_vec(),
            weights: weights.to_vec(),
            start: [None; 4],
        }
    }

    /// Degree 2 over three points is one quadratic Bézier piece: at its
    /// middle, ¼ P0 + ½ P1 + ¼ P2 (worked by hand), whatever the spacing.
    #[test]
    fn a_quadratic_over_three_points_is_a_bezier_piece() {
        let pts = [[0.0, 0.0, 0.0], [1.0, 0.0, 1.0], [2.0, 0.0, 0.0]];
        for pl in [0.1, 1.0, 7.0] {
            let c = spline(2, pl, &pts, &[1.0; 3]).curve().expect("a curve");
            assert_eq!(c.knots, vec![0.0, 0.0, 0.0, pl, pl, pl]);
            let m = c.at(pl / 2.0);
            assert!(
                (m[0] - 1.0).abs() < 1e-12 && (m[2] - 0.5).abs() < 1e-12,
                "{m:?}"
            );
        }
    }

    /// A cubic over six points: two clamped ends and interior knots
    /// spaced PL apart, 0 0 0 0 1 2 3 3 3 3 for PL=1; the curve starts at
    /// the first point and ends at the last.
    #[test]
    fn a_cubic_has_clamped_equally_spaced_knots() {
        let pts: Vec<[f64; 3]> = (0..6).map(|i| [i as f64, 0.0, (i * i) as f64]).collect();
        let c = spline(3, 1.0, &pts, &[1.0; 6]).curve().expect("a curve");
        assert_eq!(
            c.knots,
            vec![0.0, 0.0, 0.0, 0.0, 1.0, 2.0, 3.0, 3.0, 3.0, 3.0]
        );
        assert_eq!(c.at(0.0), pts[0]);
        let s = c.sampled();
        assert_eq!(s[s.len() - 1], pts[5]);
        // A weight above 1 pulls the curve toward its point.
        let mut w = [1.0; 6];
        let plain = c.at(1.5)[2];
        w[2] = 3.0;
        let pulled = spline(3, 1.0, &pts, &w).curve().expect("a curve").at(1.5);
        assert!((pulled[2] - 4.0).abs() < (plain - 4.0).abs());
    }

    #[test]
    fn what_the_control_refuses_is_refused() {
        assert_eq!(degree(None), Ok(3));
        assert_eq!(degree(Some(2.0)), Ok(2));
        for sd in [1.0, 4.0, 2.5] {
            assert!(degree(Some(sd)).is_err_and(|m| m.contains("SD=2 or SD=3")));
        }
        assert_eq!(weight(Some(3.0)), Ok(3.0));
        assert!(weight(Some(3.5)).is_err_and(|m| m.contains("0 to 3")));
        assert!(weight(Some(-1.0)).is_err());
        assert!(weight(Some(0.0)).is_err_and(|m| m.contains("above 0")));
        assert_eq!(spacing(Some(0.5), None), Ok(0.5));
        assert!(spacing(None, None).is_err_and(|m| m.contains("without its knot spacing")));
        assert!(spacing(Some(0.0), None).is_err());
        assert!(spacing(Some(0.5), Some(0.25)).is_err_and(|m| m.contains("one spacing")));
        let short = spline(3, 1.0, &[[0.0; 3]; 3], &[1.0; 3]).curve();
        assert!(short.is_err_and(|m| m.contains("at least 4")));
    }
}
