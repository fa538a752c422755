//! The build report written beside every program (`JOB.report.json`), as
//! typed data: one struct per section, every field documented with its
//! unit. `docs/report.schema.json` is generated from these types (see
//! [`schema_text`]); the conversions from the runtime's results to report
//! sections (unit scaling included) live here too, so a builder only says
//! which results go where.
//!
//! Lengths are in mm unless a field's name says otherwise (`_nm`, `_m`);
//! angles in degrees where the name ends in `_deg`; times in s. A number
//! that was not finite (an empty set's PV, say) is written as `null`.

use lensc_runtime::emit::roller::FeedLimited;
use lensc_runtime::machine::servo::SecondOrderServo;
use lensc_runtime::plan::fts::{FtsSpiral, FtsSummary, SpindleSpeed};
use lensc_runtime::plan::grinding::GrindingPath;
use lensc_runtime::plan::optimise::Summary;
use lensc_runtime::plan::raster::RasterPath;
use lensc_runtime::plan::roller::{RollerPath, RollerTool, ToolCheck};
use lensc_runtime::plan::turning::{Toolpath as TurningPath, TurningJob};
use lensc_runtime::surface::analysis::{Extremum, SurfaceAnalysis as Analysis};
use lensc_runtime::verify::heightmap::{ErrorFigures, FeatureFigures, HeightMap as Map};
use schemars::JsonSchema;
use serde::Serialize;

/// The build report of one job: where it came from, the program written,
/// the toolpath planned, what the simulation says the program cuts, and
/// the analysis of the surface.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct Report {
    /// The job's name, as declared.
    pub job: String,
    /// The version of lensc that wrote the program.
    pub lensc_version: String,
    /// The source file built, as given on the command line.
    pub source: String,
    /// FNV-1a 64 over every loaded source in load order (each followed by
    /// a zero byte), 16 hex digits; the program header carries the same.
    pub source_fnv1a64: String,
    /// The program written.
    pub program: Program,
    /// The toolpath as planned, by strategy.
    pub toolpath: Toolpath,
    /// What the job was estimated to write before it was planned (the
    /// figures its limits were checked against).
    pub estimate: Estimate,
    /// What the program cuts, simulated from its moves as printed.
    pub simulation: Simulation,
    /// The acceptance gate: each criterion the simulated part is held to,
    /// its limit, what was measured, and whether it passed.
    pub acceptance: Acceptance,
    /// The surface's analysis over its whole domain (what `lensc analyse`
    /// prints).
    pub surface: SurfaceAnalysis,
}

impl Report {
    /// The report as a JSON value (what tests read by key).
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::to_value(self).expect("a report serialises")
    }
    /// The report as it is written: pretty JSON with keys in sorted order,
    /// ending in a newline.
    pub fn to_json_text(&self) -> String {
        json_text(self)
    }
}

/// `value` as pretty JSON with every object's keys sorted (the report's
/// written form since its first version), ending in a newline.
pub fn json_text<T: Serialize>(value: &T) -> String {
    let value = serde_json::to_value(value).expect("report sections serialise");
    serde_json::to_string_pretty(&value).expect("a JSON value prints") + "\n"
}

/// The program file and its size.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct Program {
    /// File name of the program, beside the report.
    pub file: String,
    /// The dialect it is written in.
    pub dialect: String,
    /// Lines of text.
    pub lines: usize,
    /// Size in bytes.
    pub bytes: u64,
    /// The table file a fast tool servo follows, where the dialect drives
    /// the servo from a table (absent otherwise).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fts_table: Option<FtsTable>,
}

/// What a job was estimated to write before it was planned: within 2× of
/// `toolpath.cut_points` and `program.bytes` for every example.
#[derive(Clone, Copy, Debug, Default, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct Estimate {
    /// Cut points (counted as `toolpath.cut_points` counts them).
    pub cut_points: u64,
    /// Bytes of the program.
    pub program_bytes: u64,
}

impl From<&lensc_lang::lower::job::Estimate> for Estimate {
    fn from(e: &lensc_lang::lower::job::Estimate) -> Estimate {
        Estimate {
            cut_points: e.points.round() as u64,
            program_bytes: e.program_bytes.round() as u64,
        }
    }
}

/// A fast-tool-servo table written beside the program.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct FtsTable {
    /// File name of the table.
    pub file: String,
    /// Data rows (one per spiral point; the two header lines not counted).
    pub rows: usize,
}

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
const DEG: f64 = 180.0 / std::f64::consts::PI;

/// rpm of an angular speed in rad/s.
fn rpm(w: f64) -> f64 {
    w * 60.0 / (2.0 * std::f64::consts::PI)
}

/// The toolpath as planned; its fields depend on the strategy, named by
/// `strategy`.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[serde(tag = "strategy", rename_all = "snake_case")]
pub enum Toolpath {
    /// Profile turning on a lathe: roughing passes, then the finish pass.
    ProfileTurning(ProfileTurning),
    /// A spiral with a fast tool servo carrying the surface.
    FtsSpiral(Spiral),
    /// A spiral on a slow-tool-servo lathe, Z carrying the surface.
    SpiralTurning(Spiral),
    /// Iso-plane raster on a mill.
    Raster(Raster),
    /// Profile grinding with a spherical wheel.
    ProfileGrinding(ProfileGrinding),
    /// A design wrapped onto a roller, cut along a helix.
    RollerHelix(RollerHelix),
}

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
        settling: Option<&lensc_lang::lower::job::Settling>,
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

/// What the program cuts, simulated from its moves as printed.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[serde(untagged)]
pub enum Simulation {
    /// Profile jobs (turning, grinding): the profile cut.
    Profile(ProfileCut),
    /// Fast-tool-servo jobs with a servo model: the servo's following and
    /// the height map.
    Following(Following),
    /// Raster (knife) and roller jobs: the height map.
    HeightMap(HeightMapOnly),
    /// No simulation, or only the height map: why the rest was skipped.
    Skipped(Skipped),
}

/// A height map alone.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct HeightMapOnly {
    /// The height map of the cut.
    pub height_map: HeightMap,
}

/// A simulation skipped in whole or in part.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct Skipped {
    /// Why (part of) the simulation was skipped.
    pub skipped: &'static str,
    /// The height map, where one was made all the same (spiral jobs).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub height_map: Option<HeightMap>,
}

/// A profile's simulated cut: the form error (cut minus design, positive
/// where material is left) over the radii the cut reaches, with the
/// figures defined as [`Figures`] defines them (PV largest minus least,
/// RMS about the mean, the mean, the largest deviation either way).
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct ProfileCut {
    /// What was simulated.
    pub kind: &'static str,
    /// Radii sampled.
    pub samples: usize,
    /// First radius sampled (mm), null if none.
    pub from_radius_mm: Option<f64>,
    /// Last radius sampled (mm), null if none.
    pub to_radius_mm: Option<f64>,
    /// Peak to valley of the form error: largest minus least (nm).
    pub form_error_pv_nm: Option<f64>,
    /// RMS of the form error about its mean (nm).
    pub form_error_rms_nm: Option<f64>,
    /// The mean form error (nm): piston, a uniform shift from the design;
    /// null if no radius was cut.
    pub form_error_mean_nm: Option<f64>,
    /// The error of the largest magnitude, sign kept (nm), and where; its
    /// value and radius are null if no radius was cut.
    pub largest_deviation_nm: AtRadiusOrNull,
    /// The most material left above the design (nm) and where.
    pub max_residual_nm: AtRadius,
    /// The deepest cut below the design (nm) and where.
    pub max_gouge_nm: AtRadius,
    /// The area of the surface of revolution the sampled radii stand for
    /// (mm²; each sample 2π r times the spacing).
    pub simulated_area_mm2: f64,
    /// The part of it at radii the cut does not reach (mm²).
    pub uncut_area_mm2: f64,
    /// The first radius the cut does not reach (mm), null if none.
    pub first_uncut_radius_mm: Option<f64>,
}

/// A value and the radius (mm) where it occurs, either null where there
/// is none.
#[derive(Clone, Copy, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct AtRadiusOrNull {
    /// The value, in the unit the enclosing field's name gives.
    pub value: Option<f64>,
    /// Radius (mm) where it occurs.
    pub at_radius_mm: Option<f64>,
}

impl From<&lensc_runtime::verify::simulate::ProfileCut> for ProfileCut {
    fn from(cut: &lensc_runtime::verify::simulate::ProfileCut) -> ProfileCut {
        ProfileCut {
            kind: "profile envelope of the nose along the program's moves, as printed",
            samples: cut.samples.len(),
            from_radius_mm: cut.samples.first().map(|s| s.0),
            to_radius_mm: cut.samples.last().map(|s| s.0),
            form_error_pv_nm: finite(cut.pv * 1e6),
            form_error_rms_nm: finite(cut.rms * 1e6),
            form_error_mean_nm: finite(cut.mean * 1e6),
            largest_deviation_nm: AtRadiusOrNull {
                value: finite(cut.largest_deviation.0 * 1e6),
                at_radius_mm: finite(cut.largest_deviation.1),
            },
            max_residual_nm: AtRadius {
                value: cut.max_residual.0 * 1e6,
                at_radius_mm: cut.max_residual.1,
            },
            max_gouge_nm: AtRadius {
                value: cut.max_gouge.0 * 1e6,
                at_radius_mm: cut.max_gouge.1,
            },
            simulated_area_mm2: cut.area,
            uncut_area_mm2: cut.uncut_area,
            first_uncut_radius_mm: cut.uncut_at,
        }
    }
}

/// The fast axis's servo model driven by the commanded positions, and the
/// height map of the cut.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct Following {
    /// What was simulated.
    pub kind: &'static str,
    /// The rate at which positions are commanded (Hz).
    pub data_rate_hz: f64,
    /// Servo samples simulated.
    pub servo_samples: usize,
    /// The largest following error (nm) and where.
    pub max_following_error_nm: AtRadius,
    /// The following per lenslet, in the planner's feature order.
    pub lenslets: Vec<LensletFollowing>,
    /// The height map of the cut.
    pub height_map: HeightMap,
}

impl Following {
    /// The report of a following simulation at `data_rate` (Hz), with the
    /// height map of the same cut.
    pub fn new(
        f: &lensc_runtime::verify::follow::Following,
        data_rate: f64,
        height_map: HeightMap,
    ) -> Following {
        Following {
            kind: "fast-tool-servo following: the machine's servo model driven by the commanded positions, as printed, at its data rate",
            data_rate_hz: data_rate,
            servo_samples: f.samples,
            max_following_error_nm: AtRadius {
                value: f.max_error * 1e6,
                at_radius_mm: f.max_error_at,
            },
            lenslets: f
                .lenslets
                .iter()
                .map(|l| LensletFollowing {
                    centre_mm: [l.centre.0, l.centre.1],
                    radius_mm: l.radius,
                    samples: l.samples,
                    max_error_nm: l.max_error * 1e6,
                    rms_error_nm: l.rms_error * 1e6,
                    waviness_urad: l.waviness * 1e6,
                })
                .collect(),
            height_map,
        }
    }
}

/// The servo's following over one lenslet.
#[derive(Clone, Copy, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct LensletFollowing {
    /// The lenslet's centre, x and y (mm).
    pub centre_mm: [f64; 2],
    /// The lenslet's radius (mm).
    pub radius_mm: f64,
    /// Servo samples over the lenslet.
    pub samples: usize,
    /// The largest following error (nm).
    pub max_error_nm: f64,
    /// RMS following error (nm).
    pub rms_error_nm: f64,
    /// RMS slope of the error along the cut (µrad).
    pub waviness_urad: f64,
}

/// The height map of the nose (or knife edge) swept along the program's
/// moves, as printed, against the design over a window.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct HeightMap {
    /// What was simulated.
    pub kind: &'static str,
    /// The part of the surface simulated.
    pub window: Window,
    /// The grid over the window, in the coordinates of the cut.
    pub grid: Grid,
    /// Cells of the window no pass reached.
    pub uncut_cells: usize,
    /// The part's area those cells cover (mm²).
    pub uncut_area_mm2: f64,
    /// One of those cells, x and y (mm), or null if none.
    pub first_uncut_mm: Option<[f64; 2]>,
    /// The part's area the map evaluates, every cell counted whether cut
    /// or not (mm²).
    pub simulated_area_mm2: f64,
    /// Form error over the cut surface, scallops included; null if no
    /// cell was cut.
    pub surface: Option<Figures>,
    /// Form error at the passes' contacts (scallops excluded); null if
    /// none.
    pub contact: Option<Figures>,
    /// The scallops between passes.
    pub scallops: ScallopReport,
    /// RMS roughness along the cut (nm), null if not measured.
    pub rq_cutting_direction_nm: Option<f64>,
    /// RMS roughness across the cut (nm), null if not measured.
    pub rq_stepover_direction_nm: Option<f64>,
    /// The same figures per lenslet in the window.
    pub lenslets: Vec<LensletHeightMap>,
    /// Raster jobs: the knife's edge and the path's own error.
    #[serde(flatten)]
    pub raster: Option<RasterEdge>,
}

/// What a raster's height map adds.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct RasterEdge {
    /// The edge swept: the knife's edge in its rake face, across the cut.
    pub edge: &'static str,
    /// Form error at the contacts of the same moves swept unrounded (to a
    /// picometre): the path's own error apart from the machine's
    /// resolution; null if none.
    pub contact_unrounded: Option<Figures>,
}

impl HeightMap {
    /// The report of a height map over `window` on a grid described by
    /// `coordinates`, its scallops set beside the flat-surface figure for
    /// `stepover` (mm).
    pub fn new(
        map: &Map,
        window: &crate::height_map::Window,
        coordinates: &'static str,
        stepover: f64,
    ) -> HeightMap {
        let g = &map.grid;
        HeightMap {
            kind: "height map of the nose swept along the program's moves, as printed, against the design",
            window: Window {
                x_mm: [window.x.0, window.x.1],
                y_mm: [window.y.0, window.y.1],
                spacing_mm: window.spacing,
                given: window.given,
            },
            grid: Grid {
                coordinates,
                columns: g.ns,
                rows: g.nu,
                column_step: g.ds,
                row_step_mm: g.du,
                tiles: map.tiles,
                cells_evaluated: map.cells,
            },
            uncut_cells: map.uncut,
            uncut_area_mm2: map.uncut_area,
            first_uncut_mm: map.uncut_at.map(|(x, y)| [x, y]),
            simulated_area_mm2: map.area,
            surface: map.surface.as_ref().map(Figures::from),
            contact: map.contact.as_ref().map(Figures::from),
            scallops: ScallopReport {
                stepover_mm: stepover,
                flat_theory_nm: Map::flat_scallop(map.nose_radius, stepover) * 1e6,
                simulated: map.scallops.as_ref().map(Scallops::from),
            },
            rq_cutting_direction_nm: finite(map.rq_cutting * 1e6),
            rq_stepover_direction_nm: finite(map.rq_stepover * 1e6),
            lenslets: map.features.iter().map(LensletHeightMap::from).collect(),
            raster: None,
        }
    }
}

/// `v` if it is finite, else `None` (written as null).
fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

/// The window of a height map.
#[derive(Clone, Copy, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct Window {
    /// Its x range in the design's coordinates (mm).
    pub x_mm: [f64; 2],
    /// Its y range in the design's coordinates (mm).
    pub y_mm: [f64; 2],
    /// The grid spacing asked for (mm).
    pub spacing_mm: f64,
    /// Set by the job's `simulate` block (false: the default window).
    pub given: bool,
}

/// The grid of a height map.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct Grid {
    /// What the columns and rows run along.
    pub coordinates: &'static str,
    /// Columns of the grid.
    pub columns: usize,
    /// Rows of the grid.
    pub rows: usize,
    /// Step between columns (mm, or rad where `coordinates` says the
    /// columns are at spindle angles).
    pub column_step: f64,
    /// Step between rows (mm).
    pub row_step_mm: f64,
    /// The tiles it was simulated in, each a run of whole columns and
    /// its memory freed before the next; a lathe's window over more than
    /// one lenslet goes lenslet by lenslet (each on its own polar grid
    /// over its square), and `columns` and `rows` are then the window's
    /// whole grid, not what was swept.
    pub tiles: usize,
    /// Cells evaluated: in the window (and its lenslets), cut or not.
    pub cells_evaluated: usize,
}

/// The figures of a set of form errors, as an optician reads them: the
/// error is the cut minus the design at each point counted (positive
/// where material is left); `pv_nm` is its largest minus its least value
/// over the points counted, `rms_nm` its root mean square about its mean
/// (so never above PV), `mean_nm` the mean itself (piston: a part cut
/// uniformly deep shows here and in `largest_deviation_nm`, not in PV or
/// RMS), and the extremes say where they are.
#[derive(Clone, Copy, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct Figures {
    /// Cells counted.
    pub cells: usize,
    /// Peak to valley: the largest error minus the least (nm).
    pub pv_nm: f64,
    /// RMS of the error about its mean (nm).
    pub rms_nm: f64,
    /// The mean error (nm): piston, a uniform shift from the design.
    pub mean_nm: f64,
    /// The error of the largest magnitude, sign kept (nm), and where: the
    /// largest deviation from the design in either direction.
    pub largest_deviation_nm: AtPoint,
    /// The most material left above the design (nm, ≥ 0) and where.
    pub max_residual_nm: AtPoint,
    /// The deepest cut below the design (nm, ≥ 0) and where.
    pub max_gouge_nm: AtPoint,
}

impl From<&ErrorFigures> for Figures {
    fn from(f: &ErrorFigures) -> Figures {
        let at = |(v, (x, y)): (f64, (f64, f64))| AtPoint {
            value: v * 1e6,
            x_mm: x,
            y_mm: y,
        };
        Figures {
            cells: f.count,
            pv_nm: f.pv * 1e6,
            rms_nm: f.rms * 1e6,
            mean_nm: f.mean * 1e6,
            largest_deviation_nm: at(f.largest_deviation),
            max_residual_nm: at(f.max_residual),
            max_gouge_nm: at(f.max_gouge),
        }
    }
}

/// The scallops of a height map beside the flat-surface theory.
#[derive(Clone, Copy, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct ScallopReport {
    /// Distance between passes (mm).
    pub stepover_mm: f64,
    /// The scallop height on a flat surface for the nose radius and
    /// stepover (nm).
    pub flat_theory_nm: f64,
    /// The scallops simulated, null if none were found.
    pub simulated: Option<Scallops>,
}

/// Scallops found between passes.
#[derive(Clone, Copy, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct Scallops {
    /// How many.
    pub count: usize,
    /// The highest (nm).
    pub max_nm: f64,
    /// Their mean height (nm).
    pub mean_nm: f64,
}

impl From<&lensc_runtime::verify::heightmap::Scallops> for Scallops {
    fn from(s: &lensc_runtime::verify::heightmap::Scallops) -> Scallops {
        Scallops {
            count: s.count,
            max_nm: s.max * 1e6,
            mean_nm: s.mean * 1e6,
        }
    }
}

/// A height map's figures over one lenslet.
#[derive(Clone, Copy, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct LensletHeightMap {
    /// The lenslet's centre, x and y (mm).
    pub centre_mm: [f64; 2],
    /// Form error over the cut surface there, null if none.
    pub surface: Option<Figures>,
    /// Form error at the contacts there, null if none.
    pub contact: Option<Figures>,
    /// Scallops there, null if none.
    pub scallops: Option<Scallops>,
}

impl From<&FeatureFigures> for LensletHeightMap {
    fn from(f: &FeatureFigures) -> LensletHeightMap {
        LensletHeightMap {
            centre_mm: [f.centre.0, f.centre.1],
            surface: f.surface.as_ref().map(Figures::from),
            contact: f.contact.as_ref().map(Figures::from),
            scallops: f.scallops.as_ref().map(Scallops::from),
        }
    }
}

/// The acceptance gate of a job (README, "Acceptance"): the criteria
/// its `accept` block states, the rest at defaults derived from the
/// strategy's path tolerance and the machine's resolution, each compared
/// with the simulated part. Form figures are those of [`Figures`] at the
/// passes' contacts (a profile job's: over its sampled radii).
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct Acceptance {
    /// `gate`: a criterion missed, or one that cannot be measured, is an
    /// error and no program is written; `warn` (`lensc build
    /// --accept=warn`, and `lensc report`): a warning, the program is
    /// written; `none`: the job says `accept: none`, nothing is checked.
    pub mode: AcceptanceMode,
    /// Every criterion measured and met (true when `mode` is `none`).
    pub passed: bool,
    /// Each criterion the job is held to, in a fixed order.
    pub criteria: Vec<CriterionResult>,
}

impl Acceptance {
    /// Before the pipeline's gate has run: no criterion yet.
    pub fn pending() -> Acceptance {
        Acceptance {
            mode: AcceptanceMode::None,
            passed: true,
            criteria: Vec::new(),
        }
    }
}

/// How a build treats its acceptance criteria.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum AcceptanceMode {
    /// A criterion missed is an error; no program is written.
    Gate,
    /// A criterion missed is a warning; the program is written.
    Warn,
    /// The job opted out (`accept: none`).
    None,
}

/// One acceptance criterion and what the simulation found.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct CriterionResult {
    /// Its name in an `accept` block: `form_pv`, `form_rms`, `max_gouge`,
    /// `max_residual`, `uncut_area`, `max_following_error`,
    /// `max_cutting_time`.
    pub criterion: &'static str,
    /// The unit of `limit` and `measured`: `nm`, `mm2`, `fraction` (of the
    /// area simulated) or `s`.
    pub unit: &'static str,
    /// The limit the figure may not exceed.
    pub limit: f64,
    /// Stated in the job's `accept` block, or the default.
    pub source: LimitSource,
    /// How a default limit was derived; null when stated.
    pub default_rule: Option<String>,
    /// The figure measured; null if the simulation could not measure it.
    pub measured: Option<f64>,
    /// Where on the part: a PV's highest and lowest points, a gouge's
    /// deepest, a residual's highest, the first uncut cell, the worst
    /// following error; empty for a figure with no one place (RMS,
    /// cutting time).
    pub at: Vec<Place>,
    /// Measured and within the limit.
    pub passed: bool,
    /// Why the figure could not be measured; null if it was.
    pub unmeasured: Option<&'static str>,
}

/// Where a limit came from.
#[derive(Clone, Copy, Debug, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum LimitSource {
    /// The job's `accept` block.
    Stated,
    /// Derived from the strategy's tolerance (`default_rule` says how).
    Default,
}

/// A place on the part: a point (x, y) of a surface job, or a radius of
/// a profile job or a spiral.
#[derive(Clone, Copy, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct Place {
    /// What is there: `highest`, `lowest`, `deepest`, `first_uncut`,
    /// `worst`.
    pub what: &'static str,
    /// x (mm), for a point.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub x_mm: Option<f64>,
    /// y (mm), for a point.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub y_mm: Option<f64>,
    /// The radius (mm), for a radius.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub radius_mm: Option<f64>,
}

/// The analysis of a surface over its domain (also what `lensc analyse`
/// prints). Each extremum is found on the grid and refined by re-gridding
/// a shrinking window around it.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct SurfaceAnalysis {
    /// The declaration's name.
    pub surface: String,
    /// The declaration's kind.
    pub kind: String,
    /// The domain analysed.
    pub domain: Domain,
    /// Grid points per side before refinement.
    pub grid: usize,
    /// The evaluator used.
    pub backend: Backend,
    /// The sag (mm).
    pub sag_mm: Sag,
    /// The steepest slope in any direction, atan |∇z| (degrees), and
    /// where.
    pub max_slope_deg: AtPoint,
    /// The steepest slope along x (degrees) and where.
    pub max_slope_x_deg: AtPoint,
    /// The steepest slope along y (degrees) and where.
    pub max_slope_y_deg: AtPoint,
    /// The smallest radii of curvature (mm) of the x–z and y–z sections.
    pub min_radius_of_curvature_mm: MinRadii,
}

impl SurfaceAnalysis {
    /// The report of analysis `a` of surface `name` of kind `kind` on a
    /// `grid` per side, evaluated by `backend`.
    pub fn new(
        name: &str,
        kind: &str,
        domain: &lensc_runtime::surface::analysis::Domain,
        grid: usize,
        backend: Backend,
        a: &Analysis,
    ) -> SurfaceAnalysis {
        let radius = |e: &Option<Extremum>| e.as_ref().map(|e| AtPoint::of(e, 1.0));
        SurfaceAnalysis {
            surface: name.to_string(),
            kind: kind.to_string(),
            domain: Domain::from(domain),
            grid,
            backend,
            sag_mm: Sag {
                min: AtPoint::of(&a.sag_min, 1.0),
                max: AtPoint::of(&a.sag_max, 1.0),
                pv: a.pv(),
            },
            max_slope_deg: AtPoint::of(&a.max_slope, DEG),
            max_slope_x_deg: AtPoint::of(&a.max_slope_x, DEG),
            max_slope_y_deg: AtPoint::of(&a.max_slope_y, DEG),
            min_radius_of_curvature_mm: MinRadii {
                concave_x: radius(&a.min_radius_concave_x),
                convex_x: radius(&a.min_radius_convex_x),
                concave_y: radius(&a.min_radius_concave_y),
                convex_y: radius(&a.min_radius_convex_y),
            },
        }
    }
}

/// The evaluator of a surface.
#[derive(Clone, Copy, Debug, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Backend {
    /// Compiled to machine code by cranelift.
    Jit,
    /// The reference interpreter (cranelift refused the tape).
    Interpreter,
}

/// A surface's domain.
#[derive(Clone, Copy, Debug, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Domain {
    /// A disc about the origin.
    Circle {
        /// Its radius (mm).
        radius_mm: f64,
    },
    /// A ring about the origin.
    Annulus {
        /// Its inner radius (mm).
        inner_mm: f64,
        /// Its outer radius (mm).
        outer_mm: f64,
    },
    /// A rectangle.
    Rect {
        /// Its x range (mm).
        x_mm: [f64; 2],
        /// Its y range (mm).
        y_mm: [f64; 2],
    },
}

impl From<&lensc_runtime::surface::analysis::Domain> for Domain {
    fn from(d: &lensc_runtime::surface::analysis::Domain) -> Domain {
        use lensc_runtime::surface::analysis::Domain as D;
        match *d {
            D::Circle { radius } => Domain::Circle { radius_mm: radius },
            D::Annulus { inner, outer } => Domain::Annulus {
                inner_mm: inner,
                outer_mm: outer,
            },
            D::Rect { x, y } => Domain::Rect {
                x_mm: [x.0, x.1],
                y_mm: [y.0, y.1],
            },
        }
    }
}

/// The sag of a surface (mm).
#[derive(Clone, Copy, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct Sag {
    /// The lowest sag (mm) and where.
    pub min: AtPoint,
    /// The highest sag (mm) and where.
    pub max: AtPoint,
    /// Highest minus lowest (mm).
    pub pv: f64,
}

/// The smallest radius of the x–z (y–z) section where it curves each way
/// (mm), and where; null where the surface has no region of that kind.
#[derive(Clone, Copy, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct MinRadii {
    /// Concave, x–z section.
    pub concave_x: Option<AtPoint>,
    /// Convex, x–z section.
    pub convex_x: Option<AtPoint>,
    /// Concave, y–z section.
    pub concave_y: Option<AtPoint>,
    /// Convex, y–z section.
    pub convex_y: Option<AtPoint>,
}

/// The JSON Schema of [`Report`] as written (draft 2020-12): a field is
/// required unless it is left out when empty.
pub fn schema() -> schemars::Schema {
    schemars::generate::SchemaSettings::draft2020_12()
        .for_serialize()
        .into_generator()
        .into_root_schema_for::<Report>()
}

/// The schema as committed at `docs/report.schema.json`.
pub fn schema_text() -> String {
    serde_json::to_string_pretty(&schema()).expect("a schema prints") + "\n"
}

#[cfg(test)]
mod tests {
    /// The committed schema is the one the structs generate.
    #[test]
    fn committed_schema_is_current() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/report.schema.json");
        let generated = super::schema_text();
        if std::env::var_os("LENSC_BLESS").is_some() {
            std::fs::write(path, &generated).expect("write docs/report.schema.json");
            return;
        }
        let committed = std::fs::read_to_string(path).unwrap_or_default();
        assert!(
            committed == generated,
            "docs/report.schema.json is stale: regenerate it with\n    LENSC_BLESS=1 cargo test -p lensc-build --lib report"
        );
    }
}
