//! The height map a ball-end mill cuts: the ball swept along the printed
//! path of its centre. Unlike a knife, whose edge lies across the cut, a
//! ball reaches its radius along the path as well: at a column the cut is
//! made by every point of the path within the radius, not only by the
//! point in the column's plane. So each cell's height is found exactly
//! from the path's pieces that reach it: the lowest point at (s, u) of the
//! set within the radius of a straight piece (a capsule: a cylinder with a
//! sphere at each end) in closed form, and of a circular arc (a torus
//! section and its end spheres) from its boundary circles. The controller
//! interpolates straight and circular moves, and so does this.
//!
//! Each cell is owned by the pass whose ball cuts lowest there; a pass's
//! cells in a column give its contact (least error, refined by a
//! parabola) and neighbouring passes meet at a cusp, found by bisection,
//! so the figures are those of the knife's map ([`super::Column`]).

use rayon::prelude::*;

use super::{Column, Frame, Grid, NosePath, RasterLayout, Totals, band, in_features};

/// One straight or circular piece of the path: its ends (s, u, h), the
/// arc's centre (s, h) if it is one, and its pass (the step-over
/// coordinate it starts at, in picometres: the tiles' blocks start a pass
/// again at their edges, and a raster's pass keeps its u).
#[derive(Clone, Copy, Debug)]
struct Piece {
    a: (f64, f64, f64),
    b: (f64, f64, f64),
    arc: Option<(f64, f64)>,
    pass: i64,
}

impl Piece {
    /// The lowest height the ball of `radius` reaches at (s, u) when its
    /// centre runs along this piece; `None` where it does not reach.
    fn bottom(&self, radius: f64, s: f64, u: f64) -> Option<f64> {
        match self.arc {
            None => capsule_bottom(self.a, self.b, radius, s, u),
            Some(o) => arc_bottom(self.a, self.b, o, radius, s, u),
        }
    }

    /// The columns' range of s it can reach with `radius`.
    fn s_reach(&self, radius: f64) -> (f64, f64) {
        let (mut lo, mut hi) = (self.a.0.min(self.b.0), self.a.0.max(self.b.0));
        if let Some(o) = self.arc {
            // A minor arc bulges at most its radius from its centre.
            let rho = (self.a.0 - o.0).hypot(self.a.2 - o.1);
            if within_span(
                (self.a.0, self.a.2),
                (self.b.0, self.b.2),
                o,
                (o.0 - rho, o.1),
            ) {
                lo = o.0 - rho;
            }
            if within_span(
                (self.a.0, self.a.2),
                (self.b.0, self.b.2),
                o,
                (o.0 + rho, o.1),
            ) {
                hi = o.0 + rho;
            }
        }
        (lo - radius, hi + radius)
    }
}

/// The lowest point at (s, u) within `r` of the segment from `a` to `b`
/// (points (s, u, h)): the least over t in [0, 1] of
/// h(t) − √(r² − d(t)²), d(t) the horizontal distance, which is convex in
/// t, so its stationary point clamped to where the ball reaches is the
/// least.
fn capsule_bottom(a: (f64, f64, f64), b: (f64, f64, f64), r: f64, s: f64, u: f64) -> Option<f64> {
    let (ds, du, dh) = (b.0 - a.0, b.1 - a.1, b.2 - a.2);
    let (ps, pu) = (a.0 - s, a.1 - u);
    let qa = ds * ds + du * du;
    let qb = ds * ps + du * pu;
    let qc = ps * ps + pu * pu;
    let r2 = r * r;
    let depth = |t: f64| {
        let d2 = qa * t * t + 2.0 * qb * t + qc;
        a.2 + dh * t - (r2 - d2).max(0.0).sqrt()
    };
    if qa <= 1e-30 {
        return (qc <= r2).then(|| a.2.min(b.2) - (r2 - qc).sqrt());
    }
    // Where the ball reaches: d(t)² ≤ r², a range of t.
    let disc = qb * qb - qa * (qc - r2);
    if disc < 0.0 {
        return None;
    }
    let root = disc.sqrt();
    let (lo, hi) = (((-qb - root) / qa).max(0.0), ((-qb + root) / qa).min(1.0));
    if lo > hi {
        return None;
    }
    // h'(t) = 0: with w = qa t + qb, w² = dh² disc / (qa + dh²), w against dh.
    let w = -dh.signum() * (dh * dh * disc / (qa + dh * dh)).sqrt();
    let t = ((w - qb) / qa).clamp(lo, hi);
    Some(depth(t))
}

/// Whether `p` lies within the angle the minor arc from `a` to `b` about
/// `o` spans (all in the (s, h) plane).
fn within_span(a: (f64, f64), b: (f64, f64), o: (f64, f64), p: (f64, f64)) -> bool {
    let cross =
        |x: (f64, f64), y: (f64, f64)| (x.0 - o.0) * (y.1 - o.1) - (x.1 - o.1) * (y.0 - o.0);
    let turn = cross(a, b);
    let (first, second) = (cross(a, p), cross(p, b));
    if turn >= 0.0 {
        first >= 0.0 && second >= 0.0
    } else {
        first <= 0.0 && second <= 0.0
    }
}

/// The lowest point at (s, u) within `r` of the minor arc from `a` to `b`
/// (points (s, u, h), u the same at both) about `o` (s, h): the lowest of
/// the end spheres' bottoms and of the points of the torus (the circles
/// of radius ρ ± w about `o`, w = √(r² − (u − u_arc)²)) over s inside the
/// arc's angle. Every such point is within `r` of the arc, and the lowest
/// point of the set lies on one of them.
fn arc_bottom(
    a: (f64, f64, f64),
    b: (f64, f64, f64),
    o: (f64, f64),
    r: f64,
    s: f64,
    u: f64,
) -> Option<f64> {
    let du = u - (a.1 + b.1) / 2.0;
    if du.abs() > r {
        return None;
    }
    let w = (r * r - du * du).sqrt();
    let rho = ((a.0 - o.0).hypot(a.2 - o.1) + (b.0 - o.0).hypot(b.2 - o.1)) / 2.0;
    let mut lowest: Option<f64> = None;
    let mut take = |h: f64| {
        if h.is_finite() && lowest.is_none_or(|l| h < l) {
            lowest = Some(h);
        }
    };
    for end in [a, b] {
        let d = s - end.0;
        if d.abs() <= w {
            take(end.2 - (w * w - d * d).sqrt());
        }
    }
    let (pa, pb) = ((a.0, a.2), (b.0, b.2));
    for ring in [rho + w, rho - w] {
        if ring <= 0.0 {
            continue;
        }
        let d = s - o.0;
        if d.abs() > ring {
            continue;
        }
        let half = (ring * ring - d * d).sqrt();
        for h in [o.1 - half, o.1 + half] {
            if within_span(pa, pb, o, (s, h)) {
                take(h);
            }
        }
    }
    lowest
}

/// The ball's centre path gathered column by column: each piece listed
/// in every column it can reach.
pub struct BallSweep {
    grid: Grid,
    radius: f64,
    band: (f64, f64),
    pieces: Vec<Piece>,
    /// Per column, the indices of the pieces that reach it.
    columns: Vec<Vec<u32>>,
    last: Option<(f64, f64, f64)>,
}

impl NosePath for BallSweep {
    fn lift(&mut self) {
        self.last = None;
    }
    fn point(&mut self, s: f64, u: f64, h: f64) {
        self.piece((s, u, h), None);
    }
    fn arc(&mut self, s: f64, u: f64, h: f64, centre: (f64, f64)) {
        self.piece((s, u, h), Some(centre));
    }
}

impl BallSweep {
    /// A sweep of a ball of `radius` over `grid` (whose columns do not
    /// repeat: a raster's).
    pub fn new(grid: Grid, radius: f64) -> BallSweep {
        BallSweep {
            grid,
            radius,
            band: band(&grid, radius),
            pieces: Vec::new(),
            columns: vec![Vec::new(); grid.ns],
            last: None,
        }
    }

    /// The band of step-over coordinates (u) whose passes reach the rows.
    pub fn band(&self) -> (f64, f64) {
        self.band
    }

    fn piece(&mut self, p: (f64, f64, f64), arc: Option<(f64, f64)>) {
        let Some(a) = self.last.replace(p) else {
            return;
        };
        if a.1.max(p.1) < self.band.0 || a.1.min(p.1) > self.band.1 || self.grid.ns == 0 {
            return;
        }
        // A straight piece where the arc's ends and centre disagree.
        let arc = arc.filter(|&o| (a.1 - p.1).abs() < 1e-9 && (a.0, a.2) != o);
        let piece = Piece {
            a,
            b: p,
            arc,
            pass: (a.1 * 1e9).round() as i64,
        };
        let (lo, hi) = piece.s_reach(self.radius);
        let g = self.grid;
        let j_lo = ((lo - g.s0) / g.ds).ceil().max(g.j0 as f64);
        let j_hi = ((hi - g.s0) / g.ds).floor().min((g.j0 + g.ns - 1) as f64);
        if j_lo.partial_cmp(&j_hi).is_none_or(|o| o.is_gt()) {
            return;
        }
        let index = self.pieces.len() as u32;
        self.pieces.push(piece);
        for jg in j_lo as usize..=j_hi as usize {
            self.columns[jg - g.j0].push(index);
        }
    }

    /// The cut in every column against the design, as one tile of a larger
    /// map (see [`super::Sweep::finish_tile`]).
    pub(crate) fn finish_tile(
        self,
        frame: &dyn Frame,
        feature: &dyn Fn(usize) -> usize,
        layout: &RasterLayout,
        parallel: bool,
    ) -> (Totals, Vec<(usize, f64)>) {
        let g = self.grid;
        let one = |(j, list): (usize, &Vec<u32>)| self.column(j, list, frame);
        let columns: Vec<Column> = if parallel {
            self.columns.par_iter().enumerate().map(one).collect()
        } else {
            self.columns.iter().enumerate().map(one).collect()
        };
        super::finish_columns(&g, &columns, frame, feature, layout)
    }

    /// One column: each row's lowest cut and the pass that makes it, then
    /// the errors, the passes' contacts and the cusps between them.
    fn column(&self, j: usize, list: &[u32], frame: &dyn Frame) -> Column {
        let (g, r) = (self.grid, self.radius);
        let s = g.s(j);
        let mut cut = vec![f64::NAN; g.nu];
        let mut owner = vec![i64::MIN; g.nu];
        for &k in list {
            let piece = &self.pieces[k as usize];
            let (u_lo, u_hi) = (piece.a.1.min(piece.b.1) - r, piece.a.1.max(piece.b.1) + r);
            let i_lo = ((u_lo - g.u0) / g.du).ceil().max(g.i0 as f64);
            let i_hi = ((u_hi - g.u0) / g.du)
                .floor()
                .min((g.i0 + g.nu) as f64 - 1.0);
            if i_lo.partial_cmp(&i_hi).is_none_or(|o| o.is_gt()) {
                continue;
            }
            for ig in i_lo as usize..=i_hi as usize {
                let i = ig - g.i0;
                if let Some(h) = piece.bottom(r, s, g.u(i))
                    && (cut[i].is_nan() || h < cut[i])
                {
                    cut[i] = h;
                    owner[i] = piece.pass;
                }
            }
        }
        let cut_by = ColumnCut {
            s,
            r,
            pieces: list.iter().map(|&k| &self.pieces[k as usize]).collect(),
            frame,
        };
        for (i, c) in cut.iter_mut().enumerate() {
            if !c.is_nan() && !cut_by.in_window(g.u(i)) {
                *c = f64::NAN;
            }
        }
        let rows: Vec<usize> = (0..g.nu).filter(|&i| !cut[i].is_nan()).collect();
        let points: Vec<(f64, f64)> = rows.iter().map(|&i| (s, g.u(i))).collect();
        let mut design = vec![0.0; rows.len()];
        frame.design(&points, &mut design);
        for (&i, d) in rows.iter().zip(&design) {
            cut[i] -= d;
        }
        let runs = runs(&cut, &owner);
        let valleys: Vec<(f64, f64)> = runs
            .iter()
            .map(|run| cut_by.valley(&g, &cut, run))
            .collect();
        let cusps = cut_by.cusps(&g, &runs, &valleys);
        Column {
            errors: cut,
            valleys: valleys.into_iter().filter(|v| !v.1.is_nan()).collect(),
            cusps,
        }
    }
}

/// A run of neighbouring rows cut by one pass: its first and last row.
#[derive(Clone, Copy, Debug)]
struct Run {
    pass: i64,
    first: usize,
    last: usize,
}

/// The runs of rows each pass owns, in order of u.
fn runs(errors: &[f64], owner: &[i64]) -> Vec<Run> {
    let mut runs: Vec<Run> = Vec::new();
    for (i, (&e, &p)) in errors.iter().zip(owner).enumerate() {
        if e.is_nan() {
            continue;
        }
        match runs.last_mut() {
            Some(run) if run.pass == p && run.last + 1 == i => run.last = i,
            _ => runs.push(Run {
                pass: p,
                first: i,
                last: i,
            }),
        }
    }
    runs
}

/// A column's pieces, for the cut of one pass at any u.
struct ColumnCut<'a> {
    s: f64,
    r: f64,
    pieces: Vec<&'a Piece>,
    frame: &'a dyn Frame,
}

impl ColumnCut<'_> {
    /// The lowest cut pass `pass` makes at u (NaN where it does not reach).
    fn cut(&self, pass: i64, u: f64) -> f64 {
        self.pieces
            .iter()
            .filter(|p| p.pass == pass)
            .filter_map(|p| p.bottom(self.r, self.s, u))
            .fold(f64::NAN, f64::min)
    }

    fn design_at(&self, u: f64) -> f64 {
        let mut dz = [0.0];
        self.frame.design(&[(self.s, u)], &mut dz);
        dz[0]
    }

    fn in_window(&self, u: f64) -> bool {
        let (x, y) = self.frame.xy(self.s, u);
        self.frame.inside(x, y) && in_features(self.frame.features(), x, y)
    }

    /// A run's contact: its least error, refined by the parabola through
    /// it and its neighbours; (NaN, NaN) where the least lies on a run's
    /// end that no other pass bounds (the window's edge or uncut cells).
    fn valley(&self, g: &Grid, errors: &[f64], run: &Run) -> (f64, f64) {
        let m = (run.first..=run.last)
            .min_by(|&x, &y| errors[x].total_cmp(&errors[y]))
            .unwrap_or(run.first);
        let bounded = |i: usize| i.checked_sub(1).is_some_and(|k| !errors[k].is_nan());
        let open_start = m == run.first && !bounded(run.first);
        let open_end = m == run.last && errors.get(run.last + 1).is_none_or(|e| e.is_nan());
        if (open_start || open_end) && run.first != run.last {
            return (f64::NAN, f64::NAN);
        }
        let (mut best_u, mut best) = (g.u(m), errors[m]);
        if m > run.first && m < run.last {
            let (e0, e1, e2) = (errors[m - 1], errors[m], errors[m + 1]);
            let curv = e0 - 2.0 * e1 + e2;
            if curv > 0.0 {
                let t = 0.5 * (e0 - e2) / curv;
                let u = g.u(m) + t * g.du;
                let e = self.cut(run.pass, u) - self.design_at(u);
                if e < best {
                    (best_u, best) = (u, e);
                }
            }
        }
        (best_u, best)
    }

    /// Where neighbouring runs' passes cut alike (between their rows, by
    /// bisection), and how high the cut is there above the mean of their
    /// contacts.
    fn cusps(&self, g: &Grid, runs: &[Run], valleys: &[(f64, f64)]) -> Vec<(f64, f64)> {
        let mut cusps = Vec::new();
        for k in 1..runs.len() {
            let (left, right) = (runs[k - 1], runs[k]);
            let (va, vb) = (valleys[k - 1].1, valleys[k].1);
            if left.last + 1 != right.first || va.is_nan() || vb.is_nan() {
                continue;
            }
            let (mut a, mut b) = (g.u(left.last), g.u(right.first));
            for _ in 0..60 {
                let m = (a + b) / 2.0;
                if self.cut(left.pass, m) <= self.cut(right.pass, m) {
                    a = m;
                } else {
                    b = m;
                }
            }
            let u = (a + b) / 2.0;
            let e = self.cut(left.pass, u).min(self.cut(right.pass, u)) - self.design_at(u);
            cusps.push((u, e - (va + vb) / 2.0));
        }
        cusps
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The brute-force lowest point at (s, u) within r of a path: the
    /// least over many points along it of the sphere's bottom there.
    fn brute(points: impl Iterator<Item = (f64, f64, f64)>, r: f64, s: f64, u: f64) -> Option<f64> {
        points
            .filter_map(|(ps, pu, ph)| {
                let d2 = (ps - s).powi(2) + (pu - u).powi(2);
                (d2 <= r * r).then(|| ph - (r * r - d2).sqrt())
            })
            .reduce(f64::min)
    }

    #[test]
    fn a_capsule_bottom_is_the_least_of_its_spheres() {
        let (a, b, r) = ((0.0, 0.0, 0.0), (0.3, 0.05, 0.12), 0.2);
        let n = 200_000;
        let along = |t: f64| {
            (
                a.0 + t * (b.0 - a.0),
                a.1 + t * (b.1 - a.1),
                a.2 + t * (b.2 - a.2),
            )
        };
        for &(s, u) in &[
            (0.1, 0.0),
            (-0.15, 0.02),
            (0.45, 0.1),
            (0.2, -0.1),
            (0.6, 0.0),
        ] {
            let exact = capsule_bottom(a, b, r, s, u);
            let sampled = brute((0..=n).map(|k| along(k as f64 / n as f64)), r, s, u);
            match (exact, sampled) {
                (Some(e), Some(m)) => assert!((e - m).abs() < 1e-9 && e <= m + 1e-15, "{e} vs {m}"),
                (None, None) => {}
                other => panic!("reach disagrees at ({s}, {u}): {other:?}"),
            }
        }
    }

    #[test]
    fn an_arc_bottom_is_the_least_of_its_spheres() {
        // Convex (centre below) and concave (centre above) minor arcs.
        for (o, rho, from, to) in [
            ((0.2, -1.0), 1.0_f64, 1.3_f64, 1.8_f64),
            ((0.1, 0.8), 0.8, -1.9, -1.2),
        ] {
            let at = |t: f64| {
                let phi = from + t * (to - from);
                (o.0 + rho * phi.cos(), 0.01, o.1 + rho * phi.sin())
            };
            let (a, b, r) = (at(0.0), at(1.0), 0.15);
            let n = 200_000;
            for &(s, u) in &[
                (0.0, 0.01),
                (0.25, 0.05),
                (-0.3, 0.0),
                (0.5, 0.1),
                (0.4, -0.12),
            ] {
                let exact = arc_bottom(a, b, o, r, s, u);
                let sampled = brute((0..=n).map(|k| at(k as f64 / n as f64)), r, s, u);
                match (exact, sampled) {
                    (Some(e), Some(m)) => {
                        assert!(
                            (e - m).abs() < 1e-9 && e <= m + 1e-12,
                            "{e} vs {m} at ({s}, {u})"
                        )
                    }
                    (None, None) => {}
                    other => panic!("reach disagrees at ({s}, {u}): {other:?}"),
                }
            }
        }
    }
}
