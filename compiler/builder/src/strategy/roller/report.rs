//! The roller-helix section of the build report (`toolpath`), as typed data
//! (see `crate::report` for the units and the schema it is part of).

use lensc_runtime::emit::roller::FeedLimited;
use lensc_runtime::plan::roller::{RollerPath, RollerTool, ToolCheck};
use schemars::JsonSchema;
use serde::Serialize;

/// The toolpath of a roller-helix job.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct RollerHelix {
    /// Points of all passes.
    pub cut_points: usize,
    /// Estimated cutting time of all passes (s).
    pub cutting_time_s: f64,
    /// The roller's radius (mm).
    pub roller_radius_mm: f64,
    /// Where the points sit across the curve around the roller:
    /// `on_path`, `straddle` or `clear` (the strategy's `chords`, or the
    /// default).
    pub chords: String,
    /// Each helix pass, roughing first.
    pub passes: Vec<HelixPass>,
    /// The tool checks of Liu et al. section 4.
    pub tool_check: RollerToolCheck,
    /// Arc (mm) around the roller left undesigned where the design wraps,
    /// or null if the design does not wrap.
    pub wrap_gap_mm: Option<f64>,
    /// The measured edge each nose centre was placed by, or null for a
    /// nose taken as a circle.
    pub edge_profile: Option<crate::edge::EdgeReport>,
}

impl RollerHelix {
    /// The section of `path`, planned as `helix` asks, cut by `tool`,
    /// which passed `check`.
    pub fn new(
        path: &RollerPath,
        limited: &[FeedLimited],
        check: &ToolCheck,
        tool: &RollerTool,
        helix: &lensc_runtime::plan::roller::RollerHelix,
    ) -> RollerHelix {
        let roller_radius = helix.roller_radius;
        RollerHelix {
            chords: helix.chords.word().to_string(),
            cut_points: path.passes.iter().map(|p| p.points).sum(),
            cutting_time_s: path.passes.iter().filter_map(|p| p.time).sum(),
            roller_radius_mm: roller_radius,
            passes: path
                .passes
                .iter()
                .enumerate()
                .map(|(i, p)| HelixPass {
                    c_step_deg: p.c_step.to_degrees(),
                    pitch_mm: p.pitch,
                    finish_allowance_mm: p.finish_allowance,
                    points: p.points,
                    revolutions: p.revolutions,
                    x_min_mm: p.x_min,
                    x_max_mm: p.x_max,
                    cutting_time_s: p.time,
                    feed_limited_moves: limited.get(i).map_or(0, |l| l.moves),
                    fingerprint_fnv1a64: format!("{:016x}", p.fingerprint),
                })
                .collect(),
            tool_check: RollerToolCheck {
                min_radius_of_curvature_cutting_plane_mm: check.min_radius_axial,
                min_radius_of_curvature_mm: check.min_radius_overall,
                max_slope_cutting_deg: check.max_slope_cutting.to_degrees(),
                max_slope_cutting_on_roller_deg: check.max_slope_cutting_on_roller.to_degrees(),
                max_slope_axial_deg: check.max_slope_axial.to_degrees(),
                nose_radius_mm: tool.nose_radius,
                clearance_deg: tool.clearance_angle.to_degrees(),
                half_included_angle_deg: tool.opening_angle.to_degrees() / 2.0,
            },
            wrap_gap_mm: path.wrap.map(|w| w.gap),
            edge_profile: None,
        }
    }
}

/// One pass of a roller helix.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct HelixPass {
    /// Spindle angle between points (degrees).
    pub c_step_deg: f64,
    /// Advance along the roller per revolution (mm).
    pub pitch_mm: f64,
    /// Material left for the next pass (mm).
    pub finish_allowance_mm: f64,
    /// Points of the pass.
    pub points: usize,
    /// Spindle revolutions of the pass.
    pub revolutions: f64,
    /// Lowest radius of the nose centre (mm).
    pub x_min_mm: f64,
    /// Highest radius of the nose centre (mm).
    pub x_max_mm: f64,
    /// Estimated cutting time (s), or null without a spindle speed: the
    /// spindle's pace, and the moves the feed limit slowed at that limit.
    pub cutting_time_s: Option<f64>,
    /// Moves of the pass slowed below the spindle's pace because X and Z
    /// together would have fed above the machine's feed limit.
    pub feed_limited_moves: usize,
    /// FNV-1a 64 of every point of the pass, 16 hex digits.
    pub fingerprint_fnv1a64: String,
}

/// The roller tool checks (Liu et al. section 4).
#[derive(Clone, Copy, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct RollerToolCheck {
    /// The smallest concave radius of curvature in the cutting plane (mm).
    pub min_radius_of_curvature_cutting_plane_mm: f64,
    /// The smallest concave radius of curvature in any direction (mm).
    pub min_radius_of_curvature_mm: f64,
    /// The steepest slope in the cutting direction on the flat design
    /// (degrees).
    pub max_slope_cutting_deg: f64,
    /// The steepest slope in the cutting direction, around the roller
    /// (degrees).
    pub max_slope_cutting_on_roller_deg: f64,
    /// The steepest slope along the roller axis (degrees).
    pub max_slope_axial_deg: f64,
    /// The tool's nose radius (mm).
    pub nose_radius_mm: f64,
    /// The tool's clearance angle (degrees).
    pub clearance_deg: f64,
    /// Half the tool's included angle (degrees).
    pub half_included_angle_deg: f64,
}
