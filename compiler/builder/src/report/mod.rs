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

use lensc_runtime::surface::analysis::{Extremum, SurfaceAnalysis as Analysis};
use lensc_runtime::verify::heightmap::{ErrorFigures, FeatureFigures, HeightMap as Map};
use schemars::JsonSchema;
use serde::Serialize;

pub(crate) mod common;

pub use crate::compensate::Compensation;
pub use crate::strategy::grinding::report::{Intervals, ProfileGrinding};
pub use crate::strategy::raster::report::Raster;
pub use crate::strategy::roller::report::{HelixPass, RollerHelix, RollerToolCheck};
pub use crate::strategy::spiral::report::{
    AllowedSpeed, ChordsOverTolerance, FastAxis, Servo, Settling, SpeedUnit, Spiral,
};
pub use crate::strategy::turning::report::{
    PassKind, ProfileTurning, Seam, ToolLocation, TurningPass,
};
pub use common::{AtPoint, AtRadius, AtX, DEG, Optimisation, rpm};

// Each section is its strategy's, in `strategy/NAME/report.rs`.
/// The toolpath as planned; its fields depend on the strategy, named by
/// `strategy`.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[serde(tag = "strategy", rename_all = "snake_case")]
pub enum Toolpath {
    /// Profile turning on a lathe: roughing passes, then the finish pass.
    ProfileTurning(crate::strategy::turning::report::ProfileTurning),
    /// A spiral with a fast tool servo carrying the surface.
    FtsSpiral(crate::strategy::spiral::report::Spiral),
    /// A spiral on a slow-tool-servo lathe, Z carrying the surface.
    SpiralTurning(crate::strategy::spiral::report::Spiral),
    /// Iso-plane raster on a mill.
    Raster(crate::strategy::raster::report::Raster),
    /// Profile grinding with a spherical wheel.
    ProfileGrinding(crate::strategy::grinding::report::ProfileGrinding),
    /// A design wrapped onto a roller, cut along a helix.
    RollerHelix(crate::strategy::roller::report::RollerHelix),
}

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
    /// The correction cut instead of the design, when the job has a
    /// `compensate` block: the iteration of the measure-and-correct loop.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub compensation: Option<Compensation>,
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
    /// Where the program was split because it is larger than the machine's
    /// `delivery` allows: `file`, `lines` and `bytes` are then the main
    /// program's, which calls these parts in order (absent when whole).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub delivery: Option<Delivery>,
}

/// A program split into parts for its control (`crate::delivery`).
#[derive(Clone, Debug, PartialEq, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct Delivery {
    /// The limit each part file keeps (bytes): the machine's
    /// `file_limit`, or its `memory` with `link: memory`.
    pub limit: u64,
    /// The whole program's size before it was split (bytes).
    pub whole_bytes: u64,
    /// Each part's file name and size (bytes), in the order they are called.
    pub parts: Vec<Part>,
}

/// One part of a split program.
#[derive(Clone, Debug, PartialEq, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct Part {
    pub file: String,
    pub bytes: u64,
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

impl From<&crate::job::Estimate> for Estimate {
    fn from(e: &crate::job::Estimate) -> Estimate {
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
            kind: "fast-tool-servo following: the machine's servo model driven at its data rate by the commanded positions, as printed, led by its inverse model (velocity and acceleration feed-forward); the error is its position minus the command, where the nose cuts (not where it is held over the land)",
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
    /// The most material left above the design beyond the scallops (nm,
    /// ≥ 0), and where: of every cell, its error less the scallop its own
    /// neighbouring passes leave there (the higher of the two cusps of
    /// its column either side of it; beyond a column's outermost cusp,
    /// that one; the whole error in a column without cusps), the
    /// largest. Material no pass's contact reached and no scallop beside
    /// it explains, such as a rim left to the nose's flank or a nub on
    /// the spindle axis. The gate's `max_residual` is the larger of this
    /// and the contacts' (as for each lenslet). Null if no cell was cut.
    pub residual_beyond_scallops_nm: Option<AtPoint>,
    /// RMS roughness along the cut (nm), null if not measured.
    pub rq_cutting_direction_nm: Option<f64>,
    /// RMS roughness across the cut (nm), null if not measured.
    pub rq_stepover_direction_nm: Option<f64>,
    /// The same figures per lenslet in the window (an array's lenslets,
    /// each with a cut cell), in the array's order.
    pub lenslets: Vec<LensletHeightMap>,
    /// The lenslet with the largest PV at its contacts, null if none has
    /// contacts: the one to look at first.
    pub worst_lenslet: Option<WorstLenslet>,
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
        let lenslets: Vec<LensletHeightMap> =
            map.features.iter().map(LensletHeightMap::from).collect();
        HeightMap {
            kind: "height map of the nose swept along the program's moves, as printed, against the design",
            window: Window {
                x_mm: [window.x.0, window.x.1],
                y_mm: [window.y.0, window.y.1],
                spacing_mm: window.spacing,
                given: window.given,
                whole_part: window.whole,
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
            residual_beyond_scallops_nm: beyond_scallops(map.beyond_scallops),
            rq_cutting_direction_nm: finite(map.rq_cutting * 1e6),
            rq_stepover_direction_nm: finite(map.rq_stepover * 1e6),
            worst_lenslet: worst_lenslet(&lenslets),
            lenslets,
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
    /// Set by the job's `simulate` block (false: the default window,
    /// which is the whole part).
    pub given: bool,
    /// It covers the whole of what the job cuts (the part's extent, or
    /// the disc a spiral's `from` bounds), not a part of it.
    pub whole_part: bool,
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
    /// The lenslet's index in its array, from 0: row by row from the
    /// least y, along each row from the least x.
    pub index: usize,
    /// The lenslet's centre, x and y (mm).
    pub centre_mm: [f64; 2],
    /// Form error over the cut surface there, null if none.
    pub surface: Option<Figures>,
    /// Form error at the contacts there, null if none.
    pub contact: Option<Figures>,
    /// Scallops there, null if none.
    pub scallops: Option<Scallops>,
    /// The most material left above the design beyond the scallops at
    /// any of its cells (nm, ≥ 0), as the whole map's: each cell's error
    /// less the scallop its own neighbouring passes leave there. Material
    /// no pass's contact reached and no scallop beside it explains, such
    /// as the nub a spiral leaves on the spindle axis when the lenslet is
    /// not centred there. Null if no cell was cut.
    pub residual_beyond_scallops_nm: Option<AtPoint>,
}

impl From<&FeatureFigures> for LensletHeightMap {
    fn from(f: &FeatureFigures) -> LensletHeightMap {
        LensletHeightMap {
            index: f.index,
            centre_mm: [f.centre.0, f.centre.1],
            surface: f.surface.as_ref().map(Figures::from),
            contact: f.contact.as_ref().map(Figures::from),
            scallops: f.scallops.as_ref().map(Scallops::from),
            residual_beyond_scallops_nm: beyond_scallops(f.beyond_scallops),
        }
    }
}

/// The most material left above the design beyond the scallops (nm,
/// ≥ 0) and where: of every cell, its error less the scallop its own
/// neighbouring passes leave there (the higher of the two cusps of its
/// column either side of it; beyond a column's outermost cusp that one;
/// none without cusps), the largest ([`HeightMap::beyond_scallops`] of
/// the runtime's map). Material no pass's contact reached and no scallop
/// beside it explains: a rim left to the nose's flank, the nub a spiral
/// leaves on the spindle axis. `None` if no cell was cut. The whole
/// part's and each lenslet's alike.
///
/// [`HeightMap::beyond_scallops`]: lensc_runtime::verify::heightmap::HeightMap::beyond_scallops
fn beyond_scallops(beyond: Option<(f64, (f64, f64))>) -> Option<AtPoint> {
    beyond.map(|(v, (x, y))| AtPoint {
        value: v.max(0.0) * 1e6,
        x_mm: x,
        y_mm: y,
    })
}

/// The most material left above the design (nm) and where: at the
/// contacts, or at any cell beyond the scallops beside it where that is
/// more; `None` without contacts. What the gate holds to `max_residual`,
/// on the whole part and on each lenslet.
pub fn max_residual(contact: Option<&Figures>, beyond: Option<AtPoint>) -> Option<AtPoint> {
    let c = contact?.max_residual_nm;
    Some(match beyond {
        Some(b) if b.value > c.value => b,
        _ => c,
    })
}

/// The worst lenslet of a height map: the one with the largest form
/// error, its contacts' PV or the material beyond its scallops (the
/// larger of the two).
#[derive(Clone, Copy, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct WorstLenslet {
    /// Its index in its array (as in `lenslets`).
    pub index: usize,
    /// Its centre, x and y (mm).
    pub centre_mm: [f64; 2],
    /// Its contacts' PV (nm).
    pub pv_nm: f64,
    /// Its contacts' RMS (nm).
    pub rms_nm: f64,
    /// The most material left above the design (nm): at its contacts, or
    /// at any cell beyond the scallops beside it, the larger.
    pub max_residual_nm: f64,
    /// The deepest cut below the design there, at a contact or any cell
    /// (nm).
    pub max_gouge_nm: f64,
}

impl LensletHeightMap {
    /// The most material left above the design (nm): at its contacts, or
    /// at any cell beyond the scallops beside it, the larger; `None` without
    /// contacts.
    pub fn max_residual_nm(&self) -> Option<f64> {
        max_residual(self.contact.as_ref(), self.residual_beyond_scallops_nm).map(|a| a.value)
    }

    /// The deepest cut below the design (nm), at its contacts or any of
    /// its cells; `None` without contacts.
    pub fn max_gouge_nm(&self) -> Option<f64> {
        let cells = self.surface.as_ref().map_or(0.0, |s| s.max_gouge_nm.value);
        self.contact
            .as_ref()
            .map(|c| c.max_gouge_nm.value.max(cells))
    }
}

/// Of `lenslets`, the one whose contacts' PV or residual beyond its
/// scallops is the largest (the first of equals); `None` if none has
/// contacts.
fn worst_lenslet(lenslets: &[LensletHeightMap]) -> Option<WorstLenslet> {
    let mut worst: Option<(f64, WorstLenslet)> = None;
    for l in lenslets {
        let (Some(c), Some(residual), Some(gouge)) =
            (&l.contact, l.max_residual_nm(), l.max_gouge_nm())
        else {
            continue;
        };
        let key = c.pv_nm.max(residual);
        if worst.is_none_or(|(k, _)| key > k) {
            worst = Some((
                key,
                WorstLenslet {
                    index: l.index,
                    centre_mm: l.centre_mm,
                    pv_nm: c.pv_nm,
                    rms_nm: c.rms_nm,
                    max_residual_nm: residual,
                    max_gouge_nm: gouge,
                },
            ));
        }
    }
    worst.map(|(_, w)| w)
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
    /// The area of the part the simulated figures come from: the whole
    /// part, or the window a job's `simulate` block narrows it to.
    pub judged: Judged,
    /// An array's form criteria judged lenslet by lenslet, each lenslet
    /// against the same limit as the whole part (empty without
    /// lenslets); a lenslet that misses fails the job as the whole part
    /// would.
    pub lenslets: Vec<LensletCriterion>,
}

impl Acceptance {
    /// Before the pipeline's gate has run: no criterion yet.
    pub fn pending() -> Acceptance {
        Acceptance {
            mode: AcceptanceMode::None,
            passed: true,
            criteria: Vec::new(),
            lenslets: Vec::new(),
            judged: Judged {
                area: JudgedArea::None,
                words: "nothing simulated".into(),
            },
        }
    }
}

/// The area of the part a job's figures (and so its verdict) come from.
#[derive(Clone, Debug, PartialEq, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct Judged {
    /// `whole_part`, `window` or `none`.
    pub area: JudgedArea,
    /// The same in words, with the window's place and size and the grid's
    /// spacing (a profile job: the radii sampled), as the build's summary
    /// prints it.
    pub words: String,
}

/// Which area of the part a job is judged on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum JudgedArea {
    /// Everything the job cuts: a height map over the part's extent, or
    /// a profile over every radius it cuts.
    WholePart,
    /// Only the window a job's `simulate` block gives.
    Window,
    /// Nothing was simulated.
    None,
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

/// A form criterion judged lenslet by lenslet: each lenslet's figure, at
/// its own contacts (its gouge at any of its cells too), against the
/// criterion's limit.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct LensletCriterion {
    /// Its name in an `accept` block: `form_pv`, `form_rms`, `max_gouge`
    /// or `max_residual`.
    pub criterion: &'static str,
    /// The limit (nm), the whole part's.
    pub limit: f64,
    /// Lenslets judged: those with contacts.
    pub judged: usize,
    /// The lenslet whose figure is the largest (the first of equals).
    pub worst: LensletFigure,
    /// The indices of the lenslets over the limit, in the array's order.
    pub missed: Vec<usize>,
    /// Every lenslet judged is within the limit.
    pub passed: bool,
}

/// One lenslet's figure for a criterion.
#[derive(Clone, Copy, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct LensletFigure {
    /// Its index in its array (as in the height map's `lenslets`).
    pub index: usize,
    /// Its centre, x and y (mm).
    pub centre_mm: [f64; 2],
    /// The figure (nm).
    pub measured: f64,
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

/// The evaluator of a surface (defined beside the evaluation, which
/// names it without importing the report).
pub use crate::evaluate::Backend;

/// The analysis of a surface as the reports carry it (and `lensc
/// analyse` prints it), on a `grid` per side.
pub fn surface_analysis(
    name: &str,
    kind: &str,
    l: &lensc_lang::lower::surface::LoweredSurface,
    grid: usize,
) -> SurfaceAnalysis {
    let (f, backend) = crate::evaluate::evaluator(&l.tape);
    let a = lensc_runtime::surface::analysis::analyse(f.as_ref(), &l.domain, grid);
    SurfaceAnalysis::new(name, kind, &l.domain, grid, backend, &a)
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
    crate::json_schema::schema_of::<Report>()
}

/// The schema as committed at `docs/report.schema.json`.
pub fn schema_text() -> String {
    crate::json_schema::schema_text_of::<Report>()
}

#[cfg(test)]
mod tests {
    /// The committed schema is the one the structs generate.
    #[test]
    fn committed_schema_is_current() {
        crate::json_schema::assert_schema_committed(
            "report.schema.json",
            &super::schema_text(),
            "report",
        );
    }
}
