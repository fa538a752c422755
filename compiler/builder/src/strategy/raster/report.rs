//! The raster section of the build report (`toolpath`), as typed data
//! (see `crate::report` for the units and the schema it is part of).

use lensc_runtime::plan::optimise::Summary;
use lensc_runtime::plan::raster::RasterPath;
use schemars::JsonSchema;
use serde::Serialize;

use crate::report::common::*;

/// The toolpath of a raster job.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct Raster {
    /// Passes (rows of the raster).
    pub passes: usize,
    /// Points of all passes.
    pub cut_points: usize,
    /// Length of the cutting moves (mm).
    pub cut_length_mm: f64,
    /// The cutting feed (mm/min).
    pub feed_mm_per_min: f64,
    /// Estimated cutting time (s).
    pub cutting_time_s: f64,
    /// Cutting time of each pass in cutting order (s).
    pub pass_cutting_times_s: Vec<f64>,
    /// The chord tolerance the path was planned to (mm).
    pub chord_tolerance_mm: f64,
    /// Distance between passes (mm).
    pub stepover_mm: f64,
    /// What optimisation (arcs, merged lines) did to the program.
    pub optimisation: Optimisation,
    /// The steepest slope along the cut (degrees) and where.
    pub max_slope_along_deg: AtPoint,
    /// The steepest slope across the cut (degrees) and where.
    pub max_slope_across_deg: AtPoint,
    /// The smallest concave radius of curvature along the cut (mm) and
    /// where, or null if there is none.
    pub min_concave_radius_along_mm: Option<AtPoint>,
    /// Where the points sit across the curve of each pass: `on_path`,
    /// `straddle` or `clear` (the strategy's `chords`, or the default the
    /// job's `max_gouge` chose).
    pub chords: String,
}

impl Raster {
    /// The section of `path`, planned as `raster` asks, cut at `feed`
    /// (mm/s), optimised as `optimised` says.
    pub fn new(
        path: &RasterPath,
        raster: &lensc_runtime::plan::raster::Raster,
        feed: f64,
        optimised: &Summary,
    ) -> Raster {
        Raster {
            passes: path.pass_count,
            cut_points: path.point_count,
            cut_length_mm: path.cut_length,
            feed_mm_per_min: feed * 60.0,
            cutting_time_s: path.cut_length / feed,
            pass_cutting_times_s: path.pass_lengths.iter().map(|l| l / feed).collect(),
            chord_tolerance_mm: raster.chord_tolerance,
            stepover_mm: raster.stepover,
            optimisation: optimised.into(),
            max_slope_along_deg: AtPoint::of(&path.max_slope_along, DEG),
            max_slope_across_deg: AtPoint::of(&path.max_slope_across, DEG),
            min_concave_radius_along_mm: path
                .min_concave_radius_along
                .as_ref()
                .map(|e| AtPoint::of(e, 1.0)),
            chords: raster.chords.word().to_string(),
        }
    }
}
