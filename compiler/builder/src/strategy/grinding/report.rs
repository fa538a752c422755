//! The profile-grinding section of the build report (`toolpath`), as typed data
//! (see `crate::report` for the units and the schema it is part of).

use lensc_runtime::plan::grinding::GrindingPath;
use schemars::JsonSchema;
use serde::Serialize;

use crate::report::common::*;

/// The toolpath of a profile-grinding job.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct ProfileGrinding {
    /// Intervals of the profile, each ground at its own feed.
    pub segments: usize,
    /// Points of the path (the intervals' ends).
    pub cut_points: usize,
    /// Time per interval (s).
    pub interval_time_s: f64,
    /// Estimated grinding time (s).
    pub cutting_time_s: f64,
    /// The largest z speed (mm/s).
    pub max_z_speed_mm_per_s: f64,
    /// The largest z acceleration (mm/s²).
    pub max_z_acceleration_mm_per_s2: f64,
    /// How far z drifts when the intervals' velocities are integrated open
    /// loop (mm).
    pub open_loop_drift_mm: f64,
    /// The smallest concave radius of curvature of the profile (mm) and
    /// where, or null if there is none.
    pub min_concave_radius_mm: Option<AtX>,
    /// Every interval's commanded z velocity and acceleration (eqs 18–19).
    pub intervals: Intervals,
}

impl From<&GrindingPath> for ProfileGrinding {
    fn from(path: &GrindingPath) -> ProfileGrinding {
        ProfileGrinding {
            segments: path.segments,
            cut_points: path.points.len(),
            interval_time_s: path.interval_time,
            cutting_time_s: path.total_time,
            max_z_speed_mm_per_s: path.max_speed,
            max_z_acceleration_mm_per_s2: path.max_acceleration,
            open_loop_drift_mm: path.open_loop_drift,
            min_concave_radius_mm: path.min_concave_radius.map(|(r, x)| AtX {
                value: r,
                at_x_mm: x,
            }),
            // The table of eqs 18-19: every interval's commanded z
            // velocity and acceleration, as the paper's position-based
            // interpolation gives them.
            intervals: Intervals {
                columns: INTERVAL_COLUMNS,
                rows: path
                    .points
                    .iter()
                    .skip(1)
                    .map(|q| [q.contact_x, q.x, q.z, q.velocity, q.acceleration])
                    .collect(),
            },
        }
    }
}

/// The intervals of a grinding path as a table.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct Intervals {
    /// Names of the columns with their units: contact x, wheel centre x
    /// and z (mm), z velocity (mm/s), z acceleration (mm/s²).
    pub columns: [&'static str; 5],
    /// One row per interval, in the order of `columns`.
    pub rows: Vec<[f64; 5]>,
}

/// The columns of [`Intervals`].
pub const INTERVAL_COLUMNS: [&str; 5] = [
    "contact_x_mm",
    "wheel_x_mm",
    "wheel_z_mm",
    "v_mm_per_s",
    "a_mm_per_s2",
];
