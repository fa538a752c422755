//! Whole-part simulation in tiles: the program's nose path as printed is
//! kept (only the stretches that reach the window) in blocks with their
//! extents, then each tile of the window's grid (`super::window::Tile`) is
//! swept from the blocks that reach it, its envelope taken and its
//! statistics and downsampled map kept, and its memory freed before the
//! next; rayon runs the tiles side by side. The tiles' statistics merge
//! exactly ([`super::figures`]), in the tiles' order, so the figures are
//! the same for any number of threads.

use rayon::prelude::*;

use super::heightmap::{
    BallSweep, Cutter, ErrorRaster, Frame, HeightMap, NosePath, RasterLayout, Sweep, Totals,
};
use super::window::Tile;

/// Steps a block holds: its extent lets a tile skip it whole. Short
/// enough that a spiral's block is a small fraction of a turn (seed 003
/// has about 1,300 points a turn, and its outer lenslets' tiles span
/// about 6 degrees, two dozen of them), so a lenslet's tile skips the
/// blocks whose angles miss it and replays few steps that do (32 bytes of
/// extent a block: 12 MB for seed 003's 11.65 million steps).
const BLOCK: usize = 32;

/// The nose path (s, u, h, as a [`Sweep`] takes it), kept for tiles: the
/// segments that reach the band of u the tiles need, a lift (NaN) where
/// the path leaves it.
#[derive(Debug, Default)]
pub struct Recorder {
    band: (f64, f64),
    steps: Vec<(f64, f64, f64)>,
    /// The arcs' centres, by the index of the step they end at.
    arcs: Vec<(usize, (f64, f64))>,
    /// Per block of `BLOCK` steps, its extent in s and u (with the step
    /// before it, which starts its first segment).
    extents: Vec<[f64; 4]>,
    /// The last point seen, whether kept or not.
    last: Option<(f64, f64, f64)>,
    /// Whether the last point seen is the last one kept.
    last_kept: bool,
}

impl Recorder {
    /// A recorder of the segments that reach `band` (u, mm).
    pub fn new(band: (f64, f64)) -> Recorder {
        Recorder {
            band,
            ..Recorder::default()
        }
    }

    /// The band of u every tile's passes lie in: each tile's rows widened
    /// by the nose's reach.
    pub fn band_of(tiles: &[Tile], nose_radius: f64) -> (f64, f64) {
        tiles
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |b, t| {
                let band = super::heightmap::band(&t.grid, nose_radius);
                (b.0.min(band.0), b.1.max(band.1))
            })
    }

    /// Steps kept (points and lifts).
    pub fn len(&self) -> usize {
        self.steps.len()
    }

    pub fn is_empty(&self) -> bool {
        self.steps.is_empty()
    }

    fn keep(&mut self, step: (f64, f64, f64)) {
        let at = self.steps.len();
        if at.is_multiple_of(BLOCK) {
            let before = at.checked_sub(1).map(|i| self.steps[i]);
            self.extents.push([
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
            ]);
            if let Some(b) = before {
                self.widen(b);
            }
        }
        self.steps.push(step);
        self.widen(step);
    }

    fn widen(&mut self, (s, u, _): (f64, f64, f64)) {
        if s.is_nan() {
            return;
        }
        let e = self.extents.last_mut().expect("a block");
        *e = [e[0].min(s), e[1].max(s), e[2].min(u), e[3].max(u)];
    }

    /// Keeps the segment from the last point to `p` if it reaches the
    /// band; whether it did.
    fn reach(&mut self, p: (f64, f64, f64)) -> bool {
        let Some(a) = self.last.replace(p) else {
            self.last_kept = false;
            return false;
        };
        let reaches = !(a.1.max(p.1) < self.band.0 || a.1.min(p.1) > self.band.1);
        if reaches {
            if !self.last_kept {
                if self.steps.last().is_some_and(|l| !l.0.is_nan()) {
                    self.keep((f64::NAN, f64::NAN, f64::NAN));
                }
                self.keep(a);
            }
            self.keep(p);
        }
        self.last_kept = reaches;
        reaches
    }

    /// Sweeps the blocks that reach `grid`'s band and its columns into
    /// `sweep`: `s_range` the columns' range of s, repeating every
    /// `period` on a lathe's or roller's grid (a block of a spiral, an
    /// unwrapped angle, is swept only if some turn of it crosses them).
    fn replay(
        &self,
        sweep: &mut dyn NosePath,
        band: (f64, f64),
        s_range: Option<(f64, f64)>,
        period: Option<f64>,
    ) {
        for (b, e) in self.extents.iter().enumerate() {
            let misses_s = s_range.is_some_and(|r| misses(r, period, (e[0], e[1])));
            if e[3] < band.0 || e[2] > band.1 || misses_s {
                continue;
            }
            let (from, to) = (b * BLOCK, ((b + 1) * BLOCK).min(self.steps.len()));
            sweep.lift();
            if let Some(&(s, u, h)) = from.checked_sub(1).map(|i| &self.steps[i])
                && !s.is_nan()
            {
                sweep.point(s, u, h);
            }
            let mut arcs = self.arcs.partition_point(|a| a.0 < from);
            for (i, &(s, u, h)) in self.steps[from..to].iter().enumerate() {
                let i = from + i;
                while arcs < self.arcs.len() && self.arcs[arcs].0 < i {
                    arcs += 1;
                }
                if s.is_nan() {
                    sweep.lift();
                } else if arcs < self.arcs.len() && self.arcs[arcs].0 == i {
                    sweep.arc(s, u, h, self.arcs[arcs].1);
                } else {
                    sweep.point(s, u, h);
                }
            }
        }
    }
}

/// Whether the range `(lo, hi)` of s misses the columns' range
/// `(from, to)`, or every copy of it shifted by a whole number of
/// `period`s: no turn m with from + m·period ≤ hi and to + m·period ≥ lo
/// (the turns `Sweep::segment` would visit).
fn misses((from, to): (f64, f64), period: Option<f64>, (lo, hi): (f64, f64)) -> bool {
    match period {
        None => hi < from || lo > to,
        Some(p) => ((lo - to) / p).ceil() > ((hi - from) / p).floor(),
    }
}

impl NosePath for Recorder {
    fn lift(&mut self) {
        self.last = None;
        self.last_kept = false;
    }
    fn point(&mut self, s: f64, u: f64, h: f64) {
        self.reach((s, u, h));
    }
    fn arc(&mut self, s: f64, u: f64, h: f64, centre: (f64, f64)) {
        if self.reach((s, u, h)) {
            self.arcs.push((self.steps.len() - 1, centre));
        }
    }
}

/// A tile's frame: the whole map's, holding only the cells of the tile's
/// lenslet (those no earlier lenslet holds, as the whole map counts them).
struct TileFrame<'a> {
    base: &'a dyn Frame,
    /// The tile's lenslet, if it goes lenslet by lenslet.
    own: Option<Lenslet>,
}

/// A tile's lenslet: its disc (centre x, y, radius), and the earlier
/// lenslets that overlap it.
struct Lenslet {
    disc: [(f64, f64, f64); 1],
    earlier: Vec<(f64, f64, f64)>,
}

impl<'a> TileFrame<'a> {
    fn new(base: &'a dyn Frame, feature: Option<usize>) -> TileFrame<'a> {
        let own = feature.map(|k| {
            let all = base.features();
            let (cx, cy, r) = all[k];
            let earlier = all[..k]
                .iter()
                .filter(|&&(x, y, q)| (x - cx).hypot(y - cy) <= r + q)
                .copied()
                .collect();
            Lenslet {
                disc: [all[k]],
                earlier,
            }
        });
        TileFrame { base, own }
    }
}

impl Frame for TileFrame<'_> {
    fn design(&self, points: &[(f64, f64)], out: &mut [f64]) {
        self.base.design(points, out)
    }
    fn xy(&self, s: f64, u: f64) -> (f64, f64) {
        self.base.xy(s, u)
    }
    fn cell_area(&self, g: &super::heightmap::Grid, s: f64, u: f64) -> f64 {
        self.base.cell_area(g, s, u)
    }
    fn inside(&self, x: f64, y: f64) -> bool {
        self.base.inside(x, y)
            && self.own.as_ref().is_none_or(|own| {
                !own.earlier
                    .iter()
                    .any(|&disc| super::heightmap::in_disc(disc, x, y))
            })
    }
    fn column_reach(&self, s: f64, discs: &[(f64, f64, f64)]) -> Option<(f64, f64)> {
        self.base.column_reach(s, discs)
    }
    fn features(&self) -> &[(f64, f64, f64)] {
        match &self.own {
            Some(own) => &own.disc,
            None => self.base.features(),
        }
    }
    fn lenslets(&self) -> Option<&super::lenslets::Lenslets> {
        self.base.lenslets()
    }
}

/// What a simulation in tiles leaves: the figures of the whole, and its
/// error on the blocks of `layout`.
pub struct TiledMap {
    pub map: HeightMap,
    pub raster: ErrorRaster,
}

/// Simulates `tiles` (of a map whose nominal grid is `grid`) from the
/// path `recorder` kept, with `cutter`, against `frame`'s design, the
/// errors drawn on `layout`'s blocks.
pub fn simulate(
    recorder: &Recorder,
    tiles: &[Tile],
    grid: super::heightmap::Grid,
    cutter: Cutter,
    frame: &dyn Frame,
    layout: RasterLayout,
) -> TiledMap {
    let nose_radius = cutter.radius();
    let results: Vec<super::heightmap::TileBlocks> = tiles
        .par_iter()
        .map(|tile| {
            let g = tile.grid;
            let tile_frame = TileFrame::new(frame, tile.feature);
            let global = |f: usize| tile.feature.unwrap_or(f);
            let parallel = tiles.len() == 1;
            match &cutter {
                Cutter::Nose { radius, edge } => {
                    let mut sweep = Sweep::within(g, *radius, edge.clone(), &tile_frame);
                    let s_range = (g.s(0), g.s(g.ns.saturating_sub(1)));
                    let band = sweep.band();
                    recorder.replay(&mut sweep, band, Some(s_range), g.period);
                    sweep.finish_tile(&tile_frame, &global, &layout, parallel)
                }
                // A ball reaches columns its radius from its centre.
                Cutter::Ball { radius } => {
                    let radius = *radius;
                    let mut sweep = BallSweep::new(g, radius);
                    let s_range = (g.s0 - radius, g.s(g.ns.saturating_sub(1)) + radius);
                    let band = sweep.band();
                    recorder.replay(&mut sweep, band, Some(s_range), None);
                    sweep.finish_tile(&tile_frame, &global, &layout, parallel)
                }
            }
        })
        .collect();
    let mut totals = Totals::default();
    let mut cells = vec![f64::NAN; layout.len()];
    let mut uncut = vec![false; layout.len()];
    for (t, blocks, uncut_blocks) in &results {
        totals.merge(t);
        for &(b, e) in blocks {
            let c = &mut cells[b];
            if c.is_nan() || e.abs() > c.abs() {
                *c = e;
            }
        }
        for &b in uncut_blocks {
            uncut[b] = true;
        }
    }
    let mut map = HeightMap::of(grid, nose_radius, totals, frame, Vec::new());
    map.tiles = tiles.len();
    TiledMap {
        map,
        raster: ErrorRaster {
            uncut,
            ..layout.raster(cells)
        },
    }
}

#[cfg(test)]
mod tests;
