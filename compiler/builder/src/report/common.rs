//! The small typed pieces of the build report that more than one section
//! shares (a value where it occurs, the optimisation's summary) and the
//! unit changes they make; every strategy's report section is built from
//! them.

use lensc_runtime::plan::optimise::Summary;
use lensc_runtime::surface::analysis::Extremum;
use schemars::JsonSchema;
use serde::Serialize;

/// A value and the radius (mm) where it occurs.
#[derive(Clone, Copy, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct AtRadius {
    /// The value, in the unit the enclosing field's name gives.
    pub value: f64,
    /// Radius (mm) where it occurs.
    pub at_radius_mm: f64,
}

/// A value and the x (mm) of a profile where it occurs.
#[derive(Clone, Copy, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct AtX {
    /// The value, in the unit the enclosing field's name gives.
    pub value: f64,
    /// x (mm) where it occurs.
    pub at_x_mm: f64,
}

/// A value and the point (x, y in mm) of the surface where it occurs.
#[derive(Clone, Copy, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct AtPoint {
    /// The value, in the unit the enclosing field's name gives.
    pub value: f64,
    /// x (mm) where it occurs.
    pub x_mm: f64,
    /// y (mm) where it occurs.
    pub y_mm: f64,
}

impl AtPoint {
    /// An extremum of the analysis, its value multiplied by `scale` (the
    /// unit change: 180/π for an angle in degrees).
    pub fn of(e: &Extremum, scale: f64) -> AtPoint {
        AtPoint {
            value: e.value * scale,
            x_mm: e.x,
            y_mm: e.y,
        }
    }
}

/// Degrees per radian.
pub const DEG: f64 = 180.0 / std::f64::consts::PI;

/// rpm of an angular speed in rad/s.
pub fn rpm(w: f64) -> f64 {
    w * 60.0 / (2.0 * std::f64::consts::PI)
}

/// What optimisation did to a program: motion blocks before and after,
/// arcs written, straight moves that absorbed collinear points, and the
/// largest deviation from the planned polyline against the tolerance it
/// was held to.
#[derive(Clone, Copy, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct Optimisation {
    /// Motion blocks before optimisation.
    pub blocks_before: usize,
    /// Motion blocks after optimisation.
    pub blocks_after: usize,
    /// Arcs written.
    pub arcs: usize,
    /// Straight moves that absorbed collinear points.
    pub merged_lines: usize,
    /// The largest deviation of the optimised path from the planned
    /// polyline (mm).
    pub max_deviation_mm: f64,
    /// The tolerance the optimisation was held to (mm).
    pub tolerance_mm: f64,
}

impl From<&Summary> for Optimisation {
    fn from(s: &Summary) -> Optimisation {
        Optimisation {
            blocks_before: s.moves_before,
            blocks_after: s.moves_after,
            arcs: s.arcs,
            merged_lines: s.merged_lines,
            max_deviation_mm: s.max_deviation,
            tolerance_mm: s.tolerance,
        }
    }
}
