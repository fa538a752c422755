//! The profile-turning section of the build report (`toolpath`), as typed data
//! (see `crate::report` for the units and the schema it is part of).

use lensc_runtime::plan::optimise::Summary;
use lensc_runtime::plan::turning::{Toolpath as TurningPath, TurningJob};
use schemars::JsonSchema;
use serde::Serialize;

use crate::report::common::*;

/// The toolpath of a profile-turning job.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct ProfileTurning {
    /// Cutting points of all passes.
    pub cut_points: usize,
    /// Length of the cutting moves (mm).
    pub cut_length_mm: f64,
    /// The cutting feed (mm/min).
    pub feed_mm_per_min: f64,
    /// The constant surface speed (m/min), or null for a constant spindle
    /// speed.
    pub surface_speed_m_per_min: Option<f64>,
    /// The highest spindle speed (rpm): the constant speed, or the cap of
    /// a constant surface speed.
    pub max_spindle_rpm: f64,
    /// Estimated cutting time of all passes (s).
    pub cutting_time_s: f64,
    /// Each pass in cutting order and its cutting time.
    pub passes: Vec<TurningPass>,
    /// The chord tolerance the path was planned to (mm).
    pub chord_tolerance_mm: f64,
    /// The steepest slope of the profile along the path (degrees).
    pub max_profile_slope_deg: f64,
    /// The smallest concave radius of curvature of the profile (mm) and
    /// where, or null if the profile has no concave part.
    pub min_concave_radius_mm: Option<AtRadius>,
    /// How many of `passes` are roughing passes (the rest is the finish).
    pub roughing_passes: usize,
    /// How the tool's contact point was located on the surface.
    pub tool_location: ToolLocation,
    /// Concave corners the nose cannot reach into, where material is left
    /// above the design.
    pub seams: Vec<Seam>,
    /// What optimisation (arcs, merged lines) did to the program.
    pub optimisation: Optimisation,
    /// Where the finish pass's points sit across the curve of the path:
    /// `on_path`, `straddle` or `clear` (the strategy's `chords`, or the
    /// default the job's `max_gouge` chose).
    pub chords: String,
    /// The tool's measured edge the path was offset for (R + δ at each
    /// angle of contact), absent for a circular nose.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub edge_profile: Option<crate::edge::EdgeReport>,
}

impl ProfileTurning {
    /// The section of `path`, planned for `job`, optimised as `optimised`
    /// says.
    pub fn new(job: &TurningJob, path: &TurningPath, optimised: &Summary) -> ProfileTurning {
        use lensc_runtime::plan::turning::ToolLocation as L;
        ProfileTurning {
            cut_points: path.cut_points,
            cut_length_mm: path.cut_length,
            feed_mm_per_min: path.feed_speed * 60.0,
            surface_speed_m_per_min: job.strategy.surface_speed.map(|v| v * 0.06),
            max_spindle_rpm: rpm(job.strategy.spindle_speed),
            cutting_time_s: path.cutting_time(),
            passes: path
                .pass_times
                .iter()
                .enumerate()
                .map(|(i, &t)| TurningPass {
                    pass: if i < path.roughing_passes {
                        PassKind::Roughing
                    } else {
                        PassKind::Finish
                    },
                    cutting_time_s: t,
                })
                .collect(),
            chord_tolerance_mm: job.strategy.chord_tolerance,
            max_profile_slope_deg: path.max_slope.0.to_degrees(),
            min_concave_radius_mm: path.min_concave_radius.map(|(r, at)| AtRadius {
                value: r,
                at_radius_mm: at,
            }),
            roughing_passes: path.roughing_passes,
            tool_location: match job.strategy.location {
                L::Exact => ToolLocation::Exact,
                L::Sequential { .. } => ToolLocation::Sequential,
                L::Binary { .. } => ToolLocation::Binary,
            },
            seams: path
                .seams
                .iter()
                .map(|s| Seam {
                    at_radius_mm: s.at_radius,
                    uncut_depth_mm: s.depth,
                    corner_angle_deg: s.angle.to_degrees(),
                })
                .collect(),
            optimisation: optimised.into(),
            chords: job.strategy.chords.word().to_string(),
            edge_profile: None,
        }
    }
}

/// One pass of a profile-turning job.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct TurningPass {
    /// A roughing pass or the finish pass.
    pub pass: PassKind,
    /// Estimated cutting time of the pass (s).
    pub cutting_time_s: f64,
}

/// A roughing pass or the finish pass.
#[derive(Clone, Copy, Debug, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum PassKind {
    Roughing,
    Finish,
}

/// How the tool's contact point is located on the surface.
#[derive(Clone, Copy, Debug, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum ToolLocation {
    /// Solved exactly for each point.
    Exact,
    /// Searched along the profile in steps.
    Sequential,
    /// Bisected along the profile.
    Binary,
}

/// A concave corner the nose cannot reach into.
#[derive(Clone, Copy, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct Seam {
    /// Radius of the corner (mm).
    pub at_radius_mm: f64,
    /// The deepest material left above the design there (mm).
    pub uncut_depth_mm: f64,
    /// The angle between the profile's two sides at the corner (degrees).
    pub corner_angle_deg: f64,
}
