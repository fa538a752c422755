//! The window of a height map: the part of the design (x, y in mm) a
//! simulation covers, the grid over it in the coordinates of the cut
//! (Cartesian for a raster, polar for a lathe, angle and axial position
//! for a roller), the tiles that grid is simulated in (each small enough
//! to hold in memory; a lathe's lenslets one by one), and the most cells a
//! simulation may have. A window given by the job is known before
//! planning, so its size is checked then.

use std::f64::consts::TAU;

use crate::verify::heightmap::Grid;

/// The most cells a simulation may have. Tiles bound its memory, not its
/// time: about 0.1 µs a cell on one core (measured by
/// `compiler/builder/benches/whole_part.rs`), so this is minutes on two.
pub const MAX_CELLS: usize = 2_000_000_000;
/// A tile's most cells (its errors are 8 bytes each; each of its columns
/// also holds every pass within the nose's reach of its rows): a tile is
/// a run of whole columns, so a column's passes, contacts and scallops
/// are all in one tile.
pub const TILE_CELLS: usize = 1 << 20;

/// One tile of a simulation: a run of columns of the window's grid (at
/// most `TILE_CELLS` cells, or one column), and the lenslet (an index
/// into the frame's features) whose cells it holds, if the simulation
/// goes lenslet by lenslet.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tile {
    pub grid: Grid,
    pub feature: Option<usize>,
}

/// `grid` cut into runs of columns of at most `TILE_CELLS` cells.
pub fn split(grid: &Grid, feature: Option<usize>) -> Vec<Tile> {
    split_columns(grid, feature, (TILE_CELLS / grid.nu.max(1)).max(1))
}

/// `grid` cut into runs of at most `most` columns. A grid of more than
/// `MAX_CELLS` cells stays one tile: no simulation takes it
/// ([`check_cells`] refuses it), and its tiles are not worth counting out
/// (a window of kilometres at a micron would be billions of them).
pub fn split_columns(grid: &Grid, feature: Option<usize>, most: usize) -> Vec<Tile> {
    if grid.ns.saturating_mul(grid.nu) > MAX_CELLS {
        return vec![Tile {
            grid: *grid,
            feature,
        }];
    }
    let runs = grid.ns.div_ceil(most.max(1)).max(1);
    (0..runs)
        .map(|c| {
            let (j0, j1) = (c * grid.ns / runs, (c + 1) * grid.ns / runs);
            Tile {
                grid: Grid {
                    j0: grid.j0 + j0,
                    ns: j1 - j0,
                    ..*grid
                },
                feature,
            }
        })
        .collect()
}

/// One more than the most cells a simulation may have: the bound on a
/// grid's count of columns or rows, a grid that many wide being refused
/// whatever its other side ([`check_cells`]).
const OVER: usize = MAX_CELLS + 1;

/// The number of whole grid steps in `steps` (a width over a spacing),
/// at most [`OVER`], and `OVER` for what is not a number. Counts are taken
/// from floating point here and nowhere else: `as usize` alone saturates
/// at `usize::MAX`, and the `+ 1` after it wrapped to 0 (a window from
/// -1e308 mm had no rows and 1.8e19 columns, counted out into 1.8e13
/// tiles: `lensc check` aborted on a petabyte's allocation).
fn steps(steps: f64) -> usize {
    if steps.is_nan() || steps >= OVER as f64 {
        OVER
    } else {
        steps.max(0.0) as usize
    }
}

/// The spacing of a window the job gives without one (mm).
pub const DEFAULT_SPACING: f64 = 1e-3;

/// The spacings a whole part is simulated at by default, finest first
/// (mm): the finest whose tiles hold at most the strategy's budget of
/// cells is taken ([`Window::whole`]).
pub const WHOLE_SPACINGS: [f64; 12] = [
    1e-3, 2e-3, 5e-3, 1e-2, 2e-2, 5e-2, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0,
];

/// The part of the surface (x, y in the design's coordinates, mm) that is
/// simulated, and the grid spacing (mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Window {
    pub x: (f64, f64),
    pub y: (f64, f64),
    pub spacing: f64,
    /// Given by the job, not a default.
    pub given: bool,
    /// It covers the whole of what the job cuts (its extent), not a part
    /// of it.
    pub whole: bool,
}

/// A simulation tiles cannot bound: more cells than lensc takes (its
/// time), or a column longer than a tile holds (its memory).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TooManyCells {
    pub cells: usize,
    pub tiles: usize,
    /// The longest column's rows.
    pub rows: usize,
    /// A grid's side reached the bound its count is taken to ([`steps`]):
    /// `cells` and `rows` are then the least there would be.
    pub at_least: bool,
}

impl TooManyCells {
    /// The most cells, and rows to a column.
    pub const CELLS: usize = MAX_CELLS;
    pub const ROWS: usize = TILE_CELLS;
}

impl std::fmt::Display for TooManyCells {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}{} cells (tiles: {}), columns of {} rows: more than {} cells or {} rows a column",
            if self.at_least { "at least " } else { "" },
            self.cells,
            self.tiles,
            self.rows,
            Self::CELLS,
            Self::ROWS
        )
    }
}

impl std::error::Error for TooManyCells {}

/// `TooManyCells` when `tiles` have more than `MAX_CELLS` cells between
/// them, or a column more than `TILE_CELLS` rows.
pub fn check_cells(tiles: &[Tile]) -> Result<(), TooManyCells> {
    let cells = tiles.iter().fold(0usize, |n, t| {
        n.saturating_add(t.grid.ns.saturating_mul(t.grid.nu))
    });
    let rows = tiles.iter().map(|t| t.grid.nu).max().unwrap_or(0);
    if cells <= MAX_CELLS && rows <= TILE_CELLS {
        return Ok(());
    }
    Err(TooManyCells {
        cells,
        tiles: tiles.len(),
        rows,
        at_least: tiles.iter().any(|t| t.grid.ns.max(t.grid.nu) >= OVER),
    })
}

impl Window {
    /// The window a job gives (x and y ranges, mm; its spacing, or the
    /// default one), within the `extent` of what the job cuts: whole when
    /// its ranges hold that extent.
    pub fn given(
        x: (f64, f64),
        y: (f64, f64),
        spacing: Option<f64>,
        extent: ((f64, f64), (f64, f64)),
    ) -> Window {
        let holds = |r: (f64, f64), e: (f64, f64)| r.0 <= e.0 && r.1 >= e.1;
        Window {
            x,
            y,
            spacing: spacing.unwrap_or(DEFAULT_SPACING),
            given: true,
            whole: holds(x, extent.0) && holds(y, extent.1),
        }
    }

    /// The default window: the whole `extent` of what the job cuts, at the
    /// finest of [`WHOLE_SPACINGS`] whose `tiles` hold at most `budget`
    /// cells between them (the coarsest if none does).
    pub fn whole(
        extent: ((f64, f64), (f64, f64)),
        budget: usize,
        tiles: impl Fn(&Window) -> Vec<Tile>,
    ) -> Window {
        let at = |spacing: f64| Window {
            x: extent.0,
            y: extent.1,
            spacing,
            given: false,
            whole: true,
        };
        let cells = |w: &Window| {
            tiles(w).iter().fold(0usize, |n, t| {
                n.saturating_add(t.grid.ns.saturating_mul(t.grid.nu))
            })
        };
        WHOLE_SPACINGS
            .iter()
            .map(|&s| at(s))
            .find(|w| cells(w) <= budget)
            .unwrap_or_else(|| at(WHOLE_SPACINGS[WHOLE_SPACINGS.len() - 1]))
    }

    /// The tiles of a lathe's polar grid: lenslet by lenslet when the
    /// window reaches more than one of the `features` (discs: centre x, y,
    /// radius), each over the part of the window its square covers, with
    /// its index among `features`; else the window's whole grid.
    pub fn polar_tiles(&self, features: &[(f64, f64, f64)]) -> Vec<Tile> {
        let squares: Vec<(usize, Window)> = features
            .iter()
            .map(|&(cx, cy, r)| Window {
                x: (self.x.0.max(cx - r), self.x.1.min(cx + r)),
                y: (self.y.0.max(cy - r), self.y.1.min(cy + r)),
                ..*self
            })
            .enumerate()
            .filter(|(_, w)| w.x.1 >= w.x.0 && w.y.1 >= w.y.0)
            .collect();
        if squares.len() < 2 {
            return split(&self.polar(), None);
        }
        let grids: Vec<(usize, Grid)> = squares.iter().map(|&(k, w)| (k, w.polar())).collect();
        let cells = grids.iter().fold(0usize, |n, (_, g)| {
            n.saturating_add(g.ns.saturating_mul(g.nu))
        });
        if cells > MAX_CELLS {
            // Refused whole (`check_cells`): not worth counting out.
            return grids
                .iter()
                .map(|&(k, grid)| Tile {
                    grid,
                    feature: Some(k),
                })
                .collect();
        }
        grids
            .iter()
            .flat_map(|&(k, grid)| split(&grid, Some(k)))
            .collect()
    }

    pub fn contains(&self, x: f64, y: f64) -> bool {
        x >= self.x.0 && x <= self.x.1 && y >= self.y.0 && y <= self.y.1
    }

    /// Columns along x (`along_x`) or y, rows across.
    pub fn cartesian(&self, along_x: bool) -> Grid {
        let count = |r: (f64, f64)| steps(((r.1 - r.0) / self.spacing + 1e-9).floor()) + 1;
        let (s, u) = if along_x {
            (self.x, self.y)
        } else {
            (self.y, self.x)
        };
        Grid {
            s0: s.0,
            ds: self.spacing,
            ns: count(s),
            u0: u.0,
            du: self.spacing,
            nu: count(u),
            period: None,
            j0: 0,
            i0: 0,
        }
    }

    /// Columns at spindle angles, rows at radii, covering the window; the
    /// whole turn when it holds the axis.
    pub fn polar(&self) -> Grid {
        let corners = [
            (self.x.0, self.y.0),
            (self.x.1, self.y.0),
            (self.x.1, self.y.1),
            (self.x.0, self.y.1),
        ];
        let r_max = corners.iter().map(|c| c.0.hypot(c.1)).fold(0.0, f64::max);
        // `clamp` would panic on a range that is not a number.
        let near = (
            0.0f64.max(self.x.0).min(self.x.1),
            0.0f64.max(self.y.0).min(self.y.1),
        );
        let r_min = near.0.hypot(near.1);
        let nu = steps(((r_max - r_min) / self.spacing).floor()) + 1;
        if r_min < self.spacing {
            let ns = steps((TAU * r_max / self.spacing).ceil().max(8.0));
            return Grid {
                s0: 0.0,
                ds: TAU / ns as f64,
                ns,
                u0: 0.0,
                du: self.spacing,
                nu: steps((r_max / self.spacing).floor()) + 1,
                period: Some(TAU),
                j0: 0,
                i0: 0,
            };
        }
        let mid = ((self.y.0 + self.y.1) / 2.0).atan2((self.x.0 + self.x.1) / 2.0);
        let relative = |c: &(f64, f64)| {
            let a = c.1.atan2(c.0) - mid;
            a - TAU * (a / TAU).round()
        };
        let lo = corners.iter().map(relative).fold(f64::INFINITY, f64::min);
        let hi = corners
            .iter()
            .map(relative)
            .fold(f64::NEG_INFINITY, f64::max);
        let ds = self.spacing / r_max;
        Grid {
            s0: mid + lo,
            ds,
            ns: steps(((hi - lo) / ds).ceil()) + 1,
            u0: r_min,
            du: self.spacing,
            nu,
            period: Some(TAU),
            j0: 0,
            i0: 0,
        }
    }

    /// Columns at spindle angles (design y less `y_start`, the design y
    /// at angle 0, over the roller radius), rows along the roller axis
    /// (design x).
    pub fn roller(&self, roller_radius: f64, y_start: f64) -> Grid {
        let ds = self.spacing / roller_radius;
        let span = ((self.y.1 - self.y.0) / roller_radius).min(TAU - ds);
        Grid {
            s0: (self.y.0 - y_start) / roller_radius,
            ds,
            ns: steps((span / ds + 1e-9).floor()) + 1,
            u0: self.x.0,
            du: self.spacing,
            nu: steps(((self.x.1 - self.x.0) / self.spacing + 1e-9).floor()) + 1,
            period: Some(TAU),
            j0: 0,
            i0: 0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A window of 100 km at the default micron (a fuzzed job's) is one
    /// tile that `check_cells` refuses at once: counted out, its columns
    /// were tiles enough to hang `lensc check` (26 s, 2.7 GB) or abort it
    /// on a petabyte's allocation.
    #[test]
    fn a_window_beyond_any_simulation_is_refused_without_counting_its_tiles() {
        let w = Window::given((0.35, 1e5), (-0.05, 0.05), None, ((-1.0, 1.0), (-1.0, 1.0)));
        let tiles = w.polar_tiles(&[]);
        assert_eq!(tiles.len(), 1);
        let e = check_cells(&tiles).unwrap_err();
        assert!(e.cells > MAX_CELLS, "{e}");
        let tiles = split(&w.cartesian(true), None);
        assert_eq!(tiles.len(), 1);
        assert!(check_cells(&tiles).is_err());
    }

    /// The default window is the whole extent, at the finest spacing
    /// whose tiles stay within the budget: a 4 mm square at 2 µm is 4
    /// million cells, at 5 µm 641 601; a budget no spacing meets takes the
    /// coarsest.
    /// A window from -1e308 mm (a fuzzed job's, issue #33): its counts
    /// overflowed `usize` (`as usize` saturates, the `+ 1` wrapped to 0),
    /// a grid of no rows passed as small and was counted out into 1.8e13
    /// tiles, aborting `lensc check` on a petabyte's allocation. Every
    /// count is bounded, the grid stays one tile and is refused; a window
    /// of infinite extent likewise.
    #[test]
    fn a_window_of_1e308_mm_is_one_tile_refused() {
        let extent = ((-0.4, 0.4), (-0.4, 0.4));
        for x in [(-1e308, 1e5), (f64::NEG_INFINITY, 1e5)] {
            let w = Window::given(x, (-0.05, -0.0), None, extent);
            for tiles in [
                w.polar_tiles(&[]),
                split(&w.cartesian(true), None),
                split(&w.roller(5.0, 0.0), None),
            ] {
                assert_eq!(tiles.len(), 1, "{x:?}");
                assert!(tiles[0].grid.nu >= 1 && tiles[0].grid.ns >= 1, "{x:?}");
                let e = check_cells(&tiles).unwrap_err();
                assert!(e.cells > MAX_CELLS && e.at_least, "{x:?}: {e}");
            }
        }
        // Lenslet by lenslet, squares whose cells between them are too
        // many stay one tile each.
        let w = Window::given((-1e5, 1e5), (-1e5, 1e5), None, extent);
        let tiles = w.polar_tiles(&[(-5e4, 0.0, 4e4), (5e4, 0.0, 4e4)]);
        assert_eq!(tiles.len(), 2);
        assert!(check_cells(&tiles).is_err());
    }

    #[test]
    fn the_default_window_is_the_whole_part_within_its_budget() {
        let extent = ((-2.0, 2.0), (-2.0, 2.0));
        let tiles = |w: &Window| split(&w.cartesian(true), None);
        let w = Window::whole(extent, 1_000_000, tiles);
        assert_eq!((w.x, w.y, w.spacing), (extent.0, extent.1, 5e-3));
        assert!(w.whole && !w.given);
        let cells: usize = tiles(&w).iter().map(|t| t.grid.ns * t.grid.nu).sum();
        assert_eq!(cells, 801 * 801);
        assert!(check_cells(&tiles(&w)).is_ok());
        assert_eq!(Window::whole(extent, 5_000_000, tiles).spacing, 2e-3);
        assert_eq!(Window::whole(extent, 1, tiles).spacing, 5.0);
        // A job's window is whole only when it holds the extent.
        assert!(Window::given((-3.0, 3.0), (-2.0, 2.0), None, extent).whole);
        assert!(!Window::given((-1.0, 3.0), (-2.0, 2.0), None, extent).whole);
    }

    #[test]
    fn a_fine_window_is_too_large() {
        let w = Window::given(
            (-1.0, 1.0),
            (-1.0, 1.0),
            Some(20e-6),
            ((-1.0, 1.0), (-1.0, 1.0)),
        );
        let tiles = split(&w.cartesian(true), None);
        let e = check_cells(&tiles).unwrap_err();
        // Beyond the most cells, the grid stays one tile.
        assert_eq!((e.cells, e.tiles), (100_001 * 100_001, 1));
    }

    /// Tiles cover their grid's cells once each, at the grid's own places.
    #[test]
    fn tiles_cover_the_grid_once() {
        let w = Window::given((0.0, 5.0), (0.0, 3.0), Some(1e-3), ((0.0, 5.0), (0.0, 3.0)));
        let g = w.cartesian(true);
        let tiles = split(&g, None);
        // 5001 columns of 3001 rows, 349 to a tile.
        assert_eq!(tiles.len(), 15);
        let cells: usize = tiles.iter().map(|t| t.grid.ns * t.grid.nu).sum();
        assert_eq!(cells, g.ns * g.nu);
        for t in &tiles {
            assert!(t.grid.ns * t.grid.nu <= TILE_CELLS && t.grid.nu == g.nu);
            assert_eq!(t.grid.s(t.grid.ns - 1), g.s(t.grid.j0 + t.grid.ns - 1));
            assert_eq!(t.grid.u(0), g.u(t.grid.i0));
        }
    }

    /// A lathe with lenslets goes lenslet by lenslet, over the lenslets
    /// that reach into the window only.
    #[test]
    fn a_lathe_goes_lenslet_by_lenslet() {
        let features = [(0.0, 2.0, 0.5), (2.0, 0.0, 0.5), (-2.0, 0.0, 0.5)];
        let w = Window::given(
            (-3.0, 3.0),
            (-1.0, 1.0),
            Some(5e-3),
            ((-3.0, 3.0), (-3.0, 3.0)),
        );
        let tiles = w.polar_tiles(&features);
        let owners: Vec<Option<usize>> = tiles.iter().map(|t| t.feature).collect();
        // Each by its index among the lenslets, the one outside skipped.
        assert_eq!(owners, [Some(1), Some(2)]);
        // One lenslet in the window: the window's own grid.
        let one = Window::given(
            (1.0, 3.0),
            (-1.0, 1.0),
            Some(5e-3),
            ((-3.0, 3.0), (-3.0, 3.0)),
        );
        assert_eq!(one.polar_tiles(&features), split(&one.polar(), None));
        // Each covers its lenslet's square: radii 1.5 .. 2.55 mm.
        let g = tiles[0].grid;
        assert!((g.u0 - 1.5).abs() < 1e-12 && g.u(g.nu - 1) > 2.5, "{g:?}");
    }
}
