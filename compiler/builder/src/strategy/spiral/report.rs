//! The spiral section of the build report (`toolpath`), as typed data
//! (see `crate::report` for the units and the schema it is part of).

use lensc_runtime::machine::servo::SecondOrderServo;
use lensc_runtime::plan::spiral::{FtsSpiral, FtsSummary, SpindleSpeed};
use schemars::JsonSchema;
use serde::Serialize;

use crate::report::common::*;

/// The toolpath of a spiral job (fast or slow tool servo).
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct Spiral {
    /// Spindle revolutions of the spiral.
    pub revolutions: usize,
    /// Points of the spiral.
    pub cut_points: usize,
    /// Estimated cutting time (s).
    pub cutting_time_s: f64,
    /// The path tolerance the spiral was planned to (mm).
    pub chord_tolerance_mm: f64,
    /// Where the points sit across the curve of the path: `on_path`,
    /// `straddle` or `clear` (the strategy's `chords`, or the default).
    pub chords: String,
    /// Chords the data period kept further from the exact path than their
    /// share of the tolerance, where the nose reaches the part; null if
    /// none.
    pub chords_over_tolerance: Option<ChordsOverTolerance>,
    /// The tool's nose radius (mm).
    pub nose_radius_mm: f64,
    /// The measured edge the spiral was planned and simulated with, or
    /// null if the nose is taken as a circle.
    pub edge_profile: Option<crate::edge::EdgeReport>,
    /// The axis that carries the surface (the fast tool servo's, or Z).
    pub fast_axis: FastAxis,
    /// The highest spindle speed reached (rpm).
    pub max_spindle_rpm: f64,
    /// The fast axis's servo model, or null if it has none.
    pub servo: Option<Servo>,
    /// The settling offset for an array of concave lenslets, or null if
    /// there is none (the tool follows the surface).
    pub settling: Option<Settling>,
    /// FNV-1a 64 of every point of the spiral, 16 hex digits.
    pub fingerprint_fnv1a64: String,
}

impl Spiral {
    /// The section of the spiral `s` planned as `spiral` asks, with the
    /// settling offset, the servo model and the nose radius `rho` (mm).
    pub fn new(
        s: &FtsSummary,
        spiral: &FtsSpiral,
        settling: Option<&super::Settling>,
        servo: Option<&SecondOrderServo>,
        rho: f64,
    ) -> Spiral {
        let highest_allowed_speed = match spiral.speed {
            SpindleSpeed::Constant(_) => AllowedSpeed {
                unit: SpeedUnit::SpindleRpm,
                value: rpm(s.highest_allowed_speed),
            },
            SpindleSpeed::SurfaceSpeed { .. } => AllowedSpeed {
                unit: SpeedUnit::SurfaceMPerMin,
                value: s.highest_allowed_speed * 0.06,
            },
        };
        Spiral {
            revolutions: s.revolutions,
            cut_points: s.points,
            cutting_time_s: s.time,
            chord_tolerance_mm: spiral.chord_tolerance,
            chords: spiral.chords.word().to_string(),
            chords_over_tolerance: s.chords_over_tolerance.map(|o| ChordsOverTolerance {
                count: o.count,
                max_deviation_nm: o.deviation * 1e6,
                at_radius_mm: o.at_radius,
            }),
            nose_radius_mm: rho,
            edge_profile: None,
            fast_axis: FastAxis {
                w_min_mm: s.w_min,
                w_max_mm: s.w_max,
                stroke_used_mm: s.w_max - s.w_min,
                max_acceleration_m_per_s2: s.max_acceleration / 1000.0,
                max_acceleration_at_radius_mm: s.max_acceleration_at,
                highest_allowed_speed,
            },
            max_spindle_rpm: rpm(s.max_spindle_speed),
            servo: servo.map(|m| Servo {
                natural_frequency_hz: m.natural_frequency_hz,
                damping: m.damping,
                overshoot: m.overshoot(),
                settling_time_0_2_percent_s: m.settling_time(0.002),
            }),
            settling: settling.map(|st| Settling {
                settling_time_s: st.time,
                band: st.band,
                surface_speed_m_per_min: st.surface_speed * 0.06,
                d_traj_mm: st.d_traj,
                h_offset_mm: st.offset,
            }),
            fingerprint_fnv1a64: format!("{:016x}", s.fingerprint),
        }
    }
}

/// Chords of a spiral that stray beyond their share of the tolerance.
#[derive(Clone, Copy, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct ChordsOverTolerance {
    /// How many chords.
    pub count: usize,
    /// The largest deviation from the exact path (nm).
    pub max_deviation_nm: f64,
    /// Radius of the worst chord (mm).
    pub at_radius_mm: f64,
}

/// The motion of the axis that carries the surface.
#[derive(Clone, Copy, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct FastAxis {
    /// Lowest commanded position (mm).
    pub w_min_mm: f64,
    /// Highest commanded position (mm).
    pub w_max_mm: f64,
    /// The stroke used, highest minus lowest (mm).
    pub stroke_used_mm: f64,
    /// The largest acceleration (m/s²).
    pub max_acceleration_m_per_s2: f64,
    /// Radius of the largest acceleration (mm).
    pub max_acceleration_at_radius_mm: f64,
    /// The highest speed at which the axis would keep within its
    /// acceleration limit were acceleration to scale with the square of
    /// the speed: an estimate, not planned (at the trajectory's corners
    /// the sampling reaches the data period and acceleration scales with
    /// the speed itself; a settling offset changes with speed). A refused
    /// job's E0147 help gives a speed that was planned and passes.
    pub highest_allowed_speed: AllowedSpeed,
}

/// A speed and its unit.
#[derive(Clone, Copy, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct AllowedSpeed {
    /// The unit of `value`: the job's own kind of speed.
    pub unit: SpeedUnit,
    /// The speed, in `unit`.
    pub value: f64,
}

/// A spindle speed (rpm) or a surface speed (m/min).
#[derive(Clone, Copy, Debug, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum SpeedUnit {
    /// Spindle speed, rpm.
    SpindleRpm,
    /// Surface speed, m/min.
    SurfaceMPerMin,
}

/// A second-order servo model.
#[derive(Clone, Copy, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct Servo {
    /// Natural frequency (Hz).
    pub natural_frequency_hz: f64,
    /// Damping ratio (dimensionless).
    pub damping: f64,
    /// Step-response overshoot, as a fraction of the step.
    pub overshoot: f64,
    /// Time to settle within 0.2 % of a step (s), or null if it never
    /// does.
    pub settling_time_0_2_percent_s: Option<f64>,
}

/// The settling offset for an array of concave lenslets: the tool held
/// above the land while the servo settles after each lenslet.
#[derive(Clone, Copy, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct Settling {
    /// The settling time used (s): the strategy's, or the servo model's.
    pub settling_time_s: f64,
    /// The band the servo model settles to, as a fraction of a step, or
    /// null where the strategy gave the settling time.
    pub band: Option<f64>,
    /// The fastest surface speed (m/min).
    pub surface_speed_m_per_min: f64,
    /// The path covered while settling (mm).
    pub d_traj_mm: f64,
    /// How far the tool is held above the land (mm).
    pub h_offset_mm: f64,
}
