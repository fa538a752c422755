//! The window of a height map: the part of the design (x, y in mm) a
//! simulation covers, the grid over it in the coordinates of the cut
//! (Cartesian for a raster, polar for a lathe, angle and axial position
//! for a roller), and the most cells a grid may have. A window given by
//! the job is known before planning, so its grid's size is checked then.

use std::f64::consts::TAU;

use crate::verify::heightmap::Grid;

/// The most cells a window's grid may have (8 bytes each in the map, plus
/// the passes gathered per column).
pub const MAX_CELLS: usize = 4_000_000;
/// The default window: this wide (mm) and this fine (mm).
pub const DEFAULT_SIZE: f64 = 0.2;
pub const DEFAULT_SPACING: f64 = 1e-3;

/// The part of the surface (x, y in the design's coordinates, mm) that is
/// simulated, and the grid spacing (mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Window {
    pub x: (f64, f64),
    pub y: (f64, f64),
    pub spacing: f64,
    /// Given by the job, not a default.
    pub given: bool,
}

/// A grid with more cells than a simulation takes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TooManyCells {
    pub cells: usize,
    pub columns: usize,
    pub rows: usize,
    pub limit: usize,
}

impl std::fmt::Display for TooManyCells {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} cells ({} × {}) exceed the limit of {}",
            self.cells, self.columns, self.rows, self.limit
        )
    }
}

impl std::error::Error for TooManyCells {}

/// `TooManyCells` when `grid` has more than `MAX_CELLS` cells.
pub fn check_cells(grid: &Grid) -> Result<(), TooManyCells> {
    let cells = grid.ns * grid.nu;
    if cells <= MAX_CELLS {
        return Ok(());
    }
    Err(TooManyCells {
        cells,
        columns: grid.ns,
        rows: grid.nu,
        limit: MAX_CELLS,
    })
}

impl Window {
    /// The window a job gives (x and y ranges, mm; its spacing, or the
    /// default one).
    pub fn given(x: (f64, f64), y: (f64, f64), spacing: Option<f64>) -> Window {
        Window {
            x,
            y,
            spacing: spacing.unwrap_or(DEFAULT_SPACING),
            given: true,
        }
    }

    /// The default window about `centre`: `DEFAULT_SIZE` wide at
    /// `DEFAULT_SPACING`, small enough for every grid (a few hundred
    /// thousand cells at most).
    pub fn about(centre: (f64, f64)) -> Window {
        let h = DEFAULT_SIZE / 2.0;
        Window {
            x: (centre.0 - h, centre.0 + h),
            y: (centre.1 - h, centre.1 + h),
            spacing: DEFAULT_SPACING,
            given: false,
        }
    }

    pub fn contains(&self, x: f64, y: f64) -> bool {
        x >= self.x.0 && x <= self.x.1 && y >= self.y.0 && y <= self.y.1
    }

    /// Columns along x (`along_x`) or y, rows across.
    pub fn cartesian(&self, along_x: bool) -> Grid {
        let count = |r: (f64, f64)| ((r.1 - r.0) / self.spacing + 1e-9).floor() as usize + 1;
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
        let near = (
            0.0f64.clamp(self.x.0, self.x.1),
            0.0f64.clamp(self.y.0, self.y.1),
        );
        let r_min = near.0.hypot(near.1);
        let nu = ((r_max - r_min) / self.spacing).floor() as usize + 1;
        if r_min < self.spacing {
            let ns = (TAU * r_max / self.spacing).ceil().max(8.0) as usize;
            return Grid {
                s0: 0.0,
                ds: TAU / ns as f64,
                ns,
                u0: 0.0,
                du: self.spacing,
                nu: (r_max / self.spacing).floor() as usize + 1,
                period: Some(TAU),
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
            ns: ((hi - lo) / ds).ceil() as usize + 1,
            u0: r_min,
            du: self.spacing,
            nu,
            period: Some(TAU),
        }
    }

    /// Columns at spindle angles (design y over the roller radius), rows
    /// along the roller axis (design x).
    pub fn roller(&self, roller_radius: f64) -> Grid {
        let ds = self.spacing / roller_radius;
        let span = ((self.y.1 - self.y.0) / roller_radius).min(TAU - ds);
        Grid {
            s0: self.y.0 / roller_radius,
            ds,
            ns: (span / ds + 1e-9).floor() as usize + 1,
            u0: self.x.0,
            du: self.spacing,
            nu: ((self.x.1 - self.x.0) / self.spacing + 1e-9).floor() as usize + 1,
            period: Some(TAU),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A default window fits every grid wherever it lies, so only a window
    /// the job gives needs checking (before planning).
    #[test]
    fn default_windows_fit_every_grid() {
        for centre in [
            (0.0, 0.0),
            (0.05, 0.0),
            (0.101, 0.0),
            (0.3, 0.2),
            (40.0, 0.0),
        ] {
            let w = Window::about(centre);
            for grid in [
                w.cartesian(true),
                w.cartesian(false),
                w.polar(),
                w.roller(0.05),
                w.roller(100.0),
            ] {
                assert!(check_cells(&grid).is_ok(), "{centre:?}: {grid:?}");
            }
        }
    }

    #[test]
    fn a_fine_window_is_too_large() {
        let w = Window::given((-1.0, 1.0), (-1.0, 1.0), Some(0.5e-3));
        let e = check_cells(&w.cartesian(true)).unwrap_err();
        assert_eq!((e.cells, e.columns, e.rows), (16_008_001, 4001, 4001));
    }
}
