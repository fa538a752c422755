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
//! The grid's columns are positions along the cut and its rows positions
//! across; on a lathe they are angles and radii (a polar grid), masked to
//! the window the user asked for.

use rayon::prelude::*;

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
}

impl Grid {
    pub fn s(&self, j: usize) -> f64 {
        self.s0 + j as f64 * self.ds
    }
    pub fn u(&self, i: usize) -> f64 {
        self.u0 + i as f64 * self.du
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
}

/// Tool-centre positions gathered column by column as the path streams.
pub struct Sweep {
    grid: Grid,
    radius: f64,
    /// The band of u whose circles can reach the rows.
    band: (f64, f64),
    /// Per column, the (u, h) of every pass crossing it.
    columns: Vec<Vec<(f64, f64)>>,
    /// The previous point of the current pass.
    last: Option<(f64, f64, f64)>,
    /// Columns' range of s (non-periodic), for a quick reject.
    s_range: (f64, f64),
}

impl Sweep {
    pub fn new(grid: Grid, nose_radius: f64) -> Sweep {
        let margin = nose_radius + grid.du;
        Sweep {
            grid,
            radius: nose_radius,
            band: (grid.u0 - margin, grid.u_end() + margin),
            columns: vec![Vec::new(); grid.ns],
            last: None,
            s_range: (grid.s0, grid.s(grid.ns.saturating_sub(1))),
        }
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
        let bases: Vec<f64> = match g.period {
            None => {
                if hi < self.s_range.0 || lo > self.s_range.1 {
                    return;
                }
                vec![g.s0]
            }
            Some(p) => {
                let m0 = ((lo - g.s(g.ns - 1)) / p).ceil() as i64;
                let m1 = ((hi - g.s0) / p).floor() as i64;
                (m0..=m1).map(|m| g.s0 + m as f64 * p).collect()
            }
        };
        for base in bases {
            let j_lo = ((lo - base) / g.ds).ceil().max(0.0) as usize;
            let j_hi = ((hi - base) / g.ds).floor();
            if j_hi < 0.0 {
                continue;
            }
            let j_hi = (j_hi as usize).min(g.ns - 1);
            for j in j_lo..=j_hi {
                let s = base + j as f64 * g.ds;
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

    /// The envelope in every column, against the design.
    pub fn finish(self, frame: &dyn Frame) -> HeightMap {
        let g = self.grid;
        let r = self.radius;
        let columns: Vec<Column> = self
            .columns
            .into_par_iter()
            .enumerate()
            .map(|(j, centres)| column(&g, r, j, centres, frame))
            .collect();
        HeightMap::gather(g, r, columns, frame)
    }
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
}

/// The lower envelope of the circles of radius `r` about `centres` (sorted
/// by u, distinct): per piece, the circle's index and where it starts.
fn envelope(centres: &[(f64, f64)], r: f64) -> Vec<(usize, f64)> {
    let circle = |k: usize, u: f64| {
        let (cu, ch) = centres[k];
        ch - (r * r - (u - cu) * (u - cu)).max(0.0).sqrt()
    };
    // Where k (right of j) starts to be lower than j.
    let crossing = |j: usize, k: usize| -> f64 {
        let ((uj, hj), (uk, hk)) = (centres[j], centres[k]);
        let (from, to) = (uk - r, uj + r);
        if from >= to || hk <= circle(j, from) {
            return from;
        }
        if circle(k, to) >= hj {
            return to;
        }
        // The lower crossing of two equal circles.
        let (du, dh) = (uk - uj, hk - hj);
        let d = du.hypot(dh);
        let q = (r * r - d * d / 4.0).max(0.0).sqrt();
        let u = (uj + uk) / 2.0 + q * dh / d;
        if u > from && u < to {
            return u;
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

fn column(g: &Grid, r: f64, j: usize, mut centres: Vec<(f64, f64)>, frame: &dyn Frame) -> Column {
    centres.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    centres.dedup_by(|later, kept| (later.0 - kept.0).abs() < 1e-12);
    let pieces = envelope(&centres, r);
    let cut = ColumnCut {
        s: g.s(j),
        r,
        centres,
        pieces,
        frame,
    };
    let valleys = cut.valleys(g);
    Column {
        errors: cut.errors(g),
        cusps: cut.cusps(g, &valleys),
        valleys: valleys.into_iter().filter(|v| !v.1.is_nan()).collect(),
    }
}

/// One column's cut: the lower envelope of the tool circles over it,
/// piece `p` being circle `centres[pieces[p].0]` from u = `pieces[p].1`.
struct ColumnCut<'a> {
    /// The column (mm, or rad).
    s: f64,
    /// The tool radius (mm).
    r: f64,
    centres: Vec<(f64, f64)>,
    pieces: Vec<(usize, f64)>,
    frame: &'a dyn Frame,
}

impl ColumnCut<'_> {
    /// The height piece `p`'s circle cuts at u (NaN beyond its reach).
    fn height(&self, p: usize, u: f64) -> f64 {
        let (cu, ch) = self.centres[self.pieces[p].0];
        let d = u - cu;
        if d.abs() > self.r {
            f64::NAN
        } else {
            ch - (self.r * self.r - d * d).sqrt()
        }
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
        for (i, c) in cut.iter_mut().enumerate() {
            let u = g.u(i);
            while p < self.pieces.len() && self.end(p) <= u {
                p += 1;
            }
            if p < self.pieces.len() && self.pieces[p].1 <= u && self.in_window(u) {
                *c = self.height(p, u);
            }
        }
        let points: Vec<(f64, f64)> = (0..g.nu).map(|i| (self.s, g.u(i))).collect();
        let mut design = vec![0.0; g.nu];
        self.frame.design(&points, &mut design);
        cut.iter().zip(&design).map(|(c, d)| c - d).collect()
    }

    /// Contacts: the least error over each piece inside the rows, from
    /// five samples and a parabola through the least and its neighbours;
    /// (NaN, NaN) for a piece with none in the window.
    fn valleys(&self, g: &Grid) -> Vec<(f64, f64)> {
        let (s, r) = (self.s, self.r);
        let (u_lo, u_hi) = (g.u0, g.u_end());
        let mut valleys: Vec<(f64, f64)> = vec![(f64::NAN, f64::NAN); self.pieces.len()];
        let mut probe = Vec::with_capacity(6);
        let mut probe_design = [0.0; 6];
        for (q, v) in valleys.iter_mut().enumerate() {
            let (cu, _) = self.centres[self.pieces[q].0];
            let a = self.pieces[q].1.max(cu - r).max(u_lo);
            let b = self.end(q).min(cu + r).min(u_hi);
            if b.partial_cmp(&a) != Some(std::cmp::Ordering::Greater) {
                continue;
            }
            probe.clear();
            probe.extend((0..5).map(|k| (s, a + (b - a) * k as f64 / 4.0)));
            self.frame.design(&probe, &mut probe_design[..5]);
            let e: Vec<f64> = (0..5)
                .map(|k| self.height(q, probe[k].1) - probe_design[k])
                .collect();
            let m = (1..4).min_by(|&x, &y| e[x].total_cmp(&e[y])).unwrap_or(2);
            let (mut best_u, mut best) = (probe[m].1, e[m]);
            for k in [0, 4] {
                if e[k] < best {
                    (best_u, best) = (probe[k].1, e[k]);
                }
            }
            let h = (b - a) / 4.0;
            let curv = e[m - 1] - 2.0 * e[m] + e[m + 1];
            if curv > 0.0 {
                let t = 0.5 * (e[m - 1] - e[m + 1]) / curv;
                if t.abs() <= 1.0 {
                    let u = probe[m].1 + t * h;
                    let eu = self.height(q, u) - self.design_at(u);
                    if eu < best {
                        (best_u, best) = (u, eu);
                    }
                }
            }
            // A piece cut short by the window's edge has its contact outside
            // when its least error is at that edge.
            let clipped = (best_u == a && a > self.pieces[q].1.max(cu - r))
                || (best_u == b && b < self.end(q).min(cu + r));
            if !clipped && self.in_window(best_u) {
                *v = (best_u, best);
            }
        }
        valleys
    }

    /// Cusps between neighbouring pieces whose circles meet there: where
    /// and how high above the mean of the two valleys.
    fn cusps(&self, g: &Grid, valleys: &[(f64, f64)]) -> Vec<(f64, f64)> {
        let (u_lo, u_hi) = (g.u0, g.u_end());
        let mut cusps = Vec::new();
        for q in 1..self.pieces.len() {
            let u = self.pieces[q].1;
            let (cu_a, cu_b) = (
                self.centres[self.pieces[q - 1].0].0,
                self.centres[self.pieces[q].0].0,
            );
            if u < u_lo || u > u_hi || (u - cu_a).abs() > self.r || (u - cu_b).abs() > self.r {
                continue;
            }
            let (va, vb) = (valleys[q - 1].1, valleys[q].1);
            if va.is_nan() || vb.is_nan() {
                continue;
            }
            if !self.in_window(u) {
                continue;
            }
            let e = self.height(q, u) - self.design_at(u);
            cusps.push((u, e - (va + vb) / 2.0));
        }
        cusps
    }
}

/// The part's area (mm²) of the grid cell at (s, u): the parallelogram
/// its two steps span on the part.
fn cell_area(frame: &dyn Frame, g: &Grid, s: f64, u: f64) -> f64 {
    let (x0, y0) = frame.xy(s, u);
    let (x1, y1) = frame.xy(s + g.ds, u);
    let (x2, y2) = frame.xy(s, u + g.du);
    ((x1 - x0) * (y2 - y0) - (y1 - y0) * (x2 - x0)).abs()
}

fn in_features(features: &[(f64, f64, f64)], x: f64, y: f64) -> bool {
    features.is_empty()
        || features
            .iter()
            .any(|&(cx, cy, r)| (x - cx).hypot(y - cy) <= r)
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
    pub centre: (f64, f64),
    /// Over every cell of the aperture (scallops included).
    pub surface: Option<ErrorFigures>,
    /// At the passes' contacts (scallops excluded).
    pub contact: Option<ErrorFigures>,
    pub scallops: Option<Scallops>,
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

fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (mut n, mut sum) = (0usize, 0.0);
    for v in values {
        n += 1;
        sum += v;
    }
    if n == 0 { f64::NAN } else { sum / n as f64 }
}

impl HeightMap {
    fn gather(g: Grid, r: f64, columns: Vec<Column>, frame: &dyn Frame) -> HeightMap {
        let features = frame.features();
        let which = |x: f64, y: f64| {
            features
                .iter()
                .position(|&(cx, cy, fr)| (x - cx).hypot(y - cy) <= fr)
        };
        let mut surface = Tally::new();
        let mut contact = Tally::new();
        let mut per: Vec<(Tally, Tally, Vec<f64>)> = features
            .iter()
            .map(|_| (Tally::new(), Tally::new(), Vec::new()))
            .collect();
        let mut all_cusps = Vec::new();
        let mut uncut = 0;
        let (mut uncut_area, mut uncut_at, mut area) = (0.0, None, 0.0);
        let mut errors = Vec::with_capacity(g.ns * g.nu);
        for (j, c) in columns.iter().enumerate() {
            let s = g.s(j);
            for (i, &e) in c.errors.iter().enumerate() {
                let (x, y) = frame.xy(s, g.u(i));
                if e.is_nan() {
                    if frame.inside(x, y) && in_features(features, x, y) {
                        uncut += 1;
                        let a = cell_area(frame, &g, s, g.u(i));
                        uncut_area += a;
                        area += a;
                        uncut_at.get_or_insert((x, y));
                    }
                    continue;
                }
                area += cell_area(frame, &g, s, g.u(i));
                surface.add(e, (x, y));
                if let Some(f) = which(x, y) {
                    per[f].0.add(e, (x, y));
                }
            }
            for &(u, e) in &c.valleys {
                let (x, y) = frame.xy(s, u);
                contact.add(e, (x, y));
                if let Some(f) = which(x, y) {
                    per[f].1.add(e, (x, y));
                }
            }
            for &(u, h) in &c.cusps {
                all_cusps.push(h);
                let (x, y) = frame.xy(s, u);
                if let Some(f) = which(x, y) {
                    per[f].2.push(h);
                }
            }
            errors.extend_from_slice(&c.errors);
        }
        let scallops = |h: &[f64]| {
            (!h.is_empty()).then(|| Scallops {
                count: h.len(),
                max: h.iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b)),
                mean: mean(h.iter().copied()),
            })
        };
        let rq_stepover = mean(columns.iter().filter_map(|c| rq(c.errors.iter().copied())));
        let rq_cutting = mean((0..g.nu).filter_map(|i| rq(columns.iter().map(|c| c.errors[i]))));
        HeightMap {
            grid: g,
            nose_radius: r,
            surface: surface.figures(),
            contact: contact.figures(),
            scallops: scallops(&all_cusps),
            uncut,
            uncut_area,
            uncut_at,
            area,
            rq_cutting,
            rq_stepover,
            features: features
                .iter()
                .zip(&per)
                .filter(|(_, t)| t.0.count > 0)
                .map(|(&(cx, cy, _), t)| FeatureFigures {
                    centre: (cx, cy),
                    surface: t.0.figures(),
                    contact: t.1.figures(),
                    scallops: scallops(&t.2),
                })
                .collect(),
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
        let (nx, ny) = (count(w), count(h));
        let mut cells = vec![f64::NAN; nx * ny];
        let g = &self.grid;
        for j in 0..g.ns {
            let s = g.s(j);
            for i in 0..g.nu {
                let e = self.errors[j * g.nu + i];
                if e.is_nan() {
                    continue;
                }
                let (px, py) = frame.xy(s, g.u(i));
                let bx = ((px - x.0) / block).floor();
                let by = ((py - y.0) / block).floor();
                if !(bx >= 0.0 && by >= 0.0) {
                    continue;
                }
                // Cells on the far edges belong to the last blocks.
                let edge = 1e-9 * block;
                if px > x.1 + edge || py > y.1 + edge {
                    continue;
                }
                let (bx, by) = ((bx as usize).min(nx - 1), (by as usize).min(ny - 1));
                let c = &mut cells[by * nx + bx];
                if c.is_nan() || e.abs() > c.abs() {
                    *c = e;
                }
            }
        }
        ErrorRaster {
            x,
            y,
            block,
            nx,
            ny,
            cells,
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
