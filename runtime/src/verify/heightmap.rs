//! Height-map cut simulation of surfaces: what a raster, spiral or helix
//! program leaves on a window of the part, from the tool positions it
//! commands (as printed), against the design.
//!
//! Every surface strategy here cuts with a round nose whose edge lies in
//! the plane across the cut: the microshaper knife's nose in the plane
//! normal to its stroke, a lathe's or roller lathe's diamond in the plane
//! through the spindle axis. So at each position `s` along the cut (x for
//! a raster, the spindle angle for a lathe or roller), every pass that
//! crosses `s` leaves a circle of the nose radius about its centre in the
//! (u, h) plane across it (u the step-over coordinate: y, the radius, the
//! axial z; h the height, material below), and the surface cut there is
//! the lower envelope of those circles. Between programmed points the
//! controller interpolates linearly (or along a printed arc), and so does
//! this simulation. The envelope of equal circles is exact: any two cross
//! once, so the envelope takes them in order of u, and its corners are the
//! scallop cusps, found exactly, whatever the grid.
//!
//! A nose whose edge was measured (`machine::edge`) is swept as that
//! edge: each pass leaves the edge's lower side, its depth L(d) below the
//! centre at offset d across it (`Nose::lift`), instead of the circle's;
//! two copies of it, convex as any round nose's is (its waviness bends it
//! far less than its radius does), still cross once, found from the
//! circles' crossing by the secant method.
//!
//! The grid's columns are positions along the cut and its rows positions
//! across; on a lathe they are angles and radii (a polar grid), masked to
//! the window the user asked for.

use rayon::prelude::*;
use std::sync::Arc;

use crate::machine::edge::{EdgeProfile, Nose};

mod ball;
pub use ball::BallSweep;

/// The cutter a height map sweeps: a round nose whose edge lies across
/// the cut (a knife, a lathe's diamond), as measured where its `edge`
/// is given, or a ball (a ball-end mill), which reaches its radius along
/// the path as well.
#[derive(Clone, Debug, PartialEq)]
pub enum Cutter {
    Nose {
        radius: f64,
        edge: Option<Arc<EdgeProfile>>,
    },
    Ball {
        radius: f64,
    },
}

impl Cutter {
    /// A round nose that is a circle of `radius`.
    pub fn nose(radius: f64) -> Cutter {
        Cutter::Nose { radius, edge: None }
    }

    pub fn radius(&self) -> f64 {
        match *self {
            Cutter::Nose { radius, .. } | Cutter::Ball { radius } => radius,
        }
    }

    /// How far from its centre the cutter reaches (mm): its radius, or a
    /// measured edge's farthest point.
    pub fn reach(&self) -> f64 {
        match self {
            Cutter::Nose {
                radius,
                edge: Some(e),
            } => radius + e.largest().0,
            _ => self.radius(),
        }
    }
}

/// The simulation grid: columns along the cut, rows across it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    /// First column (mm, or rad when `period` is set), spacing, count.
    pub s0: f64,
    pub ds: f64,
    pub ns: usize,
    /// First row (mm), spacing, count.
    pub u0: f64,
    pub du: f64,
    pub nu: usize,
    /// Columns are spindle angles repeating every `period` (2π); the
    /// columns must span less than one period.
    pub period: Option<f64>,
    /// On a tile, the index of its first column and row on the grid it is
    /// cut from (whose `s0`, `u0` it keeps, so its cells lie exactly
    /// where that grid's do); 0 on a whole grid.
    pub j0: usize,
    pub i0: usize,
}

impl Grid {
    pub fn s(&self, j: usize) -> f64 {
        self.s0 + (self.j0 + j) as f64 * self.ds
    }
    pub fn u(&self, i: usize) -> f64 {
        self.u0 + (self.i0 + i) as f64 * self.du
    }
    fn u_end(&self) -> f64 {
        self.u(self.nu.saturating_sub(1))
    }
}

/// How grid coordinates sit on the part, and the design there. The job
/// that plans the path supplies it.
pub trait Frame: Sync {
    /// Design heights h at the (s, u) points (same units and sense as the
    /// tool-centre heights: material below).
    fn design(&self, points: &[(f64, f64)], out: &mut [f64]);
    /// The part's (x, y) (mm) at (s, u).
    fn xy(&self, s: f64, u: f64) -> (f64, f64);
    /// Whether (x, y) is in the window the user asked for.
    fn inside(&self, x: f64, y: f64) -> bool;
    /// Discs (centre x, y, radius) reported one by one (lenslets), if any;
    /// when there are some, only cells inside them count in the totals.
    fn features(&self) -> &[(f64, f64, f64)] {
        &[]
    }
    /// An array's lenslets, each reported on its own, where there are no
    /// `features`: the totals count every cell of the window as before,
    /// and each cell in a lenslet's aperture (the nearest such lenslet,
    /// see [`super::lenslets`]) counts for that lenslet too.
    fn lenslets(&self) -> Option<&super::lenslets::Lenslets> {
        None
    }
    /// The part's area (mm²) of the grid cell at (s, u): the parallelogram
    /// its two steps span on the part.
    fn cell_area(&self, g: &Grid, s: f64, u: f64) -> f64 {
        let (x0, y0) = self.xy(s, u);
        let (x1, y1) = self.xy(s + g.ds, u);
        let (x2, y2) = self.xy(s, u + g.du);
        ((x1 - x0) * (y2 - y0) - (y1 - y0) * (x2 - x0)).abs()
    }
    /// The range of u (mm) in the column at `s` outside which no point
    /// is both `inside` and in one of `discs` (when there are any), found
    /// without asking either: a column's rows, contacts and cusps beyond
    /// it are then known to be outside without being tried. It may hold
    /// points outside, never leave one inside out. `None` when the frame
    /// cannot tell (every row is tried).
    fn column_reach(&self, _s: f64, _discs: &[(f64, f64, f64)]) -> Option<(f64, f64)> {
        None
    }
}

/// Where the nose's centre goes, as a program commands it: what a
/// [`Sweep`] gathers and a [`super::tiles::Recorder`] keeps for tiles.
pub trait NosePath {
    /// The tool leaves the part: the next point starts a new pass.
    fn lift(&mut self);
    /// The next commanded point of the current pass: cutting coordinate
    /// `s` (unwrapped angle for a lathe), step-over coordinate `u`,
    /// height `h` of the nose centre, reached along a straight line.
    fn point(&mut self, s: f64, u: f64, h: f64);
    /// The next point reached along a circular arc in the (s, h) plane
    /// (u constant) about `centre`; the arc is the minor one.
    fn arc(&mut self, s: f64, u: f64, h: f64, centre: (f64, f64));
}

impl NosePath for Sweep {
    fn lift(&mut self) {
        Sweep::lift(self)
    }
    fn point(&mut self, s: f64, u: f64, h: f64) {
        Sweep::point(self, s, u, h)
    }
    fn arc(&mut self, s: f64, u: f64, h: f64, centre: (f64, f64)) {
        Sweep::arc(self, s, u, h, centre)
    }
}

/// Tool-centre positions gathered column by column as the path streams.
pub struct Sweep {
    grid: Grid,
    radius: f64,
    /// The nose's measured edge, if any (the module doc).
    edge: Option<Arc<EdgeProfile>>,
    /// The band of u whose circles can reach the rows.
    band: (f64, f64),
    /// Per column, the (u, h) of every pass crossing it.
    columns: Vec<Vec<(f64, f64)>>,
    /// The previous point of the current pass.
    last: Option<(f64, f64, f64)>,
    /// Columns' range of s (non-periodic), for a quick reject.
    s_range: (f64, f64),
    /// Per column, whether any of its rows can be in the window (see
    /// [`Sweep::within`]); a column that cannot gathers no passes.
    live: Vec<bool>,
}

/// The band of step-over coordinates (u) whose passes, with a nose of
/// `nose_radius`, can reach `grid`'s rows.
pub fn band(grid: &Grid, nose_radius: f64) -> (f64, f64) {
    let margin = nose_radius + grid.du;
    (grid.u0 - margin, grid.u_end() + margin)
}

impl Sweep {
    pub fn new(grid: Grid, nose_radius: f64) -> Sweep {
        Sweep::with_edge(grid, nose_radius, None)
    }

    /// A sweep of a nose of `nose_radius` whose edge, where `edge` is
    /// given, is the one measured.
    pub fn with_edge(grid: Grid, nose_radius: f64, edge: Option<Arc<EdgeProfile>>) -> Sweep {
        let reach = nose_radius + edge.as_ref().map_or(0.0, |e| e.largest().0);
        Sweep {
            grid,
            radius: nose_radius,
            edge,
            band: band(&grid, reach),
            columns: vec![Vec::new(); grid.ns],
            last: None,
            s_range: (grid.s(0), grid.s(grid.ns.saturating_sub(1))),
            live: vec![true; grid.ns],
        }
    }

    /// A sweep of the columns whose rows `frame` can hold a cell of (its
    /// window and features, by [`Frame::column_reach`]): the others are
    /// left uncut, as every cell of theirs is outside (a lenslet's tile
    /// covers the polar square around its disc, whose corner columns
    /// miss it).
    pub fn within(
        grid: Grid,
        nose_radius: f64,
        edge: Option<Arc<EdgeProfile>>,
        frame: &dyn Frame,
    ) -> Sweep {
        let mut sweep = Sweep::with_edge(grid, nose_radius, edge);
        for (j, live) in sweep.live.iter_mut().enumerate() {
            *live = reach_of_rows(&grid, frame, grid.s(j)).is_some();
        }
        sweep
    }

    /// The tool leaves the part: the next point starts a new pass.
    pub fn lift(&mut self) {
        self.last = None;
    }

    /// The next commanded point of the current pass: cutting coordinate
    /// `s` (unwrapped angle for a lathe), step-over coordinate `u`,
    /// height `h` of the nose centre, reached along a straight line.
    pub fn point(&mut self, s: f64, u: f64, h: f64) {
        if let Some((sa, ua, ha)) = self.last.replace((s, u, h))
            && !(ua.max(u) < self.band.0 || ua.min(u) > self.band.1)
        {
            self.segment((sa, ua, ha), (s, u, h), None);
        }
    }

    /// The next point reached along a circular arc in the (s, h) plane
    /// (u constant) about `centre`; the arc is the minor one.
    pub fn arc(&mut self, s: f64, u: f64, h: f64, centre: (f64, f64)) {
        if let Some((sa, ua, ha)) = self.last.replace((s, u, h))
            && !(ua.max(u) < self.band.0 || ua.min(u) > self.band.1)
        {
            self.segment((sa, ua, ha), (s, u, h), Some(centre));
        }
    }

    fn segment(&mut self, a: (f64, f64, f64), b: (f64, f64, f64), arc: Option<(f64, f64)>) {
        let (lo, hi) = (a.0.min(b.0), a.0.max(b.0));
        let g = self.grid;
        // The periods (turns) whose columns the segment may cross.
        let turns = match g.period {
            None => {
                if hi < self.s_range.0 || lo > self.s_range.1 {
                    return;
                }
                (0, 0, 0.0)
            }
            Some(p) => (
                ((lo - g.s(g.ns - 1)) / p).ceil() as i64,
                ((hi - g.s(0)) / p).floor() as i64,
                p,
            ),
        };
        for m in turns.0..=turns.1 {
            // Column indices on the whole grid (this one's from j0 on).
            let base = g.s0 + m as f64 * turns.2;
            let j_lo = ((lo - base) / g.ds).ceil().max(g.j0 as f64) as usize;
            let j_hi = ((hi - base) / g.ds).floor();
            if j_hi < g.j0 as f64 {
                continue;
            }
            let j_hi = (j_hi as usize).min(g.j0 + g.ns - 1);
            for jg in j_lo..=j_hi {
                let (j, s) = (jg - g.j0, base + jg as f64 * g.ds);
                if !self.live[j] {
                    continue;
                }
                let t = if b.0 == a.0 {
                    0.0
                } else {
                    (s - a.0) / (b.0 - a.0)
                };
                let u = a.1 + t * (b.1 - a.1);
                if u < self.band.0 || u > self.band.1 {
                    continue;
                }
                match arc {
                    None => self.columns[j].push((u, a.2 + t * (b.2 - a.2))),
                    Some(o) => {
                        if let Some(h) = minor_arc_height((a.0, a.2), (b.0, b.2), o, s) {
                            self.columns[j].push((u, h));
                        }
                    }
                }
            }
        }
    }

    /// The band of step-over coordinates (u) whose passes reach the rows.
    pub fn band(&self) -> (f64, f64) {
        self.band
    }

    /// The envelope in every column, against the design.
    pub fn finish(self, frame: &dyn Frame) -> HeightMap {
        let (g, r) = (self.grid, self.radius);
        let columns = self.columns(frame);
        let totals = Totals::gather(&g, &columns, frame, &|f| f);
        let mut errors = Vec::with_capacity(g.ns * g.nu);
        for c in &columns {
            errors.extend_from_slice(&c.errors);
        }
        HeightMap::of(g, r, totals, frame, errors)
    }

    /// The envelope in every column against the design, as one tile of a
    /// larger map: its totals (its `frame`'s feature `f` being the whole
    /// map's `feature(f)`) and its cells' errors on `layout`'s blocks.
    /// Its columns are taken one after the other unless `parallel`
    /// (rayon runs the tiles side by side; columns in parallel within
    /// them would let a waiting thread start yet another tile).
    pub(crate) fn finish_tile(
        self,
        frame: &dyn Frame,
        feature: &dyn Fn(usize) -> usize,
        layout: &RasterLayout,
        parallel: bool,
    ) -> TileBlocks {
        let g = self.grid;
        let columns = if parallel {
            self.columns(frame)
        } else {
            let nose = Nose {
                radius: self.radius,
                edge: self.edge.as_deref(),
            };
            self.columns
                .into_iter()
                .enumerate()
                .map(|(j, centres)| column(&g, &nose, j, centres, frame))
                .collect()
        };
        finish_columns(&g, &columns, frame, feature, layout)
    }

    fn columns(self, frame: &dyn Frame) -> Vec<Column> {
        let g = self.grid;
        let nose = Nose {
            radius: self.radius,
            edge: self.edge.as_deref(),
        };
        self.columns
            .into_par_iter()
            .enumerate()
            .map(|(j, centres)| column(&g, &nose, j, centres, frame))
            .collect()
    }
}

/// A tile's columns' totals and their cells' worst errors on `layout`'s
/// blocks.
fn finish_columns(
    g: &Grid,
    columns: &[Column],
    frame: &dyn Frame,
    feature: &dyn Fn(usize) -> usize,
    layout: &RasterLayout,
) -> TileBlocks {
    let totals = Totals::gather(g, columns, frame, feature);
    // Each block's worst, the first of equals in column order (NaN: no
    // cell yet).
    let mut worst = vec![f64::NAN; layout.len()];
    let mut uncut = std::collections::BTreeSet::new();
    for (j, c) in columns.iter().enumerate() {
        for (i, &e) in c.errors.iter().enumerate() {
            if let Some(b) = layout.block(frame, g.s(j), g.u(i), e) {
                let w = &mut worst[b];
                if w.is_nan() || e.abs() > w.abs() {
                    *w = e;
                }
            } else if e.is_nan()
                && c.may_hold(i)
                && uncut_part_cell(frame, g.s(j), g.u(i))
                && let Some(b) = layout.block_of(frame, g.s(j), g.u(i))
            {
                uncut.insert(b);
            }
        }
    }
    (
        totals,
        worst
            .into_iter()
            .enumerate()
            .filter(|(_, e)| !e.is_nan())
            .collect(),
        uncut.into_iter().collect(),
    )
}

/// A tile's totals, its blocks' worst errors and its blocks that hold an
/// uncut cell of the part.
pub(crate) type TileBlocks = (Totals, Vec<(usize, f64)>, Vec<usize>);

/// Whether the cell at (s, u), which no pass cut, is part of the part:
/// in the window and its features (what the totals count as uncut).
fn uncut_part_cell(frame: &dyn Frame, s: f64, u: f64) -> bool {
    let (x, y) = frame.xy(s, u);
    frame.inside(x, y) && in_features(frame.features(), x, y)
}

/// The height on the minor arc from `a` to `b` about `o` at `s` (between
/// them): of the circle's two heights there, the one nearer the chord (a
/// minor arc stays within its sagitta of it; printed centres and ends
/// disagree by the resolution, so no exact side test is safe).
fn minor_arc_height(a: (f64, f64), b: (f64, f64), o: (f64, f64), s: f64) -> Option<f64> {
    let radius = ((a.0 - o.0).hypot(a.1 - o.1) + (b.0 - o.0).hypot(b.1 - o.1)) / 2.0;
    let dh = (radius * radius - (s - o.0) * (s - o.0)).max(0.0).sqrt();
    let chord = if b.0 == a.0 {
        (a.1 + b.1) / 2.0
    } else {
        a.1 + (s - a.0) / (b.0 - a.0) * (b.1 - a.1)
    };
    let (lo, hi) = (o.1 - dh, o.1 + dh);
    let h = if (lo - chord).abs() <= (hi - chord).abs() {
        lo
    } else {
        hi
    };
    h.is_finite().then_some(h)
}

/// One column's result.
struct Column {
    /// Error (cut − design, mm) per row; NaN where no pass reaches or the
    /// cell is outside the window.
    errors: Vec<f64>,
    /// Per pass on the envelope inside the window: where its contact
    /// (least error) is and that error.
    valleys: Vec<(f64, f64)>,
    /// Per cusp between neighbouring passes: where and the scallop height
    /// above the neighbours' contacts.
    cusps: Vec<(f64, f64)>,
    /// The scallops that bound the pieces of the cut, in order of u, for
    /// the scallop each cell is allowed ([`local_scallop`]): every cusp
    /// between two pieces, wherever it lies (beyond the rows, the window,
    /// the axis), its height above the mean of the nearest contacts on
    /// either side of it in the column (of one, where the other side has
    /// none): a rim's last cusp with a pass whose contact lies beyond the
    /// aperture, the cusps beside the axis between passes of the opposite
    /// ray that cut away each other's contacts.
    bounds: Vec<(f64, f64)>,
    /// The rows (from, to) that may hold a cell of the window: those
    /// beyond are outside it (see [`Frame::column_reach`]).
    rows: (usize, usize),
}

impl Column {
    /// Whether row `i` may hold a cell of the window (those that cannot
    /// are uncut and not counted, without asking the frame).
    fn may_hold(&self, i: usize) -> bool {
        i >= self.rows.0 && i < self.rows.1
    }
}

/// The range of u in the column at `s` that may hold a cell of `frame`'s
/// window and features ([`Frame::column_reach`]) within `g`'s rows, or
/// `None` when none can.
fn reach_of_rows(g: &Grid, frame: &dyn Frame, s: f64) -> Option<(f64, f64)> {
    let (lo, hi) = frame
        .column_reach(s, frame.features())
        .unwrap_or((f64::NEG_INFINITY, f64::INFINITY));
    let (lo, hi) = (lo.max(g.u(0)), hi.min(g.u_end()));
    (lo <= hi).then_some((lo, hi))
}

/// The lower envelope of the noses about `centres` (sorted by u,
/// distinct): per piece, the nose's index and where it starts. Circles
/// cross where the closed form says; a measured edge's copies near there
/// (`edge_crossing`).
fn envelope(centres: &[(f64, f64)], nose: &Nose) -> Vec<(usize, f64)> {
    let r = nose.reach();
    let rho = nose.radius;
    let circle = |k: usize, u: f64| {
        let (cu, ch) = centres[k];
        ch - nose.lift(u - cu).map_or(0.0, |l| l.0)
    };
    // Where k (right of j) starts to be lower than j.
    let crossing = |j: usize, k: usize| -> f64 {
        let ((uj, hj), (uk, hk)) = (centres[j], centres[k]);
        let (from, to) = (uk - r, uj + r);
        // A circle is nowhere above its centre: k lower than j's centre
        // is the first test's only chance, higher the second's (the same
        // answers, without the square root that cannot change them).
        if from >= to || (hk <= hj && hk <= circle(j, from)) {
            return from;
        }
        if hk >= hj && circle(k, to) >= hj {
            return to;
        }
        // The lower crossing of two equal circles.
        let (du, dh) = (uk - uj, hk - hj);
        let d = du.hypot(dh);
        let q = (rho * rho - d * d / 4.0).max(0.0).sqrt();
        let u = (uj + uk) / 2.0 + q * dh / d;
        if u > from && u < to {
            if nose.edge.is_none() {
                return u;
            }
            let gap = |x: f64| circle(k, x) - circle(j, x);
            if let Some(x) = edge_crossing(&gap, u, from, to) {
                return x;
            }
        }
        let (mut a, mut b) = (from, to);
        for _ in 0..80 {
            let m = (a + b) / 2.0;
            if circle(k, m) < circle(j, m) {
                b = m;
            } else {
                a = m;
            }
        }
        (a + b) / 2.0
    };
    let mut stack: Vec<(usize, f64)> = Vec::new();
    for (k, &(centre_u, _)) in centres.iter().enumerate() {
        loop {
            match stack.last() {
                None => {
                    stack.push((k, centre_u - r));
                    break;
                }
                Some(&(j, start)) => {
                    let x = crossing(j, k);
                    if x <= start {
                        stack.pop();
                    } else {
                        stack.push((k, x));
                        break;
                    }
                }
            }
        }
    }
    stack
}

/// Where two copies of a measured edge cross, `gap` the height of the
/// later one less the earlier's (it falls through zero there): by the
/// secant method from the circles' crossing `u`, within (`from`, `to`);
/// `None` if it does not settle there (the caller bisects).
fn edge_crossing(gap: &dyn Fn(f64) -> f64, u: f64, from: f64, to: f64) -> Option<f64> {
    let (mut a, mut b) = (u, u + 1e-6);
    let (mut ga, mut gb) = (gap(a), gap(b));
    for _ in 0..30 {
        if gb == 0.0 {
            return Some(b);
        }
        if gb == ga || !gb.is_finite() {
            break;
        }
        let next = b - gb * (b - a) / (gb - ga);
        if !(next > from && next < to) {
            return None;
        }
        (a, ga) = (b, gb);
        (b, gb) = (next, gap(next));
        if (b - a).abs() < 1e-13 {
            return Some(b);
        }
    }
    None
}

fn column(
    g: &Grid,
    nose: &Nose,
    j: usize,
    mut centres: Vec<(f64, f64)>,
    frame: &dyn Frame,
) -> Column {
    // A column none of whose points can be in the window is all outside:
    // no cell, contact or cusp of it counts.
    let Some(reach) = reach_of_rows(g, frame, g.s(j)) else {
        return Column {
            errors: vec![f64::NAN; g.nu],
            valleys: Vec::new(),
            cusps: Vec::new(),
            bounds: Vec::new(),
            rows: (0, 0),
        };
    };
    centres.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    centres.dedup_by(|later, kept| (later.0 - kept.0).abs() < 1e-12);
    let pieces = envelope(&centres, nose);
    let from = (0..g.nu).position(|i| g.u(i) >= reach.0).unwrap_or(g.nu);
    let to = (0..g.nu)
        .rposition(|i| g.u(i) <= reach.1)
        .map_or(0, |i| i + 1);
    let cut = ColumnCut {
        s: g.s(j),
        r: nose.reach(),
        nose: *nose,
        centres,
        pieces,
        frame,
        reach,
        rows: (from, to.max(from)),
    };
    let valleys = cut.valleys(g);
    let (cusps, bounds) = cut.cusps(g, &valleys);
    Column {
        errors: cut.errors(g),
        cusps,
        bounds,
        valleys: valleys.into_iter().filter(|v| !v.1.is_nan()).collect(),
        rows: cut.rows,
    }
}

/// One column's cut: the lower envelope of the tool circles over it,
/// piece `p` being circle `centres[pieces[p].0]` from u = `pieces[p].1`.
struct ColumnCut<'a> {
    /// The column (mm, or rad).
    s: f64,
    /// How far the tool reaches from its centre (mm): its radius, or a
    /// measured edge's farthest point.
    r: f64,
    nose: Nose<'a>,
    centres: Vec<(f64, f64)>,
    pieces: Vec<(usize, f64)>,
    frame: &'a dyn Frame,
    /// The range of u that may be in the window (`reach_of_rows`), and
    /// the rows within it: outside, no point is.
    reach: (f64, f64),
    rows: (usize, usize),
}

impl ColumnCut<'_> {
    /// The height piece `p`'s circle cuts at u (NaN beyond its reach).
    fn height(&self, p: usize, u: f64) -> f64 {
        let (cu, ch) = self.centres[self.pieces[p].0];
        self.nose.lift(u - cu).map_or(f64::NAN, |l| ch - l.0)
    }

    /// Where piece `p` ends: where the next begins.
    fn end(&self, p: usize) -> f64 {
        self.pieces.get(p + 1).map_or(f64::INFINITY, |q| q.1)
    }

    /// Whether (s, u) lies in the window and its features.
    fn in_window(&self, u: f64) -> bool {
        let (x, y) = self.frame.xy(self.s, u);
        self.frame.inside(x, y) && in_features(self.frame.features(), x, y)
    }

    /// The design's height at (s, u).
    #[cfg(test)]
    fn design_at(&self, u: f64) -> f64 {
        let mut dz = [0.0];
        self.frame.design(&[(self.s, u)], &mut dz);
        dz[0]
    }

    /// Cut − design at every row (NaN where no piece reaches or outside
    /// the window).
    fn errors(&self, g: &Grid) -> Vec<f64> {
        let mut cut = vec![f64::NAN; g.nu];
        let mut p = 0;
        for (i, c) in cut
            .iter_mut()
            .enumerate()
            .take(self.rows.1)
            .skip(self.rows.0)
        {
            let u = g.u(i);
            while p < self.pieces.len() && self.end(p) <= u {
                p += 1;
            }
            if p < self.pieces.len() && self.pieces[p].1 <= u && self.in_window(u) {
                *c = self.height(p, u);
            }
        }
        // The design only where the cut is (the window, its lenslets).
        let rows: Vec<usize> = (self.rows.0..self.rows.1)
            .filter(|&i| !cut[i].is_nan())
            .collect();
        let points: Vec<(f64, f64)> = rows.iter().map(|&i| (self.s, g.u(i))).collect();
        let mut design = vec![0.0; rows.len()];
        self.frame.design(&points, &mut design);
        for (&i, d) in rows.iter().zip(&design) {
            cut[i] -= d;
        }
        cut
    }

    /// Contacts: the least error over each piece inside the rows, from
    /// five samples and a parabola through the least and its neighbours;
    /// (NaN, NaN) for a piece with none in the window. The design is
    /// evaluated for every piece of the column at once (the samples, then
    /// the parabolas' vertices): the same points as one piece at a time,
    /// without a call per piece.
    fn valleys(&self, g: &Grid) -> Vec<(f64, f64)> {
        let (s, r) = (self.s, self.r);
        let (u_lo, u_hi) = (g.u0, g.u_end());
        let mut valleys: Vec<(f64, f64)> = vec![(f64::NAN, f64::NAN); self.pieces.len()];
        // Each piece's span within the rows, where it has one and it
        // reaches the window (a contact beyond the reach is outside it). The first
        // and last pieces run on to their circle's end, a nose radius from
        // its centre, where their neighbours' are a feed long; their
        // contacts lie within about a neighbour's length of the cusp, so
        // they are searched within two of it (a contact found at that
        // bound is beyond it, and none): over the whole half circle, the
        // samples lay far apart and the cusp itself, at the span's end,
        // passed for the contact (issue #29: a 27 nm "contact" at the first
        // revolution's cusp under a 10 µm feed and 0.5 mm nose).
        let reach = self.reach;
        let n = self.pieces.len();
        let length = |q: usize| self.end(q) - self.pieces[q].1;
        let spans: Vec<(usize, f64, f64)> = (0..n)
            .filter_map(|q| {
                let (cu, _) = self.centres[self.pieces[q].0];
                let mut a = self.pieces[q].1.max(cu - r).max(u_lo);
                let mut b = self.end(q).min(cu + r).min(u_hi);
                if n > 1 && q + 1 == n {
                    b = b.min(self.pieces[q].1 + 2.0 * length(q - 1));
                }
                if n > 1 && q == 0 {
                    a = a.max(self.end(q) - 2.0 * length(1));
                }
                (b.partial_cmp(&a) == Some(std::cmp::Ordering::Greater)
                    && b >= reach.0
                    && a <= reach.1)
                    .then_some((q, a, b))
            })
            .collect();
        let probes: Vec<(f64, f64)> = spans
            .iter()
            .flat_map(|&(_, a, b)| (0..5).map(move |k| (s, a + (b - a) * k as f64 / 4.0)))
            .collect();
        let mut probe_design = vec![0.0; probes.len()];
        self.frame.design(&probes, &mut probe_design);
        // Per span: its best sample, and the parabola's vertex to try.
        let mut best: Vec<(f64, f64)> = Vec::with_capacity(spans.len());
        let mut vertices: Vec<(usize, (f64, f64))> = Vec::new();
        for (n, &(q, a, b)) in spans.iter().enumerate() {
            let probe = &probes[5 * n..5 * n + 5];
            let e: [f64; 5] =
                std::array::from_fn(|k| self.height(q, probe[k].1) - probe_design[5 * n + k]);
            let m = (1..4).min_by(|&x, &y| e[x].total_cmp(&e[y])).unwrap_or(2);
            let (mut best_u, mut least) = (probe[m].1, e[m]);
            for k in [0, 4] {
                if e[k] < least {
                    (best_u, least) = (probe[k].1, e[k]);
                }
            }
            best.push((best_u, least));
            let h = (b - a) / 4.0;
            let curv = e[m - 1] - 2.0 * e[m] + e[m + 1];
            if curv > 0.0 {
                let t = 0.5 * (e[m - 1] - e[m + 1]) / curv;
                if t.abs() <= 1.0 {
                    vertices.push((n, (s, probe[m].1 + t * h)));
                }
            }
        }
        let points: Vec<(f64, f64)> = vertices.iter().map(|v| v.1).collect();
        let mut vertex_design = vec![0.0; points.len()];
        self.frame.design(&points, &mut vertex_design);
        for (&(n, (_, u)), d) in vertices.iter().zip(&vertex_design) {
            let eu = self.height(spans[n].0, u) - d;
            if eu < best[n].1 {
                best[n] = (u, eu);
            }
        }
        for (&(q, a, b), &(best_u, least)) in spans.iter().zip(&best) {
            let (cu, _) = self.centres[self.pieces[q].0];
            // A piece cut short by the window's edge has its contact outside
            // when its least error is at that edge.
            let clipped = (best_u == a && a > self.pieces[q].1.max(cu - r))
                || (best_u == b && b < self.end(q).min(cu + r));
            // A piece whose least error is where a neighbour's begins has
            // its contact cut away by that neighbour: a sliver between two
            // deeper cuts (the nose on the opposite ray near the axis), its
            // least the cusp, not a contact.
            let at_neighbour = (best_u == a && q > 0 && a == self.pieces[q].1)
                || (best_u == b && q + 1 < n && b == self.end(q));
            if !clipped && !at_neighbour && self.in_window(best_u) {
                valleys[q] = (best_u, least);
            }
        }
        valleys
    }

    /// Cusps between neighbouring pieces whose circles meet there: where
    /// and how high above the mean of the two valleys, those in the rows
    /// and the window between two contacts (the scallops reported); and
    /// every cusp beside a contact, wherever it lies, for the scallop a
    /// cell is allowed ([`Column::bounds`]).
    #[allow(clippy::type_complexity)]
    fn cusps(&self, g: &Grid, valleys: &[(f64, f64)]) -> (Vec<(f64, f64)>, Vec<(f64, f64)>) {
        let (u_lo, u_hi) = (g.u0, g.u_end());
        // Each cusp's height above the mean of its known valleys but for
        // the design's height, and whether it is a scallop reported; the
        // design asked of all at once.
        let mut found: Vec<(f64, f64, bool)> = Vec::new();
        let mut points: Vec<(f64, f64)> = Vec::new();
        let nearest = nearest_contacts(valleys);
        for q in 1..self.pieces.len() {
            let u = self.pieces[q].1;
            let (cu_a, cu_b) = (
                self.centres[self.pieces[q - 1].0].0,
                self.centres[self.pieces[q].0].0,
            );
            if (u - cu_a).abs() > self.r || (u - cu_b).abs() > self.r {
                continue;
            }
            let (va, vb) = (valleys[q - 1].1, valleys[q].1);
            let reported =
                !va.is_nan() && !vb.is_nan() && u >= u_lo && u <= u_hi && self.in_window(u);
            let mean = if reported {
                (va + vb) / 2.0
            } else {
                nearest[q - 1].0.mean_with(nearest[q].1)
            };
            if mean.is_nan() {
                continue;
            }
            found.push((self.height(q, u), mean, reported));
            points.push((self.s, u));
        }
        let mut design = vec![0.0; points.len()];
        self.frame.design(&points, &mut design);
        let (mut cusps, mut bounds) = (Vec::new(), Vec::new());
        for ((&(h, mean, reported), &(_, u)), d) in found.iter().zip(&points).zip(&design) {
            let height = (h - d) - mean;
            if reported {
                cusps.push((u, height));
            }
            if !height.is_nan() {
                bounds.push((u, height));
            }
        }
        (cusps, bounds)
    }
}

/// Per piece of a column (in order of u, each with its contact's error
/// or NaN where it has none), the error at the nearest contact at or
/// before it and at or after it (NaN where there is none).
fn nearest_contacts(valleys: &[(f64, f64)]) -> Vec<(Contact, Contact)> {
    let mut out = vec![(Contact(f64::NAN), Contact(f64::NAN)); valleys.len()];
    let mut last = f64::NAN;
    for (o, v) in out.iter_mut().zip(valleys) {
        if !v.1.is_nan() {
            last = v.1;
        }
        o.0 = Contact(last);
    }
    last = f64::NAN;
    for (o, v) in out.iter_mut().zip(valleys).rev() {
        if !v.1.is_nan() {
            last = v.1;
        }
        o.1 = Contact(last);
    }
    out
}

/// A contact's error (mm), NaN for none.
#[derive(Clone, Copy, Debug)]
struct Contact(f64);

impl Contact {
    /// The mean of this and `other`, or the one that is a contact; NaN if
    /// neither is.
    fn mean_with(self, other: Contact) -> f64 {
        match (self.0.is_nan(), other.0.is_nan()) {
            (false, false) => (self.0 + other.0) / 2.0,
            (false, true) => self.0,
            (true, false) => other.0,
            (true, true) => f64::NAN,
        }
    }
}

fn in_features(features: &[(f64, f64, f64)], x: f64, y: f64) -> bool {
    features.is_empty() || features.iter().any(|&disc| in_disc(disc, x, y))
}

/// Whether (x, y) lies in the disc (centre x, y, radius): by squares, as
/// every cell is asked (a `hypot` took a tenth of a whole array's
/// simulation).
pub(crate) fn in_disc((cx, cy, r): (f64, f64, f64), x: f64, y: f64) -> bool {
    let (dx, dy) = (x - cx, y - cy);
    dx * dx + dy * dy <= r * r
}

/// The figures of a set of errors at (x, y) points (see
/// [`super::figures`]: PV max − min, RMS about the mean, the mean and the
/// largest deviation).
pub type ErrorFigures = super::figures::ErrorFigures<(f64, f64)>;

/// The statistics of errors at (x, y) points, as they are gathered.
type Tally = super::figures::ErrorStats<(f64, f64)>;

/// Scallop heights between neighbouring passes (mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scallops {
    pub count: usize,
    pub max: f64,
    pub mean: f64,
}

/// The figures of one lenslet (a feature disc) in the window.
#[derive(Clone, Debug, PartialEq)]
pub struct FeatureFigures {
    /// Its index among the frame's features.
    pub index: usize,
    pub centre: (f64, f64),
    /// Over every cell of the aperture (scallops included).
    pub surface: Option<ErrorFigures>,
    /// At the passes' contacts (scallops excluded).
    pub contact: Option<ErrorFigures>,
    pub scallops: Option<Scallops>,
    /// As the map's [`HeightMap::beyond_scallops`], over its cells.
    pub beyond_scallops: Option<(f64, (f64, f64))>,
}

/// A height map's error on square blocks of the part's x–y plane (see
/// [`HeightMap::raster`]).
#[derive(Clone, Debug, PartialEq)]
pub struct ErrorRaster {
    /// The plane covered (mm): blocks from `x.0`, `y.0` on, `block` (mm)
    /// wide, `nx` along x and `ny` along y (the last ones may reach past
    /// `x.1`, `y.1`).
    pub x: (f64, f64),
    pub y: (f64, f64),
    pub block: f64,
    pub nx: usize,
    pub ny: usize,
    /// Row by row from `y.0`: the error (mm) of the largest magnitude in
    /// each block; NaN where no cut cell falls.
    pub cells: Vec<f64>,
    /// Row by row as `cells`: the blocks holding a cell of the part (in
    /// the window and its features) that the program leaves uncut — a
    /// plot draws them as uncut, whatever else they hold.
    pub uncut: Vec<bool>,
}

/// The blocks of an [`ErrorRaster`], before any cell is placed in them
/// (see [`HeightMap::raster`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RasterLayout {
    x: (f64, f64),
    y: (f64, f64),
    block: f64,
    nx: usize,
    ny: usize,
}

impl RasterLayout {
    /// Square blocks over `x` × `y` (mm) widened by half of `min_block` on
    /// every side, no smaller than `min_block`, at most `max_side` a side.
    pub fn new(x: (f64, f64), y: (f64, f64), min_block: f64, max_side: usize) -> RasterLayout {
        let half = (min_block / 2.0).max(0.0);
        let (x, y) = ((x.0 - half, x.1 + half), (y.0 - half, y.1 + half));
        let (w, h) = ((x.1 - x.0).max(0.0), (y.1 - y.0).max(0.0));
        let max_side = max_side.max(1);
        let block = (w.max(h) / max_side as f64).max(min_block);
        let count = |extent: f64| {
            if block > 0.0 && block.is_finite() {
                ((extent / block - 1e-9).ceil().max(1.0) as usize).min(max_side)
            } else {
                1
            }
        };
        RasterLayout {
            x,
            y,
            block,
            nx: count(w),
            ny: count(h),
        }
    }

    /// The block (row by row) the cut cell at (s, u) with error `e` falls
    /// in; `None` for an uncut cell or one outside the blocks.
    fn block(&self, frame: &dyn Frame, s: f64, u: f64, e: f64) -> Option<usize> {
        if e.is_nan() {
            return None;
        }
        let (px, py) = frame.xy(s, u);
        let bx = ((px - self.x.0) / self.block).floor();
        let by = ((py - self.y.0) / self.block).floor();
        if !(bx >= 0.0 && by >= 0.0) {
            return None;
        }
        // Cells on the far edges belong to the last blocks.
        let edge = 1e-9 * self.block;
        if px > self.x.1 + edge || py > self.y.1 + edge {
            return None;
        }
        let (bx, by) = (
            (bx as usize).min(self.nx - 1),
            (by as usize).min(self.ny - 1),
        );
        Some(by * self.nx + bx)
    }

    /// The block (row by row) any cell at (s, u) falls in, cut or not.
    fn block_of(&self, frame: &dyn Frame, s: f64, u: f64) -> Option<usize> {
        self.block(frame, s, u, 0.0)
    }

    /// The raster of these blocks holding `cells` (row by row).
    pub fn raster(&self, cells: Vec<f64>) -> ErrorRaster {
        ErrorRaster {
            x: self.x,
            y: self.y,
            block: self.block,
            nx: self.nx,
            ny: self.ny,
            uncut: vec![false; cells.len()],
            cells,
        }
    }

    /// The number of blocks.
    pub fn len(&self) -> usize {
        self.nx * self.ny
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

impl ErrorRaster {
    /// The least and largest error over the blocks, if any holds one.
    pub fn range(&self) -> Option<(f64, f64)> {
        let mut it = self.cells.iter().copied().filter(|e| !e.is_nan());
        let first = it.next()?;
        Some(it.fold((first, first), |(lo, hi), e| (lo.min(e), hi.max(e))))
    }
}

/// What the program cuts on the window.
#[derive(Clone, Debug, PartialEq)]
pub struct HeightMap {
    pub grid: Grid,
    pub nose_radius: f64,
    /// Error (cut − design, mm) per cell, column by column (`ns` columns
    /// of `nu` rows); NaN where uncut or outside the window.
    pub errors: Vec<f64>,
    /// Over every cut cell: the surface as cut, scallops included.
    pub surface: Option<ErrorFigures>,
    /// At the passes' contacts: the path's own form error.
    pub contact: Option<ErrorFigures>,
    pub scallops: Option<Scallops>,
    /// The most material beyond the scallops (mm, negative where every
    /// cell is within them) and where: of every cut cell, its error less
    /// the scallop its own neighbouring passes leave there, the higher of
    /// the two cusps of its column either side of it (beyond a column's
    /// outermost cusp, that one); in a column with no cusp beside a
    /// contact in the judged area (a window's corner), the map's highest
    /// scallop. `None` if no cell was cut.
    pub beyond_scallops: Option<(f64, (f64, f64))>,
    /// Cells in the window that no pass reached.
    pub uncut: usize,
    /// The part's area (mm²) those cells cover, and one of them (x, y),
    /// if any.
    pub uncut_area: f64,
    pub uncut_at: Option<(f64, f64)>,
    /// The area (mm²) of every cell counted, cut or not: the area the
    /// map evaluates.
    pub area: f64,
    /// RMS of the error along each row (the cutting direction) and along
    /// each column (the step-over direction) about its least-squares
    /// quadratic (the form's trend), averaged over rows and columns (mm).
    pub rq_cutting: f64,
    pub rq_stepover: f64,
    pub features: Vec<FeatureFigures>,
    /// Cells evaluated: in the window (and its lenslets, if any), cut or
    /// not.
    pub cells: usize,
    /// The tiles the map was simulated in (1: one grid, whose `errors`
    /// are kept; more: `errors` is empty and only the figures and a
    /// downsampled map are kept).
    pub tiles: usize,
}

/// The RMS roughness of a line of errors: about their least-squares
/// quadratic, so the form error's trend across the window is left out and
/// what remains is the scallops and the chords' ripple.
fn rq(values: impl Iterator<Item = f64>) -> Option<f64> {
    let v: Vec<(f64, f64)> = values
        .enumerate()
        .filter(|(_, e)| !e.is_nan())
        .map(|(i, e)| (i as f64, e))
        .collect();
    if v.len() < 4 {
        return None;
    }
    // Fit on t in [−1, 1] for a well-conditioned system.
    let (t0, t1) = (v[0].0, v[v.len() - 1].0);
    let (mid, half) = ((t0 + t1) / 2.0, ((t1 - t0) / 2.0).max(1.0));
    let mut m = [[0.0; 3]; 3];
    let mut rhs = [0.0; 3];
    for &(i, e) in &v {
        let t = (i - mid) / half;
        let p = [1.0, t, t * t];
        for a in 0..3 {
            rhs[a] += p[a] * e;
            for b in 0..3 {
                m[a][b] += p[a] * p[b];
            }
        }
    }
    let c = solve3(m, rhs)?;
    let sum2: f64 = v
        .iter()
        .map(|&(i, e)| {
            let t = (i - mid) / half;
            let r = e - (c[0] + c[1] * t + c[2] * t * t);
            r * r
        })
        .sum();
    Some((sum2 / v.len() as f64).sqrt())
}

/// Solves a 3 × 3 system by Cramer's rule; None when it is singular.
fn solve3(m: [[f64; 3]; 3], r: [f64; 3]) -> Option<[f64; 3]> {
    let det = |m: &[[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(&m);
    if d.abs() < 1e-300 || !d.is_finite() {
        return None;
    }
    let mut out = [0.0; 3];
    for (k, o) in out.iter_mut().enumerate() {
        let mut mk = m;
        for (row, &rv) in mk.iter_mut().zip(&r) {
            row[k] = rv;
        }
        *o = det(&mk) / d;
    }
    Some(out)
}

/// Scallop heights as they are gathered: how many, the largest, the sum.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct CuspTally {
    count: usize,
    max: f64,
    sum: f64,
}

impl CuspTally {
    fn add(&mut self, h: f64) {
        self.max = if self.count == 0 { h } else { self.max.max(h) };
        self.count += 1;
        self.sum += h;
    }
    fn merge(&mut self, o: &CuspTally) {
        if o.count > 0 {
            self.max = if self.count == 0 {
                o.max
            } else {
                self.max.max(o.max)
            };
            self.count += o.count;
            self.sum += o.sum;
        }
    }
    fn scallops(&self) -> Option<Scallops> {
        (self.count > 0).then(|| Scallops {
            count: self.count,
            max: self.max,
            mean: self.sum / self.count as f64,
        })
    }
}

/// The scallop a cell at `u` is allowed, from its column's bounding
/// cusps ([`Column::bounds`], sorted by u, `next` the first at or beyond
/// `u`): the higher of the nearest cusp on either side of it, the two
/// that bound the piece of the cut it lies on, so the scallop its own
/// neighbouring passes leave there (mm, ≥ 0); beyond a column's outermost
/// cusp (a rim the last pass left to its flank) the one on its inner
/// side; `None` in a column with none (no contact of its in the judged
/// area: a window's corner).
fn local_scallop(cusps: &[(f64, f64)], next: usize) -> Option<f64> {
    let before = next.checked_sub(1).and_then(|k| cusps.get(k));
    let after = cusps.get(next);
    (!cusps.is_empty()).then(|| {
        before
            .into_iter()
            .chain(after)
            .map(|c| c.1)
            .fold(0.0, f64::max)
    })
}

/// The most material beyond the scallops as it is gathered: of every cut
/// cell, its error less the scallop its neighbouring passes leave there
/// ([`local_scallop`]), the largest and where; and of the cells of
/// columns without cusps, the largest error, less the highest scallop
/// once every tile is in ([`BeyondTally::max`]). The first of equals, in
/// column order; tiles merge in theirs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct BeyondTally {
    local: Largest,
    unbounded: Largest,
}

/// The largest of some values and where (the first of equals).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Largest(Option<(f64, (f64, f64))>);

impl Largest {
    fn add(&mut self, e: f64, at: (f64, f64)) {
        if !e.is_nan() && self.0.is_none_or(|(m, _)| e > m) {
            self.0 = Some((e, at));
        }
    }
    fn merge(&mut self, o: &Largest) {
        if let Some((e, at)) = o.0 {
            self.add(e, at);
        }
    }
}

impl BeyondTally {
    /// Counts a cell with error `e` at `at`, allowed the scallop
    /// `scallop` beside it (`None`: its column has none).
    fn add(&mut self, e: f64, scallop: Option<f64>, at: (f64, f64)) {
        match scallop {
            Some(s) => self.local.add(e - s, at),
            None => self.unbounded.add(e, at),
        }
    }
    fn merge(&mut self, o: &BeyondTally) {
        self.local.merge(&o.local);
        self.unbounded.merge(&o.unbounded);
    }
    /// The most material beyond the scallops and where, the cells of
    /// columns without cusps judged against `highest` (the highest
    /// scallop of the map, or of the lenslet; 0 without one).
    fn max(&self, highest: Option<&Scallops>) -> Option<(f64, (f64, f64))> {
        let mut all = self.local;
        if let Some((e, at)) = self.unbounded.0 {
            all.add(e - highest.map_or(0.0, |s| s.max.max(0.0)), at);
        }
        all.0
    }
}

/// One lenslet's statistics as they are gathered: surface, contacts,
/// scallops, the material beyond them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct FeatureTally {
    surface: Tally,
    contact: Tally,
    cusps: CuspTally,
    beyond: BeyondTally,
}

/// A height map's statistics as they are gathered, over a whole window
/// or one tile of it; two over disjoint cells merge into the statistics
/// of both (see [`super::figures`]), so a map cut into tiles totals them
/// exactly. The roughness figures are means of lines (rows, columns), so
/// a tile contributes the lines it holds (a line cut by tiles counts as
/// one per tile).
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Totals {
    surface: Tally,
    contact: Tally,
    cusps: CuspTally,
    beyond: BeyondTally,
    /// By the whole map's feature index.
    features: std::collections::BTreeMap<usize, FeatureTally>,
    uncut: usize,
    uncut_area: f64,
    uncut_at: Option<(f64, f64)>,
    area: f64,
    /// Sums and counts of the lines' RMS roughness.
    rq_cutting: (f64, usize),
    rq_stepover: (f64, usize),
    /// Cells evaluated (in the window and its features, cut or not).
    cells: usize,
}

impl Totals {
    fn gather(
        g: &Grid,
        columns: &[Column],
        frame: &dyn Frame,
        feature: &dyn Fn(usize) -> usize,
    ) -> Totals {
        let features = frame.features();
        let lenslets = frame.lenslets().filter(|_| features.is_empty());
        let which = |x: f64, y: f64| match lenslets {
            Some(l) => l.which(x, y),
            None => features
                .iter()
                .position(|&disc| in_disc(disc, x, y))
                .map(feature),
        };
        let mut t = Totals::default();
        for (j, c) in columns.iter().enumerate() {
            let s = g.s(j);
            // The first of the column's bounding cusps at or beyond the
            // row's u.
            let mut next = 0;
            for (i, &e) in c.errors.iter().enumerate() {
                if e.is_nan() && !c.may_hold(i) {
                    continue;
                }
                let (x, y) = frame.xy(s, g.u(i));
                if e.is_nan() {
                    if frame.inside(x, y) && in_features(features, x, y) {
                        t.uncut += 1;
                        t.cells += 1;
                        let a = frame.cell_area(g, s, g.u(i));
                        t.uncut_area += a;
                        t.area += a;
                        t.uncut_at.get_or_insert((x, y));
                    }
                    continue;
                }
                t.cells += 1;
                t.area += frame.cell_area(g, s, g.u(i));
                t.surface.add(e, (x, y));
                let u = g.u(i);
                while next < c.bounds.len() && c.bounds[next].0 < u {
                    next += 1;
                }
                let scallop = local_scallop(&c.bounds, next);
                t.beyond.add(e, scallop, (x, y));
                if let Some(f) = which(x, y) {
                    let f = t.features.entry(f).or_default();
                    f.surface.add(e, (x, y));
                    f.beyond.add(e, scallop, (x, y));
                }
            }
            for &(u, e) in &c.valleys {
                let (x, y) = frame.xy(s, u);
                t.contact.add(e, (x, y));
                if let Some(f) = which(x, y) {
                    t.features.entry(f).or_default().contact.add(e, (x, y));
                }
            }
            for &(u, h) in &c.cusps {
                t.cusps.add(h);
                let (x, y) = frame.xy(s, u);
                if let Some(f) = which(x, y) {
                    t.features.entry(f).or_default().cusps.add(h);
                }
            }
        }
        let lines = |rq: &mut (f64, usize), v: Option<f64>| {
            if let Some(v) = v {
                rq.0 += v;
                rq.1 += 1;
            }
        };
        for c in columns {
            lines(&mut t.rq_stepover, rq(c.errors.iter().copied()));
        }
        for i in 0..g.nu {
            lines(&mut t.rq_cutting, rq(columns.iter().map(|c| c.errors[i])));
        }
        t
    }

    /// Adds another tile's totals (disjoint cells).
    pub(crate) fn merge(&mut self, o: &Totals) {
        self.surface.merge(&o.surface);
        self.contact.merge(&o.contact);
        self.cusps.merge(&o.cusps);
        self.beyond.merge(&o.beyond);
        for (&k, f) in &o.features {
            let mine = self.features.entry(k).or_default();
            mine.surface.merge(&f.surface);
            mine.contact.merge(&f.contact);
            mine.cusps.merge(&f.cusps);
            mine.beyond.merge(&f.beyond);
        }
        self.uncut += o.uncut;
        self.uncut_area += o.uncut_area;
        self.uncut_at = self.uncut_at.or(o.uncut_at);
        self.area += o.area;
        self.rq_cutting = (
            self.rq_cutting.0 + o.rq_cutting.0,
            self.rq_cutting.1 + o.rq_cutting.1,
        );
        self.rq_stepover = (
            self.rq_stepover.0 + o.rq_stepover.0,
            self.rq_stepover.1 + o.rq_stepover.1,
        );
        self.cells += o.cells;
    }
}

impl HeightMap {
    /// The map of `totals` on `g` (its features, or its lenslets, those
    /// of the whole map's `frame`).
    pub(crate) fn of(g: Grid, r: f64, t: Totals, frame: &dyn Frame, errors: Vec<f64>) -> HeightMap {
        let centre = |k: usize| match (frame.features().get(k), frame.lenslets()) {
            (Some(&(x, y, _)), _) => (x, y),
            (None, Some(l)) if k < l.len() => l.centre(k),
            _ => (f64::NAN, f64::NAN),
        };
        let per_line = |rq: (f64, usize)| {
            if rq.1 == 0 {
                f64::NAN
            } else {
                rq.0 / rq.1 as f64
            }
        };
        HeightMap {
            grid: g,
            nose_radius: r,
            surface: t.surface.figures(),
            contact: t.contact.figures(),
            scallops: t.cusps.scallops(),
            beyond_scallops: t.beyond.max(t.cusps.scallops().as_ref()),
            uncut: t.uncut,
            uncut_area: t.uncut_area,
            uncut_at: t.uncut_at,
            area: t.area,
            rq_cutting: per_line(t.rq_cutting),
            rq_stepover: per_line(t.rq_stepover),
            features: t
                .features
                .iter()
                .filter(|(_, f)| f.surface.count > 0)
                .map(|(&k, f)| FeatureFigures {
                    index: k,
                    centre: centre(k),
                    surface: f.surface.figures(),
                    contact: f.contact.figures(),
                    scallops: f.cusps.scallops(),
                    beyond_scallops: f.beyond.max(f.cusps.scallops().as_ref()),
                })
                .collect(),
            cells: t.cells,
            tiles: 1,
            errors,
        }
    }

    /// The map on an x–y raster over `x` × `y` (mm), for a plot: square
    /// blocks no smaller than `min_block` (mm) and no more than `max_side`
    /// to a side; each block holds, of the cut cells whose (x, y) falls in
    /// it, the error with the largest magnitude (sign kept), so no peak is
    /// lost however many cells a block gathers; NaN where none falls.
    /// `min_block` keeps blocks from being finer than the grid (on a
    /// polar grid, √2 times its spacing puts a cell in every block). The
    /// raster reaches half of `min_block` beyond the window on every side,
    /// so cells on a grid of that spacing fall in the middle of blocks.
    pub fn raster(
        &self,
        frame: &dyn Frame,
        x: (f64, f64),
        y: (f64, f64),
        min_block: f64,
        max_side: usize,
    ) -> ErrorRaster {
        let layout = RasterLayout::new(x, y, min_block, max_side);
        let mut cells = vec![f64::NAN; layout.nx * layout.ny];
        let mut uncut = vec![false; cells.len()];
        let g = &self.grid;
        for j in 0..g.ns {
            let s = g.s(j);
            for i in 0..g.nu {
                let e = self.errors[j * g.nu + i];
                if let Some(b) = layout.block(frame, s, g.u(i), e) {
                    let c = &mut cells[b];
                    if c.is_nan() || e.abs() > c.abs() {
                        *c = e;
                    }
                } else if e.is_nan()
                    && uncut_part_cell(frame, s, g.u(i))
                    && let Some(b) = layout.block_of(frame, s, g.u(i))
                {
                    uncut[b] = true;
                }
            }
        }
        ErrorRaster {
            uncut,
            ..layout.raster(cells)
        }
    }

    /// The scallop a round nose of radius `r` leaves between passes `step`
    /// apart on a flat (mm).
    pub fn flat_scallop(r: f64, step: f64) -> f64 {
        r - (r * r - step * step / 4.0).max(0.0).sqrt()
    }
}

#[cfg(test)]
mod tests;
