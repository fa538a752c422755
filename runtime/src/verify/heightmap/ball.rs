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

use super::{Column, Frame, Grid, NosePath, RasterLayout, band, in_features};

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
    /// The range of s the centre's path covers.
    span: (f64, f64),
    /// An arc's radius: the mean of its ends' distances from its centre
    /// (printed centres and ends disagree by the resolution); 0 for a
    /// straight piece.
    rho: f64,
    /// The lowest height the centre's path reaches ([`Piece::lowest`]).
    low: f64,
}

impl Piece {
    /// The lowest height the ball of `radius` reaches at (s, u) when its
    /// centre runs along this piece; `None` where it does not reach.
    fn bottom(&self, radius: f64, s: f64, u: f64) -> Option<f64> {
        match self.arc {
            None => capsule_bottom(self.a, self.b, radius, s, u),
            Some(o) => arc_bottom(self.a, self.b, (o, self.rho), radius, s, u),
        }
    }

    /// The lowest height the centre's path reaches: the lower end, or
    /// the bottom of an arc that passes through it.
    fn lowest(&self) -> f64 {
        let ends = self.a.2.min(self.b.2);
        match self.arc {
            None => ends,
            Some(o) => {
                let rho = (self.a.0 - o.0).hypot(self.a.2 - o.1);
                let bottom = (o.0, o.1 - rho);
                if within_span((self.a.0, self.a.2), (self.b.0, self.b.2), o, bottom) {
                    // The two ends' radii differ by the printed rounding.
                    let rho = rho.max((self.b.0 - o.0).hypot(self.b.2 - o.1));
                    ends.min(o.1 - rho)
                } else {
                    ends
                }
            }
        }
    }

    /// The range of s the centre's path covers.
    fn s_span(&self) -> (f64, f64) {
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
        (lo, hi)
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

/// The mean distance of the arc's ends `a`, `b` (s, u, h) from its centre
/// `o` (s, h).
fn arc_radius(a: (f64, f64, f64), b: (f64, f64, f64), o: (f64, f64)) -> f64 {
    ((a.0 - o.0).hypot(a.2 - o.1) + (b.0 - o.0).hypot(b.2 - o.1)) / 2.0
}

/// The lowest point at (s, u) within `r` of the minor arc from `a` to `b`
/// (points (s, u, h), u the same at both) about `o` (s, h), of radius
/// `rho` ([`arc_radius`], found once per piece): the lowest of
/// the end spheres' bottoms and of the points of the torus (the circles
/// of radius ρ ± w about `o`, w = √(r² − (u − u_arc)²)) over s inside the
/// arc's angle. Every such point is within `r` of the arc, and the lowest
/// point of the set lies on one of them.
fn arc_bottom(
    a: (f64, f64, f64),
    b: (f64, f64, f64),
    (o, rho): ((f64, f64), f64),
    r: f64,
    s: f64,
    u: f64,
) -> Option<f64> {
    let du = u - (a.1 + b.1) / 2.0;
    if du.abs() > r {
        return None;
    }
    let w = (r * r - du * du).sqrt();
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
    /// Every piece tried on every row it reaches, none culled: the
    /// reference the culled sweep is tested against.
    brute: bool,
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
            brute: false,
        }
    }

    /// The same sweep with no piece culled (the reference).
    #[cfg(test)]
    fn brute(self) -> BallSweep {
        BallSweep {
            brute: true,
            ..self
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
        let mut piece = Piece {
            a,
            b: p,
            arc,
            pass: (a.1 * 1e9).round() as i64,
            span: (0.0, 0.0),
            rho: arc.map_or(0.0, |o| arc_radius(a, p, o)),
            low: 0.0,
        };
        piece.span = piece.s_span();
        piece.low = piece.lowest();
        let (lo, hi) = (piece.span.0 - self.radius, piece.span.1 + self.radius);
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
    ) -> super::TileBlocks {
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
        if self.brute {
            self.lowest_cuts_brute(s, list, &mut cut, &mut owner);
        } else {
            self.lowest_cuts(s, list, &mut cut, &mut owner);
        }
        let mut passes: std::collections::BTreeMap<i64, Vec<&Piece>> = Default::default();
        for &k in list {
            let piece = &self.pieces[k as usize];
            passes.entry(piece.pass).or_default().push(piece);
        }
        let cut_by = ColumnCut {
            s,
            r,
            passes,
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
        let (cusps, bounds) = cut_by.cusps(&g, &runs, &valleys);
        Column {
            errors: cut,
            valleys: valleys.into_iter().filter(|v| !v.1.is_nan()).collect(),
            cusps,
            bounds,
            rows: (0, g.nu),
        }
    }
}

impl BallSweep {
    /// Each row's lowest cut at column `s` and the pass that makes it,
    /// from the pieces `list` names: each row first by the pieces whose
    /// path crosses the column nearest it on either side, then block by
    /// block of `ROW_BLOCK` rows, the pieces whose bound is below the
    /// block's highest cut so far taken lowest bound first, and
    /// once the next one's bound (its lowest centre less the ball's reach
    /// over the block, [`Piece::lowest`]) is no lower than the block's
    /// highest cut so far, neither it nor any after it can lower a cell,
    /// and the block is done. The cut is the same as every piece's tried
    /// on every row ([`BallSweep::lowest_cuts_brute`]).
    fn lowest_cuts(&self, s: f64, list: &[u32], cut: &mut [f64], owner: &mut [i64]) {
        let (g, r) = (self.grid, self.radius);
        let mut try_piece = |k: u32, rows: std::ops::Range<usize>, cut: &mut [f64]| {
            let piece = &self.pieces[k as usize];
            let Some((i_lo, i_hi, _)) = self.rows_reached(piece, s) else {
                return;
            };
            for i in i_lo.max(rows.start)..=i_hi.min(rows.end.saturating_sub(1)) {
                if let Some(h) = piece.bottom(r, s, g.u(i))
                    && (cut[i].is_nan() || h < cut[i])
                {
                    cut[i] = h;
                    owner[i] = piece.pass;
                }
            }
        };
        // Rows some piece's bounds reach: others stay uncut, and do not
        // hold their block's culling back.
        let mut reached = vec![0i32; g.nu + 1];
        // The pieces whose path crosses the column, by their u: each row
        // is first cut by the nearest on either side, so every block has
        // a highest cut to hold the others' bounds to before any is
        // sorted.
        let mut crossing: Vec<(f64, u32)> = Vec::new();
        for &k in list {
            let piece = &self.pieces[k as usize];
            let Some((i_lo, i_hi, gap)) = self.rows_reached(piece, s) else {
                continue;
            };
            reached[i_lo] += 1;
            reached[i_hi + 1] -= 1;
            if gap == 0.0 {
                crossing.push(((piece.a.1 + piece.b.1) / 2.0, k));
            }
        }
        crossing.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        let mut next = 0;
        for i in 0..g.nu {
            let u = g.u(i);
            while next < crossing.len() && crossing[next].0 < u {
                next += 1;
            }
            for &(_, k) in crossing[next.saturating_sub(1)..(next + 1).min(crossing.len())].iter() {
                try_piece(k, i..i + 1, cut);
            }
        }
        let mut count = 0;
        let reached: Vec<bool> = reached[..g.nu]
            .iter()
            .map(|&d| {
                count += d;
                count > 0
            })
            .collect();
        let blocks = g.nu.div_ceil(ROW_BLOCK);
        let rows_of = |b: usize| b * ROW_BLOCK..((b + 1) * ROW_BLOCK).min(g.nu);
        let highest = |rows: std::ops::Range<usize>, cut: &[f64]| {
            rows.filter(|&i| reached[i])
                .map(|i| {
                    if cut[i].is_nan() {
                        f64::INFINITY
                    } else {
                        cut[i]
                    }
                })
                .fold(f64::NEG_INFINITY, f64::max)
        };
        let tops: Vec<f64> = (0..blocks).map(|b| highest(rows_of(b), cut)).collect();
        let mut reach: Vec<Vec<(f64, u32)>> = vec![Vec::new(); blocks];
        for &k in list {
            let piece = &self.pieces[k as usize];
            let Some((i_lo, i_hi, gap)) = self.rows_reached(piece, s) else {
                continue;
            };
            let (pu_lo, pu_hi) = (piece.a.1.min(piece.b.1), piece.a.1.max(piece.b.1));
            let low = piece.low;
            for (b, pieces) in reach
                .iter_mut()
                .enumerate()
                .take(i_hi / ROW_BLOCK + 1)
                .skip(i_lo / ROW_BLOCK)
            {
                let (bu_lo, bu_hi) = (g.u(b * ROW_BLOCK), g.u(((b + 1) * ROW_BLOCK).min(g.nu) - 1));
                let du = (pu_lo - bu_hi).max(bu_lo - pu_hi).max(0.0);
                let left = r * r - gap * gap - du * du;
                // Only a piece that may cut below the block's highest cut.
                if left >= 0.0 && low - left.sqrt() < tops[b] {
                    pieces.push((low - left.sqrt(), k));
                }
            }
        }
        for (b, pieces) in reach.iter_mut().enumerate() {
            pieces.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
            let rows = rows_of(b);
            let mut top = tops[b];
            for &(bound, k) in pieces.iter() {
                if bound >= top {
                    break;
                }
                try_piece(k, rows.clone(), cut);
                top = highest(rows.clone(), cut);
            }
        }
    }

    /// The rows (on this tile, first and last) within the ball's reach of
    /// `piece` at column `s`, and its gap in s from the column; `None`
    /// where it reaches none.
    fn rows_reached(&self, piece: &Piece, s: f64) -> Option<(usize, usize, f64)> {
        let (g, r) = (self.grid, self.radius);
        // Across the cut it reaches as far as the ball's section at the
        // nearest s its path covers.
        let gap = (piece.span.0 - s).max(s - piece.span.1).max(0.0);
        if gap > r {
            return None;
        }
        let w = (r * r - gap * gap).sqrt();
        let (u_lo, u_hi) = (piece.a.1.min(piece.b.1) - w, piece.a.1.max(piece.b.1) + w);
        let i_lo = ((u_lo - g.u0) / g.du).ceil().max(g.i0 as f64);
        let i_hi = ((u_hi - g.u0) / g.du)
            .floor()
            .min((g.i0 + g.nu) as f64 - 1.0);
        if i_lo.partial_cmp(&i_hi).is_none_or(|o| o.is_gt()) {
            return None;
        }
        Some((i_lo as usize - g.i0, i_hi as usize - g.i0, gap))
    }

    /// Each row's lowest cut by trying every piece on every row it
    /// reaches: what [`BallSweep::lowest_cuts`] must equal.
    fn lowest_cuts_brute(&self, s: f64, list: &[u32], cut: &mut [f64], owner: &mut [i64]) {
        let (g, r) = (self.grid, self.radius);
        for &k in list {
            let piece = &self.pieces[k as usize];
            let Some((i_lo, i_hi, _)) = self.rows_reached(piece, s) else {
                continue;
            };
            for i in i_lo..=i_hi {
                if let Some(h) = piece.bottom(r, s, g.u(i))
                    && (cut[i].is_nan() || h < cut[i])
                {
                    cut[i] = h;
                    owner[i] = piece.pass;
                }
            }
        }
    }
}

/// Rows a block of a column holds when its pieces are culled
/// ([`BallSweep::lowest_cuts`]).
const ROW_BLOCK: usize = 16;

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
    /// The column's pieces by pass.
    passes: std::collections::BTreeMap<i64, Vec<&'a Piece>>,
    frame: &'a dyn Frame,
}

impl ColumnCut<'_> {
    /// The lowest cut pass `pass` makes at u (NaN where it does not reach).
    fn cut(&self, pass: i64, u: f64) -> f64 {
        self.passes
            .get(&pass)
            .into_iter()
            .flatten()
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
    /// end that no other pass bounds (the window's edge or uncut cells)
    /// and the pass's own cut, a row beyond that end, is lower or cannot
    /// be told: its contact lies outside the window, and the rows inside
    /// are the flank of its scallop (as the knife's contact counts only
    /// where its least lies in the window, [`super::ColumnCut::valleys`]).
    /// A run of one row is judged so too: where the window's edge crosses
    /// a column just past a cusp, the one row of the pass beyond is that
    /// scallop's top, not a contact (issue #29).
    fn valley(&self, g: &Grid, errors: &[f64], run: &Run) -> (f64, f64) {
        let m = (run.first..=run.last)
            .min_by(|&x, &y| errors[x].total_cmp(&errors[y]))
            .unwrap_or(run.first);
        let bounded = |i: usize| i.checked_sub(1).is_some_and(|k| !errors[k].is_nan());
        let open_start = m == run.first && !bounded(run.first);
        let open_end = m == run.last && errors.get(run.last + 1).is_none_or(|e| e.is_nan());
        // The pass's error a row beyond `u`, no lower than the least:
        // the least is a contact.
        let rises = |u: f64| {
            let beyond = self.cut(run.pass, u) - self.design_at(u);
            beyond >= errors[m]
        };
        if (open_start && !rises(g.u(m) - g.du)) || (open_end && !rises(g.u(m) + g.du)) {
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

    /// Where pass `left`'s cut meets pass `right`'s between the rows
    /// `(a, b)` (the left one cutting lower at a, the right one at b): by
    /// the Illinois variant of false position on the difference of the
    /// two cuts, which converges in a few steps where the two balls' cuts
    /// are smooth, to 1e-13 mm; by bisection (40 halvings of rows a few
    /// micrometres apart leave 1e-18 mm) where a cut is missing or the
    /// ends do not bracket the meeting.
    fn meet(&self, left: i64, right: i64, (mut a, mut b): (f64, f64)) -> f64 {
        let diff = |m: f64| self.cut(left, m) - self.cut(right, m);
        let (mut fa, mut fb) = (diff(a), diff(b));
        if fa.is_finite() && fb.is_finite() && fa <= 0.0 && fb > 0.0 {
            // Which end moved last: halve the other's value when it
            // stays twice running (Illinois).
            let mut last = 0;
            for _ in 0..100 {
                if b - a <= 1e-13 {
                    break;
                }
                let m = (a * fb - b * fa) / (fb - fa);
                // A step that leaves the bracket (rounding) bisects.
                let m = if m > a && m < b { m } else { (a + b) / 2.0 };
                let fm = diff(m);
                if !fm.is_finite() {
                    return self.halve(left, right, (a, b));
                }
                if fm <= 0.0 {
                    (a, fa) = (m, fm);
                    if last == -1 {
                        fb /= 2.0;
                    }
                    last = -1;
                } else {
                    (b, fb) = (m, fm);
                    if last == 1 {
                        fa /= 2.0;
                    }
                    last = 1;
                }
                if fm == 0.0 {
                    return m;
                }
            }
            return (a + b) / 2.0;
        }
        self.halve(left, right, (a, b))
    }

    /// [`ColumnCut::meet`] by 40 halvings.
    fn halve(&self, left: i64, right: i64, (mut a, mut b): (f64, f64)) -> f64 {
        for _ in 0..40 {
            let m = (a + b) / 2.0;
            if self.cut(left, m) <= self.cut(right, m) {
                a = m;
            } else {
                b = m;
            }
        }
        (a + b) / 2.0
    }

    /// Where neighbouring runs' passes cut alike (between their rows,
    /// [`ColumnCut::meet`]), and how high the cut is there above the mean
    /// of their contacts: between two contacts (the scallops reported),
    /// and elsewhere above the nearest contacts either side
    /// (`Column::bounds`, for the scallop a cell is allowed: a rim's last
    /// cusp with a pass whose contact lies beyond the window).
    #[allow(clippy::type_complexity)]
    fn cusps(
        &self,
        g: &Grid,
        runs: &[Run],
        valleys: &[(f64, f64)],
    ) -> (Vec<(f64, f64)>, Vec<(f64, f64)>) {
        let (mut cusps, mut bounds) = (Vec::new(), Vec::new());
        let nearest = super::nearest_contacts(valleys);
        for k in 1..runs.len() {
            let (left, right) = (runs[k - 1], runs[k]);
            let (va, vb) = (valleys[k - 1].1, valleys[k].1);
            let mean = nearest[k - 1].0.mean_with(nearest[k].1);
            if left.last + 1 != right.first || mean.is_nan() {
                continue;
            }
            let u = self.meet(left.pass, right.pass, (g.u(left.last), g.u(right.first)));
            let e = self.cut(left.pass, u).min(self.cut(right.pass, u)) - self.design_at(u);
            if va.is_nan() || vb.is_nan() {
                if !(e - mean).is_nan() {
                    bounds.push((u, e - mean));
                }
                continue;
            }
            cusps.push((u, e - (va + vb) / 2.0));
            bounds.push((u, e - (va + vb) / 2.0));
        }
        (cusps, bounds)
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
                let exact = arc_bottom(a, b, (o, arc_radius(a, b, o)), r, s, u);
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

    /// A cubic design (mm) over the test's window.
    fn cubic(s: f64, u: f64) -> f64 {
        0.02 * (s * s * s + u * u * u) + 0.002 * (9.0 * s).sin()
    }

    struct Cubic;
    impl Frame for Cubic {
        fn design(&self, points: &[(f64, f64)], out: &mut [f64]) {
            for (o, &(s, u)) in out.iter_mut().zip(points) {
                *o = cubic(s, u);
            }
        }
        fn xy(&self, s: f64, u: f64) -> (f64, f64) {
            (s, u)
        }
        fn inside(&self, x: f64, y: f64) -> bool {
            (x - 0.5).hypot(y - 0.3) <= 0.28
        }
    }

    /// A raster of a ball of radius `r` over the cubic: passes 15 µm
    /// apart along s, chords 40 µm long, the centre one radius above the
    /// design (not an exact offset: the form error is the chords' and the
    /// offset's), every fifth pass with a circular arc in its middle and
    /// one point 200 nm low (a gouge).
    fn swept(sweep: &mut dyn NosePath, r: f64) {
        for p in 0..=40 {
            let u = 0.0 + p as f64 * 0.015;
            sweep.lift();
            for k in 0..=25 {
                let s = k as f64 * 0.04;
                let mut h = cubic(s, u) + r;
                if p % 5 == 2 && k == 13 {
                    h -= 200e-6;
                }
                if p % 5 == 0 && k == 12 {
                    // A flat arc through the point (centre far above).
                    let (sa, ha) = (s - 0.04, cubic(s - 0.04, u) + r);
                    let mid = ((sa + s) / 2.0, (ha + h) / 2.0);
                    let (ds, dh) = (s - sa, h - ha);
                    let len = ds.hypot(dh);
                    let centre = (mid.0 - 2.0 * dh / len, mid.1 + 2.0 * ds / len);
                    sweep.arc(s, u, h, centre);
                } else {
                    sweep.point(s, u, h);
                }
            }
        }
    }

    /// The culled sweep gives the same map as every piece tried on every
    /// row: the same cut in every cell, so the same PV, RMS, gouge,
    /// residual, contacts and scallops, with a tolerance of zero.
    #[test]
    fn culling_pieces_changes_no_cell() {
        let g = Grid {
            s0: 0.2,
            ds: 0.004,
            ns: 151,
            u0: 0.0,
            du: 0.003,
            nu: 201,
            period: None,
            j0: 0,
            i0: 0,
        };
        let r = 0.1;
        let layout = RasterLayout::new((0.2, 0.8), (0.0, 0.6), 0.01, 64);
        let run = |brute: bool| {
            let mut sweep = BallSweep::new(g, r);
            if brute {
                sweep = sweep.brute();
            }
            swept(&mut sweep, r);
            let (totals, blocks, _) = sweep.finish_tile(&Cubic, &|f| f, &layout, false);
            (
                super::super::HeightMap::of(g, r, totals, &Cubic, Vec::new()),
                blocks,
            )
        };
        let (fast, fast_blocks) = run(false);
        let (brute, brute_blocks) = run(true);
        let (f, b) = (fast.surface.unwrap(), brute.surface.unwrap());
        assert!(b.count > 20_000, "{b:?}");
        // The gouges show: 200 nm low, less the ball's reach over it.
        assert!(b.max_gouge.0 > 100e-6, "{b:?}");
        assert_eq!(
            (f.pv, f.rms, f.max_gouge, f.max_residual),
            (b.pv, b.rms, b.max_gouge, b.max_residual)
        );
        assert_eq!(fast.contact, brute.contact);
        assert_eq!(fast.scallops, brute.scallops);
        assert_eq!(fast_blocks, brute_blocks);
        assert_eq!(fast, brute);
    }

    /// A flat design judged in a circle (the whole part's window).
    struct FlatDisc;
    impl Frame for FlatDisc {
        fn design(&self, points: &[(f64, f64)], out: &mut [f64]) {
            out[..points.len()].fill(0.0);
        }
        fn xy(&self, s: f64, u: f64) -> (f64, f64) {
            (s, u)
        }
        fn inside(&self, x: f64, y: f64) -> bool {
            (x - 0.5).hypot(y - 0.3) <= 0.28
        }
    }

    /// A ball of 0.1 mm rastered on the flat exactly, passes 15 µm apart
    /// on every tenth row: each pass's contact is its centre's row, with
    /// no error; between passes the scallops, 281 nm high. Where the
    /// circular window's edge crosses a column just past a cusp, the
    /// rows inside it of the pass beyond the edge are the flank of its
    /// scallop (one row of them in some columns), and its contact lies
    /// outside: read as a contact, a scallop's height became the residual
    /// at the passes' contacts (issue #29: 551 nm on a dome whose contacts
    /// are 401 nm at most). Equally, a pass whose centre's row is the
    /// window's first or last has its contact there, and it counts: one
    /// contact per pass and column whose centre lies in the window, no
    /// more, no fewer.
    #[test]
    fn a_scallop_at_the_window_edge_is_not_a_contact() {
        let g = Grid {
            s0: 0.2,
            ds: 0.004,
            ns: 151,
            u0: 0.0,
            du: 0.0015,
            nu: 401,
            period: None,
            j0: 0,
            i0: 0,
        };
        let (r, step) = (0.1, 0.015);
        let mut sweep = BallSweep::new(g, r);
        for p in 0..=40 {
            sweep.lift();
            for k in 0..=30 {
                sweep.point(0.1 + k as f64 * 0.03, p as f64 * step, r);
            }
        }
        let layout = RasterLayout::new((0.2, 0.8), (0.0, 0.6), 0.01, 64);
        let (totals, _, _) = sweep.finish_tile(&FlatDisc, &|f| f, &layout, false);
        let map = super::super::HeightMap::of(g, r, totals, &FlatDisc, Vec::new());
        let scallop = super::super::HeightMap::flat_scallop(r, step);
        let surface = map.surface.expect("cut");
        assert!(
            surface.max_residual.0 > 0.95 * scallop,
            "{surface:?} {scallop}"
        );
        let contact = map.contact.expect("contacts");
        assert!(contact.max_residual.0 < 1e-9, "{contact:?}");
        let centres = (0..g.ns)
            .flat_map(|j| (0..=40).map(move |p| (g.s(j), g.u(10 * p))))
            .filter(|&(s, u)| FlatDisc.inside(s, u))
            .count();
        assert_eq!(contact.count, centres, "{contact:?}");
    }

    /// False position finds where two passes' cuts meet as bisection
    /// does: within 1e-12 mm, the cut there within 1e-15 mm (1e-6 nm).
    #[test]
    fn false_position_meets_where_bisection_does() {
        let g = Grid {
            s0: 0.2,
            ds: 0.02,
            ns: 31,
            u0: 0.0,
            du: 0.001,
            nu: 601,
            period: None,
            j0: 0,
            i0: 0,
        };
        let r = 0.1;
        let mut sweep = BallSweep::new(g, r);
        swept(&mut sweep, r);
        let mut met = 0;
        for (j, list) in sweep.columns.iter().enumerate() {
            let s = g.s(j);
            let (mut cut, mut owner) = (vec![f64::NAN; g.nu], vec![i64::MIN; g.nu]);
            sweep.lowest_cuts(s, list, &mut cut, &mut owner);
            let mut passes: std::collections::BTreeMap<i64, Vec<&Piece>> = Default::default();
            for &k in list {
                let piece = &sweep.pieces[k as usize];
                passes.entry(piece.pass).or_default().push(piece);
            }
            let by = ColumnCut {
                s,
                r,
                passes,
                frame: &Cubic,
            };
            let runs = runs(&cut, &owner);
            for k in 1..runs.len() {
                let (left, right) = (runs[k - 1], runs[k]);
                if left.last + 1 != right.first {
                    continue;
                }
                let ends = (g.u(left.last), g.u(right.first));
                let (u, v) = (
                    by.meet(left.pass, right.pass, ends),
                    by.halve(left.pass, right.pass, ends),
                );
                let at = |u: f64| by.cut(left.pass, u).min(by.cut(right.pass, u));
                assert!((u - v).abs() < 1e-12, "{u} vs {v}");
                assert!((at(u) - at(v)).abs() < 1e-15, "{} vs {}", at(u), at(v));
                met += 1;
            }
        }
        assert!(met > 500, "{met}");
    }
}
