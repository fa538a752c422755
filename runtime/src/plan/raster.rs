//! Iso-plane raster finishing on a 3-axis mill (Lin 2022, seed 000): the
//! tool cuts along one axis at a fixed position on the other, is raised,
//! steps over, and cuts the next path, until the aperture is covered.
//!
//! Every tool-centre point is exact, computed from the surface's exact
//! derivatives:
//! - the microshaper knife scrapes along the cut with its rake face
//!   facing the motion, so its cutting edge, the nose arc, lies in the
//!   plane across the cut: at each position along the cut the nose centre
//!   is the offset of the surface's cross-section (the section across the
//!   cut) by the nose radius, its contact solved (Newton on the exact
//!   derivatives) so that the centre lies on the path plane. The cut this
//!   leaves is what the height-map simulation sweeps (`heightmap.rs`), the
//!   geometry the clearance-angle check assumes, and what gives Lin's
//!   step-over scallops. Lin's own model (the nose circle in the plane of
//!   the path, his Fig. 5 and eq 4) is kept as reference functions;
//! - the ball-end mill's centre is the contact point moved by the radius
//!   along the 3-D surface normal; the contact point is solved (Newton on
//!   the exact derivatives) so that the centre lies on the path plane.
//!
//! Points are spaced so that no chord between consecutive centres strays
//! more than the chord tolerance from the exact centre curve, optionally
//! also capped by a fixed step and by Lin's step rule (eqs 2–3). Each path
//! ends where the contact point reaches the edge of the aperture grown by
//! the rim's reach (`rim_reach`: a stepover, or the largest distance
//! between neighbouring planes' contacts where that is more), so that
//! every point of the rim lies between two planes' contacts and is cut to
//! a scallop, not left to the flank of the last plane inside; where the
//! surface is undefined beyond the aperture, the path ends where it stops
//! being defined. Lin's approximate compensations (eq 4, eqs 5–6) are
//! provided as functions to compare against; the planner itself does not
//! use them.
//!
//! Units: mm and rad. +z points out of the material, towards the tool.

use crate::plan::chords::{self, Band, ChordPlacement};
use crate::surface::analysis::{Domain, Extremum};
use crate::surface::ir::SurfaceFn;

/// A machine axis in the plane of the part.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Axis {
    X,
    Y,
}

/// The raster strategy as the user gave it.
#[derive(Clone, Debug, PartialEq)]
pub struct Raster {
    /// The cutting direction; paths step over along the other axis.
    pub along: Axis,
    /// Cut alternate paths in opposite directions; `false` cuts every path
    /// the same way (one-way, rapid back between paths).
    pub zigzag: bool,
    /// Distance (mm) between path planes.
    pub stepover: f64,
    /// The path's tolerance T (mm); the chords take
    /// `optimise::CHORD_SHARE` of it, arc fitting and blending the rest.
    pub chord_tolerance: f64,
    /// Longest move (mm) between consecutive tool-centre points, if capped.
    pub max_step: Option<f64>,
    /// Lin's step rule (eqs 2–3), if asked for: the central angle α (rad)
    /// one step may subtend on the section's osculating circle. The step
    /// between consecutive contact points, measured along the cut, then
    /// never exceeds `lin_step(ρ, α, dz/du)` evaluated at either end.
    pub lin_angle: Option<f64>,
    /// Height (mm) of the rapid plane above the highest tool-centre point.
    pub retract: f64,
    /// Where the points sit across the curve of each pass (`plan::chords`),
    /// each moved along Z by the bands of its chords.
    pub chords: ChordPlacement,
}

/// The cutter, referenced at the centre of its nose circle or ball.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RasterTool {
    /// The microshaper: its edge, the nose arc, lies in its rake face,
    /// across the cut, so the tool-centre is the 2-D offset of the section
    /// across the cut, with the centre on the path plane. The tip is
    /// `nose_radius` below the centre.
    Knife { nose_radius: f64 },
    /// Ball-end mill: 3-D offset along the surface normal, with the centre
    /// kept on the path plane.
    Ball { radius: f64 },
}

impl RasterTool {
    /// Nose or ball radius (mm).
    pub fn radius(&self) -> f64 {
        match *self {
            RasterTool::Knife { nose_radius } => nose_radius,
            RasterTool::Ball { radius } => radius,
        }
    }
}

/// A planned raster and what planning learned about the part.
#[derive(Clone, Debug, PartialEq)]
pub struct RasterPath {
    /// Tool-centre points [x, y, z] of each pass, in cutting order (zigzag
    /// reverses alternate path planes). Between passes the tool rapids at
    /// `safe_z`.
    pub passes: Vec<Vec<[f64; 3]>>,
    /// Height (mm) of the rapid plane.
    pub safe_z: f64,
    pub pass_count: usize,
    /// Tool-centre points over all passes.
    pub point_count: usize,
    /// Length (mm) of the cutting moves (rapids, plunges and retracts excluded).
    pub cut_length: f64,
    /// Length (mm) of each pass's cutting moves, in cutting order.
    pub pass_lengths: Vec<f64>,
    /// Steepest slope along the cut, atan |∂z/∂u| (rad), at a contact point.
    pub max_slope_along: Extremum,
    /// Steepest slope across the cut, atan |∂z/∂v| (rad), at a contact point.
    pub max_slope_across: Extremum,
    /// Smallest radius of curvature (mm) of the section along the cut where
    /// it is concave (curving towards the tool); `None` if nowhere concave.
    pub min_concave_radius_along: Option<Extremum>,
}

/// Why a raster cannot be planned as given, with the figures a diagnostic
/// needs. Locations (x, y) are in mm on the part.
#[derive(Clone, Debug, PartialEq)]
pub enum RasterError {
    /// A parameter is out of range (not finite, or not positive where it
    /// must be).
    InvalidParameter { name: &'static str, value: f64 },
    /// The tool is larger than the smallest concave radius of curvature it
    /// must fit: the section across the cut for the knife, the larger
    /// principal curvature for the ball. It would cut the sides of the
    /// hollow before reaching its bottom.
    ToolTooLarge {
        tool_radius: f64,
        min_radius: f64,
        x: f64,
        y: f64,
    },
    /// The knife's clearance angle (rad) is not above the surface's
    /// steepest slope along the cut (rad), found at (x, y): its flank
    /// would rub.
    ClearanceTooSmall {
        clearance: f64,
        slope: f64,
        x: f64,
        y: f64,
    },
    /// The surface (or its derivatives) is not finite at this point of the
    /// aperture.
    Undefined { x: f64, y: f64 },
    /// No contact point puts the tool centre on the path plane here.
    NoContact { x: f64, y: f64 },
    /// The chord tolerance cannot be met in floating point near this point.
    ToleranceUnreachable { x: f64, y: f64, tolerance: f64 },
    /// Too many path planes for the stepover.
    TooManyPaths { paths: f64, limit: usize },
    /// Too many tool-centre points for the tolerance and steps asked for.
    TooManyPoints { limit: usize },
    /// No path plane crosses the aperture.
    NothingToCut,
}

impl std::fmt::Display for RasterError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            RasterError::InvalidParameter { name, value } => {
                write!(f, "{name} {value} is out of range")
            }
            RasterError::ToolTooLarge {
                tool_radius,
                min_radius,
                x,
                y,
            } => write!(
                f,
                "tool radius {tool_radius} mm exceeds the smallest concave radius \
                 {min_radius} mm at ({x}, {y})"
            ),
            RasterError::ClearanceTooSmall {
                clearance,
                slope,
                x,
                y,
            } => write!(
                f,
                "clearance angle {clearance} rad does not clear the slope {slope} rad \
                 along the cut at ({x}, {y})"
            ),
            RasterError::Undefined { x, y } => write!(f, "surface undefined at ({x}, {y})"),
            RasterError::NoContact { x, y } => {
                write!(f, "no tool contact on the path plane near ({x}, {y})")
            }
            RasterError::ToleranceUnreachable { x, y, tolerance } => write!(
                f,
                "chord tolerance {tolerance} mm cannot be met near ({x}, {y})"
            ),
            RasterError::TooManyPaths { paths, limit } => {
                write!(f, "{paths} paths exceed the limit of {limit}")
            }
            RasterError::TooManyPoints { limit } => {
                write!(f, "more than {limit} tool-centre points")
            }
            RasterError::NothingToCut => write!(f, "no path crosses the aperture"),
        }
    }
}

impl std::error::Error for RasterError {}

impl RasterError {
    /// The point (x, y) on the part the error names, if it names one.
    fn place(&self) -> Option<(f64, f64)> {
        match *self {
            RasterError::ToolTooLarge { x, y, .. }
            | RasterError::ClearanceTooSmall { x, y, .. }
            | RasterError::Undefined { x, y }
            | RasterError::NoContact { x, y }
            | RasterError::ToleranceUnreachable { x, y, .. } => Some((x, y)),
            RasterError::InvalidParameter { .. }
            | RasterError::TooManyPaths { .. }
            | RasterError::TooManyPoints { .. }
            | RasterError::NothingToCut => None,
        }
    }
}

/// A contact point on the surface and the tool centre that touches it there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToolContact {
    pub contact: [f64; 3],
    pub centre: [f64; 3],
}

/// Signed radius of curvature (mm) of a section with slope dz/du and
/// curvature term d²z/du² — Lin's ρ = (1 + z'²)^(3/2) / z'': positive where
/// the section is concave (a bowl), negative where convex, infinite where
/// straight.
pub fn section_radius(slope: f64, d2z: f64) -> f64 {
    (1.0 + slope * slope).powf(1.5) / d2z
}

/// Lin eq 2: the chord l = 2ρ sin(α/2) subtending the central angle α on a
/// circle of radius |ρ|.
pub fn lin_chord(radius_of_curvature: f64, alpha: f64) -> f64 {
    2.0 * radius_of_curvature.abs() * (0.5 * alpha).sin()
}

/// Lin eqs 2–3: the step along the cutting axis, Δ = l cos θ with
/// l = 2ρ sin(α/2) and θ = atan(dz/du). Infinite where the section is
/// straight (ρ infinite).
pub fn lin_step(radius_of_curvature: f64, alpha: f64, slope: f64) -> f64 {
    lin_chord(radius_of_curvature, alpha) / (1.0 + slope * slope).sqrt()
}

/// Lin eq 4: how far (mm) to raise the knife tip above the designed point S
/// so that a nose of radius r, centred over S, clears the surface:
/// δ = δ1 + δ2, δ1 = r (1/cos θ − 1), δ2 = (ρ / cos θ)(1/cos α − 1),
/// θ = atan(dz/du), α = atan((r/ρ) tan θ), with Lin's signed ρ
/// (`section_radius`). δ2 is taken as 0 where the section is straight.
/// Exact for a straight section; on a curved one it agrees with the exact
/// raise to first order in r/ρ, leaving a relative error of about −(r/ρ)²
/// (−0.73 % for the 85 µm nose on a 1 mm sphere; see the tests).
pub fn lin_interference_offset(nose_radius: f64, radius_of_curvature: f64, slope: f64) -> f64 {
    let cos_t = 1.0 / (1.0 + slope * slope).sqrt();
    let d1 = nose_radius * (1.0 / cos_t - 1.0);
    let d2 = if radius_of_curvature.is_finite() {
        let alpha = (nose_radius / radius_of_curvature * slope).atan();
        radius_of_curvature / cos_t * (1.0 / alpha.cos() - 1.0)
    } else {
        0.0
    };
    d1 + d2
}

/// Lin eqs 5–6: the boundary compensation δ = δ*/(dz/du) with
/// δ* = r (1 − cos θ), θ = atan(dz/du): how far the last contact point
/// sits inside the aperture edge so that the knife tip, r (1 − cos θ) below
/// the contact point, stays at the height of the edge — exact where the
/// section is straight. Signed like the slope; 0 where the slope is 0.
/// (Eq 5, for the path direction, is lost from the seed's text; it is taken
/// to be eq 6 with the slope along the path, as the text's parallel
/// wording implies.)
pub fn lin_boundary_offset(nose_radius: f64, slope: f64) -> f64 {
    // r (1 − cos θ) / tan θ = r cos θ tan(θ/2), which is finite at θ = 0.
    let theta = slope.atan();
    nose_radius * theta.cos() * (0.5 * theta).tan()
}

/// The exact contact and tool-centre of `tool` for the path plane at
/// `plane` (y for cuts along x, x for cuts along y) at position `u` along
/// the cut: u is the contact point's coordinate along the cut, and the
/// contact's other coordinate is solved so that the centre lies on the
/// plane. The knife's centre is at u too (its edge is across the cut); the
/// ball's is moved along the cut by the normal's component there.
pub fn tool_contact(
    tool: &RasterTool,
    surface: &dyn SurfaceFn,
    along: Axis,
    plane: f64,
    u: f64,
) -> Result<ToolContact, RasterError> {
    validate_tool(tool)?;
    if !(plane.is_finite() && u.is_finite()) {
        return Err(RasterError::InvalidParameter {
            name: "position",
            value: if plane.is_finite() { u } else { plane },
        });
    }
    let cutter = Cutter::new(tool, surface, along);
    let c = cutter.contact(plane, u, plane)?;
    let (x, y) = xy(along, c.u, c.v);
    Ok(ToolContact {
        contact: [x, y, c.l.z],
        centre: cutter.centre_xyz(plane, &c),
    })
}

/// What the raster's path planes show before any pass is sampled: the
/// figures gathered at every contact of the planes' scans and span ends.
/// The planned path's figures (`RasterPath`) extend them over every
/// sampled contact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RasterScan {
    /// Steepest slope along the cut, atan |∂z/∂u| (rad), at a contact point.
    pub max_slope_along: Extremum,
    /// Steepest slope across the cut, atan |∂z/∂v| (rad), at a contact point.
    pub max_slope_across: Extremum,
    /// Smallest radius of curvature (mm) of the section along the cut where
    /// it is concave; `None` if nowhere concave.
    pub min_concave_radius_along: Option<Extremum>,
}

/// Checks a raster against its surface before planning: its parameters
/// are in range, the surface is defined and has a contact wherever a path
/// plane crosses the aperture, and the tool fits the smallest concave
/// radius it must fit at the contacts of its planes. The compiler's
/// lowering runs it so `lensc check` reports these; the planner runs the
/// same scan as its first phase, so the figures agree on a raster of up to
/// `CHECK_PLANES` planes. On a finer raster the check scans that many
/// planes spread evenly over all of them (the first, the last and the one
/// at the aperture's far edge among them), so `check` takes the same time
/// at any stepover (a 50 mm part at 0.4 µm has 125,000 planes: 17.7 s of
/// scanning in a debug build); the build's first phase scans every plane
/// and refuses, with the same errors, what falls between them.
pub fn check_raster(
    r: &Raster,
    tool: &RasterTool,
    surface: &dyn SurfaceFn,
    aperture: &Domain,
) -> Result<RasterScan, RasterError> {
    check_raster_planes(r, tool, surface, aperture).map(|(scan, _)| scan)
}

/// [`check_raster`], with the planes its scan found cutting and their
/// spans: what the estimate counts a program by, at no second scan.
pub fn check_raster_planes(
    r: &Raster,
    tool: &RasterTool,
    surface: &dyn SurfaceFn,
    aperture: &Domain,
) -> Result<(RasterScan, PlaneSpans), RasterError> {
    let cutter = Cutter::new(tool, surface, r.along);
    let (lines, summary) = scan_planes(r, tool, &cutter, aperture, CHECK_PLANES)?;
    let scan = RasterScan {
        max_slope_along: summary.slope_along,
        max_slope_across: summary.slope_across,
        min_concave_radius_along: summary.concave_along,
    };
    let planes = lines
        .into_iter()
        .map(|(v, spans)| {
            let ends = spans.iter().map(|(a, b)| [(a.u, a.v), (b.u, b.v)]);
            (v, ends.collect())
        })
        .collect();
    Ok((
        scan,
        PlaneSpans {
            planes,
            weight: summary.weight,
        },
    ))
}

/// A plane's span of contacts, from its first to its last, each (u, v)
/// (v is y when cutting along x).
pub type ContactSpan = [(f64, f64); 2];

/// The planes a raster cuts, as its planner's first phase finds them
/// (`scan_planes`), the rim's planes among them: those beyond the
/// aperture whose contacts reach its rim (`rim_reach`). By default none.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PlaneSpans {
    /// Each scanned plane that cuts: its v and its spans.
    pub planes: Vec<(f64, Vec<ContactSpan>)>,
    /// How many of the raster's planes each scanned one stands for: 1
    /// when every plane is scanned.
    pub weight: f64,
}

/// The knife's flank must clear the steepest slope along the cut:
/// `ClearanceTooSmall` unless `clearance` (rad) is above `slope_along`.
/// Lowering applies it to the planes' scan, the build to the planned path.
pub fn check_clearance(clearance: f64, slope_along: Extremum) -> Result<(), RasterError> {
    if clearance > slope_along.value {
        return Ok(());
    }
    Err(RasterError::ClearanceTooSmall {
        clearance,
        slope: slope_along.value,
        x: slope_along.x,
        y: slope_along.y,
    })
}

/// A path plane (v) and the spans of contacts it cuts.
type Line = (f64, Vec<(Contact, Contact)>);

/// Phase 1 of the raster: where each plane at v0 + k·stepover (v is y
/// when cutting along x) cuts, with the surface and the tool checked
/// there; the planes that cut, and the figures gathered.
fn scan_planes(
    r: &Raster,
    tool: &RasterTool,
    cutter: &Cutter,
    aperture: &Domain,
    most: usize,
) -> Result<(Vec<Line>, Summary), RasterError> {
    validate(r, tool, aperture)?;
    // Contacts are taken beyond the aperture's edge (`rim_reach`), on the
    // surface's own continuation where it has one: a point of the rim
    // lies between the contacts of two planes only if the outer plane's
    // contact reaches past it. A first reach of a stepover covers the rim
    // wherever the contacts of neighbouring planes lie no further apart
    // than their planes (a flat or convex section across the cut); where
    // they spread further (a concave one: a ball in a bowl), the planes
    // are scanned again with the reach their spread asks for.
    let (lines, summary) = scan_reach(r, cutter, aperture, r.stepover, most)?;
    let reach = rim_reach(r.stepover, cutter.radius, summary.spread);
    if reach <= r.stepover {
        return Ok((lines, summary));
    }
    scan_reach(r, cutter, aperture, reach, most)
}

/// How far (mm) beyond the aperture the contacts are taken: the largest
/// distance between the contacts of neighbouring planes, `stepover`
/// times `spread` (the largest ratio of that distance to the stepover at
/// the aperture's contacts, 1/(1 − ρ ∂(z_v/W)/∂v), `Cutter::spread`), at
/// least a stepover and at most the tool's radius (a spread that large is
/// a tool that barely fits its hollow).
fn rim_reach(stepover: f64, tool_radius: f64, spread: f64) -> f64 {
    let spacing = stepover * spread;
    if spacing.is_nan() || spacing <= stepover {
        return stepover;
    }
    spacing.min(tool_radius.max(stepover))
}

/// The planes' scan (`scan_planes`) with contacts taken up to `margin`
/// (mm) beyond the aperture, over at most `most` planes (`sampled`).
fn scan_reach(
    r: &Raster,
    cutter: &Cutter,
    aperture: &Domain,
    margin: f64,
    most: usize,
) -> Result<(Vec<Line>, Summary), RasterError> {
    let ((x0, x1), (y0, y1)) = aperture.bounds();
    let ((u0, u1), (v0, v1)) = match r.along {
        Axis::X => ((x0, x1), (y0, y1)),
        Axis::Y => ((y0, y1), (x0, x1)),
    };
    // The contact lies off its plane by up to the tool's radius, and is
    // taken up to `margin` beyond the aperture, so the planes reach that
    // far beyond it on either side.
    let last = ((v1 - v0) / r.stepover + 1e-9).floor();
    let extra = ((cutter.radius + margin) / r.stepover).ceil();
    let paths = last + 1.0 + 2.0 * extra;
    if paths > MAX_PATHS as f64 {
        return Err(RasterError::TooManyPaths {
            paths,
            limit: MAX_PATHS,
        });
    }
    let (last, extra) = (last as i64, extra as i64);
    // The figures (slopes, curvatures, the tool's fit) stay the
    // aperture's own.
    let reach = aperture.grown(margin);
    let mut summary = Summary::within(r.along, *aperture);
    let mut lines = Vec::new();
    let ks = sampled(-extra, last + extra, last, most);
    summary.weight = paths / ks.len().max(1) as f64;
    for k in ks {
        let mut v = v0 + k as f64 * r.stepover;
        if k == last {
            v = v.min(v1);
        }
        let spans = cutter.spans(aperture, &reach, v, (u0, u1), &mut summary)?;
        if !spans.is_empty() {
            lines.push((v, spans));
        }
    }
    if lines.is_empty() {
        return Err(RasterError::NothingToCut);
    }
    summary.check_tool(cutter.radius)?;
    Ok((lines, summary))
}

/// The planes `first..=end` in order, or `most` of them (at least 2)
/// spread evenly over that range, with `first`, `end` and `keep` among them.
fn sampled(first: i64, end: i64, keep: i64, most: usize) -> Vec<i64> {
    let count = (end - first + 1).max(0) as u64;
    let most = most.max(2) as u64;
    if count <= most {
        return (first..=end).collect();
    }
    let mut ks: Vec<i64> = (0..most)
        .map(|i| first + (i * (count - 1) / (most - 1)) as i64)
        .collect();
    if let Err(at) = ks.binary_search(&keep) {
        ks.insert(at, keep);
    }
    ks
}

/// Plans the raster over `aperture`: path planes at v0 + k·stepover (v is y
/// when cutting along x), each pass running between the points where the
/// contact point meets the edge of the aperture grown by the rim's reach
/// (`rim_reach`), or stops short of it where the surface is undefined
/// beyond the aperture.
pub fn plan_raster(
    r: &Raster,
    tool: &RasterTool,
    surface: &dyn SurfaceFn,
    aperture: &Domain,
) -> Result<RasterPath, RasterError> {
    let cutter = Cutter::new(tool, surface, r.along);
    // Phase 1: where each plane cuts, with the surface checked there.
    let (lines, mut summary) = scan_planes(r, tool, &cutter, aperture, usize::MAX)?;

    // Phase 2: the exact centres of each pass, chord by chord.
    let mut budget = MAX_POINTS;
    let mut passes = Vec::new();
    for (j, (v, spans)) in lines.iter().enumerate() {
        let mut line = Vec::with_capacity(spans.len());
        for &(a, b) in spans {
            let pts = cutter.sample(r, *v, a, b, &mut budget, &mut summary)?;
            let mut centres: Vec<[f64; 3]> = pts.iter().map(|c| cutter.centre_xyz(*v, c)).collect();
            if r.chords != ChordPlacement::OnPath {
                let share =
                    r.chord_tolerance * crate::plan::optimise::CHORD_SHARE * r.chords.sag_factor();
                centres = cutter.place(r.chords, *v, &pts, &centres, share)?;
            }
            line.push(centres);
        }
        if r.zigzag && j % 2 == 1 {
            line.reverse();
            for pass in &mut line {
                pass.reverse();
            }
        }
        passes.extend(line);
    }
    summary.check_tool(cutter.radius)?;

    let top = passes
        .iter()
        .flatten()
        .map(|p| p[2])
        .fold(f64::NEG_INFINITY, f64::max);
    let cut_length = passes
        .iter()
        .flat_map(|p| p.windows(2))
        .map(|w| distance3(w[0], w[1]))
        .sum();
    let pass_lengths = passes
        .iter()
        .map(|p| p.windows(2).map(|w| distance3(w[0], w[1])).sum())
        .collect();
    Ok(RasterPath {
        safe_z: top + r.retract,
        pass_count: passes.len(),
        point_count: passes.iter().map(Vec::len).sum(),
        cut_length,
        pass_lengths,
        max_slope_along: summary.slope_along,
        max_slope_across: summary.slope_across,
        min_concave_radius_along: summary.concave_along,
        passes,
    })
}

/// Most path planes one raster may have.
const MAX_PATHS: usize = 1_000_000;
/// Most tool-centre points one raster may have.
const MAX_POINTS: usize = 5_000_000;
/// Deepest bisection of one pass.
const MAX_DEPTH: u32 = 48;
/// Shortest span (mm) of contacts a plane cuts, a nanometre: shorter ones
/// are a plane touching the aperture's edge, widened by rounding (a tangent
/// touch in f64 gives a chord of about √ε times the radius).
const MIN_SPAN: f64 = 1e-6;
/// Points at which each plane is scanned for its contact spans.
const SCAN: usize = 512;
/// Most planes the pre-plan check (`check_raster`) scans.
const CHECK_PLANES: usize = 1024;
/// Chords are checked against the exact curve at i/PROBES, 0 < i < PROBES.
const PROBES: usize = 8;

fn invalid(name: &'static str, value: f64) -> RasterError {
    RasterError::InvalidParameter { name, value }
}

fn validate_tool(tool: &RasterTool) -> Result<(), RasterError> {
    let (name, value) = match *tool {
        RasterTool::Knife { nose_radius } => ("nose radius", nose_radius),
        RasterTool::Ball { radius } => ("ball radius", radius),
    };
    if !(value > 0.0 && value.is_finite()) {
        return Err(invalid(name, value));
    }
    Ok(())
}

fn validate(r: &Raster, tool: &RasterTool, aperture: &Domain) -> Result<(), RasterError> {
    let positive = |name: &'static str, v: f64| {
        if v > 0.0 && v.is_finite() {
            Ok(())
        } else {
            Err(invalid(name, v))
        }
    };
    positive("stepover", r.stepover)?;
    positive("chord tolerance", r.chord_tolerance)?;
    if let Some(m) = r.max_step {
        positive("max step", m)?;
    }
    if let Some(a) = r.lin_angle {
        positive("Lin step angle", a)?;
        if a > std::f64::consts::PI {
            return Err(invalid("Lin step angle", a));
        }
    }
    if !(r.retract >= 0.0 && r.retract.is_finite()) {
        return Err(invalid("retract", r.retract));
    }
    validate_tool(tool)?;
    match *aperture {
        Domain::Circle { radius } => positive("aperture radius", radius),
        Domain::Annulus { inner, outer } => {
            positive("aperture outer radius", outer)?;
            if inner >= 0.0 && inner < outer {
                Ok(())
            } else {
                Err(invalid("aperture inner radius", inner))
            }
        }
        Domain::Rect { x, y } => {
            positive("aperture x range", x.1 - x.0)?;
            positive("aperture y range", y.1 - y.0)
        }
    }
}

/// (x, y) of the point at u along the cut on the plane at v.
fn xy(along: Axis, u: f64, v: f64) -> (f64, f64) {
    match along {
        Axis::X => (u, v),
        Axis::Y => (v, u),
    }
}

/// The surface and its exact derivatives in path coordinates: u along the
/// cut, v across it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Local {
    z: f64,
    zu: f64,
    zv: f64,
    zuu: f64,
    zuv: f64,
    zvv: f64,
}

impl Local {
    fn at(surface: &dyn SurfaceFn, along: Axis, u: f64, v: f64) -> Local {
        let (x, y) = xy(along, u, v);
        Local::from_outputs(&surface.eval(x, y), along)
    }

    /// The surface's six outputs at a point (`SurfaceFn`'s order) in path
    /// coordinates.
    fn from_outputs(o: &[f64], along: Axis) -> Local {
        match along {
            Axis::X => Local {
                z: o[0],
                zu: o[1],
                zv: o[2],
                zuu: o[3],
                zuv: o[4],
                zvv: o[5],
            },
            Axis::Y => Local {
                z: o[0],
                zu: o[2],
                zv: o[1],
                zuu: o[5],
                zuv: o[4],
                zvv: o[3],
            },
        }
    }

    fn is_finite(&self) -> bool {
        [self.z, self.zu, self.zv, self.zuu, self.zuv, self.zvv]
            .iter()
            .all(|v| v.is_finite())
    }

    /// Curvature (1/mm) of the section along the cut, positive where concave.
    fn curvature_along(&self) -> f64 {
        self.zuu / (1.0 + self.zu * self.zu).powf(1.5)
    }

    /// Curvature (1/mm) of the section across the cut, positive where
    /// concave.
    fn curvature_across(&self) -> f64 {
        self.zvv / (1.0 + self.zv * self.zv).powf(1.5)
    }

    /// Whether `max_principal_curvature` is surely not positive, from
    /// signs alone: the mean curvature is negative and the Gaussian
    /// positive (a convex cap) by a margin far above the rounding of
    /// either, so the curvature as computed is not positive either
    /// (√(h² − k) ≤ |h| when k ≥ 0) and its radius is no concave radius.
    /// Saves the square roots and divisions at every convex contact.
    fn surely_not_concave(&self) -> bool {
        let (e, f, g) = (
            1.0 + self.zu * self.zu,
            self.zu * self.zv,
            1.0 + self.zv * self.zv,
        );
        let (gl, fm, en) = (g * self.zuu, 2.0 * f * self.zuv, e * self.zvv);
        let mean = en - fm + gl;
        let (ln, mm) = (self.zuu * self.zvv, self.zuv * self.zuv);
        let gauss = ln - mm;
        const MARGIN: f64 = 1e-9;
        mean < -MARGIN * (gl.abs() + fm.abs() + en.abs()) && gauss > MARGIN * (ln.abs() + mm)
    }

    /// The larger principal curvature (1/mm), positive where concave.
    fn max_principal_curvature(&self) -> f64 {
        let w2 = 1.0 + self.zu * self.zu + self.zv * self.zv;
        let w = w2.sqrt();
        let (e, f, g) = (
            1.0 + self.zu * self.zu,
            self.zu * self.zv,
            1.0 + self.zv * self.zv,
        );
        let (l, m, n) = (self.zuu / w, self.zuv / w, self.zvv / w);
        let k = (l * n - m * m) / w2;
        let h = (e * n - 2.0 * f * m + g * l) / (2.0 * w2);
        h + (h * h - k).max(0.0).sqrt()
    }
}

/// A contact point (u, v on the part, `l` the surface there) and the tool
/// centre `c` = (u, z) in the path plane.
#[derive(Clone, Copy, Debug)]
struct Contact {
    u: f64,
    v: f64,
    l: Local,
    c: [f64; 2],
}

/// Most Newton steps of one contact solve.
const MAX_STEPS: u32 = 60;
/// Most halvings of one Newton step before the solve gives up.
const MAX_HALVINGS: u32 = 40;
/// Most contacts solved side by side (`Cutter::contacts`): a chord's
/// interior probes.
const MAX_BATCH: usize = PROBES - 1;

/// A contact solve's point: the surface there, g(v), W² and W
/// (`Cutter::newton_at`).
#[derive(Clone, Copy, Debug, Default)]
struct Newton {
    l: Local,
    g: f64,
    w2: f64,
    w: f64,
}

/// One contact solve of `Cutter::contacts`: at t along the cut, v its
/// current guess.
struct Solve {
    t: f64,
    v: f64,
    /// The solve at v (once the surface there is known).
    at: Newton,
    /// Newton steps taken.
    steps: u32,
    stage: Stage,
}

/// Where a contact solve stands.
enum Stage {
    /// Waiting for the surface at its first guess.
    Start,
    /// Waiting for the surface at v + `step`, the Newton step halved
    /// `halvings` times.
    Step { step: f64, halvings: u32 },
    /// Solved: the contact is at t and v, the surface there `at`
    /// (`Cutter::solved`, which works out the tool centre when the
    /// contact is read, long after the surface's values were stored).
    Solved,
    /// Refused, or a contact known before the solve began.
    Done(Result<Contact, RasterError>),
}

impl Solve {
    /// The v at which the solve needs the surface next, if it does.
    fn asks(&self) -> Option<f64> {
        match self.stage {
            Stage::Start => Some(self.v),
            Stage::Step { step, .. } => Some(self.v + step),
            Stage::Solved | Stage::Done(_) => None,
        }
    }
}

/// A chord's probe contacts (`Cutter::too_coarse`), each with the t and
/// guess its solve was given.
#[derive(Clone, Copy)]
struct ProbeSet {
    at: [(f64, f64); PROBES - 1],
    contacts: [Contact; PROBES - 1],
}

impl ProbeSet {
    const EMPTY: ProbeSet = ProbeSet {
        at: [(f64::NAN, f64::NAN); PROBES - 1],
        contacts: [Contact {
            u: f64::NAN,
            v: f64::NAN,
            l: Local {
                z: f64::NAN,
                zu: f64::NAN,
                zv: f64::NAN,
                zuu: f64::NAN,
                zuv: f64::NAN,
                zvv: f64::NAN,
            },
            c: [f64::NAN; 2],
        }; PROBES - 1],
    };

    /// Probe `j`'s contact if it was solved from this very t and guess
    /// (bit for bit: a solve is a function of its plane, t and guess).
    #[inline(always)]
    fn same(&self, j: usize, t: f64, guess: f64) -> Option<Contact> {
        let (pt, pg) = self.at[j];
        (pt.to_bits() == t.to_bits() && pg.to_bits() == guess.to_bits()).then_some(self.contacts[j])
    }
}

/// Which half of a split chord.
#[derive(Clone, Copy)]
enum Half {
    First,
    Second,
}

/// One point of a ball plane's scan.
enum Probe {
    /// The contact lies in the reach (the aperture grown to cut its rim).
    In(Contact),
    /// The contact lies outside it.
    Out,
    /// The contact failed outside the aperture: the surface has no
    /// continuation there to cut the rim with.
    Lost,
    /// No contact was found.
    Fail(RasterError),
}

struct Cutter<'a> {
    surface: &'a dyn SurfaceFn,
    along: Axis,
    radius: f64,
    ball: bool,
    /// Whether a split chord's halves take their parent's probes
    /// (`too_coarse`); off only in the test that holds it to solving
    /// every probe.
    reuse_probes: bool,
}

impl<'a> Cutter<'a> {
    fn new(tool: &RasterTool, surface: &'a dyn SurfaceFn, along: Axis) -> Cutter<'a> {
        Cutter {
            surface,
            along,
            radius: tool.radius(),
            ball: matches!(tool, RasterTool::Ball { .. }),
            reuse_probes: true,
        }
    }

    fn error_at(&self, u: f64, v: f64, no_contact: bool) -> RasterError {
        let (x, y) = xy(self.along, u, v);
        if no_contact {
            RasterError::NoContact { x, y }
        } else {
            RasterError::Undefined { x, y }
        }
    }

    fn centre_xyz(&self, plane: f64, c: &Contact) -> [f64; 3] {
        let (x, y) = xy(self.along, c.c[0], plane);
        [x, y, c.c[1]]
    }

    /// The contact at `t` along the cut for the plane at `plane`; `guess`
    /// starts the solve for the contact's v.
    fn contact(&self, plane: f64, t: f64, guess: f64) -> Result<Contact, RasterError> {
        let [c] = self.contacts(plane, [(t, guess)]);
        c
    }

    /// The contacts at each (t, guess) of `at` for the plane at `plane`,
    /// each solved as `contact` solves it alone (the same points asked
    /// for, in the same order, so the same contact to the last bit), the
    /// solves taking their steps side by side: every round asks the
    /// surface for one point of each unfinished solve in one batch, and
    /// the solves' chains of square roots and divisions overlap.
    fn contacts<const N: usize>(
        &self,
        plane: f64,
        at: [(f64, f64); N],
    ) -> [Result<Contact, RasterError>; N] {
        let solves = at.map(|(t, guess)| Solve {
            t,
            v: if guess.is_finite() { guess } else { plane },
            at: Newton::default(),
            steps: 0,
            stage: Stage::Start,
        });
        self.solve_side_by_side(plane, solves)
    }

    /// Runs `solves` to their ends side by side (`contacts`).
    #[inline(always)]
    fn solve_side_by_side<const N: usize>(
        &self,
        plane: f64,
        mut solves: [Solve; N],
    ) -> [Result<Contact, RasterError>; N] {
        self.run_side_by_side(plane, &mut solves);
        solves.map(|s| match s.stage {
            Stage::Solved => Ok(self.solved(&s)),
            Stage::Done(c) => c,
            _ => unreachable!("a solve asks for points until it is done"),
        })
    }

    /// Runs `solves` to their ends side by side, in place (each then
    /// `Stage::Solved` or `Stage::Done`).
    #[inline(always)]
    fn run_side_by_side<const N: usize>(&self, plane: f64, solves: &mut [Solve; N]) {
        const { assert!(N <= MAX_BATCH, "a batch of contacts fits the buffers") };
        // Buffers of the batch's own size: one contact (most calls) zeroes
        // 9 words, not 63 (a memset that was a tenth of `lensc check`'s
        // time on seed 000's rasters).
        let (mut xs, mut ys) = ([0.0; N], [0.0; N]);
        let mut out = [[0.0; 6]; N];
        let out = out.as_flattened_mut();
        let mut asked = [0; N];
        loop {
            let mut k = 0;
            for (i, s) in solves.iter().enumerate() {
                if let Some(v) = s.asks() {
                    (xs[k], ys[k]) = xy(self.along, s.t, v);
                    asked[k] = i;
                    k += 1;
                }
            }
            if k == 0 {
                break;
            }
            self.surface
                .eval_batch(&xs[..k], &ys[..k], &mut out[..6 * k]);
            for (j, o) in out[..6 * k].chunks_exact(6).enumerate() {
                let l = Local::from_outputs(o, self.along);
                self.advance(plane, &mut solves[asked[j]], l);
            }
        }
    }

    /// The slope along the cut that tilts the tool's normal: the ball's
    /// contact normal is the surface's; the knife's edge, across the cut,
    /// sees only the cross-section (its normal in the plane u = t).
    fn lean(&self, l: &Local) -> f64 {
        if self.ball { l.zu } else { 0.0 }
    }

    /// The solve's function at v (the surface `l` there): g(v) = v −
    /// ρ z_v/W − plane, zero where the centre's v is on the plane, W =
    /// √(1 + z_u² + z_v²) (z_u = 0 for the knife); with W² and W.
    fn newton_at(&self, plane: f64, v: f64, l: Local) -> Newton {
        let zu = self.lean(&l);
        let w2 = 1.0 + zu * zu + l.zv * l.zv;
        let w = w2.sqrt();
        Newton {
            l,
            g: v - self.radius * l.zv / w - plane,
            w2,
            w,
        }
    }

    /// Takes the surface `l` at the point solve `s` asked for, and moves
    /// the solve on: damped Newton for v with g(v) = 0 (`newton_at`),
    /// g'(v) = 1 − ρ ∂(z_v/W)/∂v, each step halved until |g| falls.
    #[inline(always)]
    fn advance(&self, plane: f64, s: &mut Solve, l: Local) {
        match s.stage {
            Stage::Start => {
                if !l.is_finite() {
                    s.stage = Stage::Done(Err(self.error_at(s.t, s.v, false)));
                    return;
                }
                s.at = self.newton_at(plane, s.v, l);
                self.step(plane, s);
            }
            Stage::Step { step, halvings } => {
                let vn = s.v + step;
                if l.is_finite() {
                    let next = self.newton_at(plane, vn, l);
                    if next.g.abs() < s.at.g.abs() {
                        (s.v, s.at) = (vn, next);
                        s.steps += 1;
                        self.step(plane, s);
                        return;
                    }
                }
                if halvings + 1 < MAX_HALVINGS {
                    s.stage = Stage::Step {
                        step: step * 0.5,
                        halvings: halvings + 1,
                    };
                } else {
                    self.conclude(plane, s);
                }
            }
            Stage::Solved | Stage::Done(_) => {}
        }
    }

    /// The next Newton step of solve `s` from where it is, or its end:
    /// converged, out of steps, or its plane's offset folding over.
    #[inline(always)]
    fn step(&self, plane: f64, s: &mut Solve) {
        let rho = self.radius;
        let scale = 1.0 + plane.abs() + rho;
        let Newton { l, g, w2, w } = s.at;
        if s.steps == MAX_STEPS || g.abs() <= 1e-16 * scale {
            return self.conclude(plane, s);
        }
        let jac = self.plane_rate(&l, w2, w);
        if jac.is_nan() || jac <= 0.0 {
            // The plane's offset folds over: the tool is too large for
            // the hollow here, or no contact lies on this plane.
            let min_radius = self.limiting_radius(&l);
            s.stage = Stage::Done(Err(if min_radius > 0.0 && rho > min_radius {
                let (x, y) = xy(self.along, s.t, s.v);
                RasterError::ToolTooLarge {
                    tool_radius: rho,
                    min_radius,
                    x,
                    y,
                }
            } else {
                self.error_at(s.t, s.v, true)
            }));
            return;
        }
        s.stage = Stage::Step {
            step: -g / jac,
            halvings: 0,
        };
    }

    /// g'(v) = 1 − ρ ∂(z_v/W)/∂v at the surface `l` (W² `w2`, W `w`):
    /// how fast the tool centre's v moves with its contact's v across the
    /// cut, the Newton solve's slope.
    #[inline(always)]
    fn plane_rate(&self, l: &Local, w2: f64, w: f64) -> f64 {
        let zu = self.lean(l);
        let dq = l.zvv / w - l.zv * (zu * l.zuv + l.zv * l.zvv) / (w2 * w);
        1.0 - self.radius * dq
    }

    /// How many stepovers apart the contacts of neighbouring planes lie
    /// at a contact with the surface `l` there: 1/g'(v) (`plane_rate`),
    /// below 1 where the section across the cut is convex, above 1 where
    /// it is concave, infinite where the offset folds over.
    fn spread(&self, l: &Local) -> f64 {
        let zu = self.lean(l);
        let w2 = 1.0 + zu * zu + l.zv * l.zv;
        let rate = self.plane_rate(l, w2, w2.sqrt());
        if rate > 0.0 {
            1.0 / rate
        } else {
            f64::INFINITY
        }
    }

    /// The end solve `s` has reached: solved, or why there is no contact.
    fn conclude(&self, plane: f64, s: &mut Solve) {
        let scale = 1.0 + plane.abs() + self.radius;
        let g = s.at.g;
        s.stage = if g.is_nan() || g.abs() > 1e-13 * scale {
            Stage::Done(Err(self.error_at(s.t, s.v, true)))
        } else {
            Stage::Solved
        };
    }

    /// The contact of a solve that has ended `Stage::Solved`: at its t and
    /// v, the tool centre offset along the normal there.
    #[inline(always)]
    fn solved(&self, s: &Solve) -> Contact {
        let rho = self.radius;
        let Newton { l, w, .. } = s.at;
        Contact {
            u: s.t,
            v: s.v,
            l,
            c: [s.t - rho * self.lean(&l) / w, l.z + rho / w],
        }
    }

    /// Where the surface stops being defined on the plane at v, between
    /// `ok` (defined, if a defined point was seen) and `bad` (undefined), by
    /// bisection: the point a diagnostic names.
    fn edge_of_definition(&self, v: f64, ok: Option<f64>, mut bad: f64) -> RasterError {
        let defined = |t: f64| Local::at(self.surface, self.along, t, v).is_finite();
        if let Some(mut ok) = ok {
            for _ in 0..64 {
                let mid = 0.5 * (ok + bad);
                if mid == ok || mid == bad {
                    break;
                }
                if defined(mid) {
                    ok = mid;
                } else {
                    bad = mid;
                }
            }
        }
        self.error_at(bad, v, false)
    }

    /// The smallest concave radius (mm) the tool must fit at a contact:
    /// the cross-section's for the knife (its edge), the smaller principal
    /// radius for the ball; infinite or negative where nothing is concave.
    fn limiting_radius(&self, l: &Local) -> f64 {
        if self.ball {
            1.0 / l.max_principal_curvature()
        } else {
            1.0 / l.curvature_across()
        }
    }

    /// The spans of the plane at v: runs of contact positions whose contact
    /// point lies in `reach` (the aperture grown to cut its rim), their
    /// ends refined to its edge. Where a contact fails beyond the aperture
    /// on this plane (a surface undefined there, a tool that finds no
    /// contact), the surface has no continuation to cut the rim with, and
    /// the plane's contacts are taken in the aperture only, as far as its
    /// edge: the contacts next to a failure would be sampled where the
    /// solve is ill-conditioned (a conic near its root, its slope
    /// unbounded).
    fn spans(
        &self,
        aperture: &Domain,
        reach: &Domain,
        v: f64,
        (u0, u1): (f64, f64),
        summary: &mut Summary,
    ) -> Result<Vec<(Contact, Contact)>, RasterError> {
        match self.spans_in(aperture, reach, v, (u0, u1), summary)? {
            Some(spans) => Ok(spans),
            None => Ok(self
                .spans_in(aperture, aperture, v, (u0, u1), summary)?
                .unwrap_or_default()),
        }
    }

    /// `spans` with contacts taken as far as `reach`; `None` if a contact
    /// beyond the aperture failed and `reach` is larger than the aperture.
    fn spans_in(
        &self,
        aperture: &Domain,
        reach: &Domain,
        v: f64,
        (u0, u1): (f64, f64),
        summary: &mut Summary,
    ) -> Result<Option<Vec<(Contact, Contact)>>, RasterError> {
        // The ball's centre is up to a radius along the cut from its
        // contact; the knife's is at the contact's u.
        let margin = if self.ball { self.radius } else { 0.0 };
        let ((rx0, rx1), (ry0, ry1)) = reach.bounds();
        let (ru0, ru1) = match self.along {
            Axis::X => (rx0, rx1),
            Axis::Y => (ry0, ry1),
        };
        let (a, b) = (u0.min(ru0) - margin, u1.max(ru1) + margin);
        let at = |i: usize| a + (b - a) * i as f64 / SCAN as f64;
        let inside = |c: &Contact| {
            let (x, y) = xy(self.along, c.u, c.v);
            reach.contains(x, y)
        };
        let grown = reach != aperture;
        let scan = self.probe_plane(aperture, reach, v, &at, &inside)?;
        if grown && scan.iter().any(|p| matches!(p, Probe::Lost)) {
            return Ok(None);
        }
        let scan: Vec<Option<Contact>> = scan
            .into_iter()
            .map(|p| match p {
                Probe::In(c) => Some(c),
                _ => None,
            })
            .collect();
        // Moves from an inside contact towards an outside position until
        // the contact sits on the edge of the reach; a contact that fails
        // on the way counts as outside, and is noted.
        let lost = std::cell::Cell::new(false);
        let refine = |mut c_in: Contact, mut t_out: f64| {
            for _ in 0..64 {
                let mid = 0.5 * (c_in.u + t_out);
                if mid == c_in.u || mid == t_out {
                    break;
                }
                match self.contact(v, mid, c_in.v) {
                    Ok(c) if inside(&c) => c_in = c,
                    Ok(_) => t_out = mid,
                    Err(e) => {
                        let in_reach = |(x, y): (f64, f64)| reach.contains(x, y);
                        if e.place().is_none_or(in_reach) {
                            lost.set(true);
                        }
                        t_out = mid;
                    }
                }
            }
            c_in
        };
        let in_aperture = |c: &Contact| {
            let (x, y) = xy(self.along, c.u, c.v);
            aperture.contains(x, y)
        };
        // The contact on the aperture's edge between two contacts of the
        // plane, one in the aperture and one out of it, by bisection.
        let on_edge = |p: &Contact, q: &Contact| {
            let (mut c_in, mut t_out) = if in_aperture(p) { (*p, q.u) } else { (*q, p.u) };
            for _ in 0..64 {
                let mid = 0.5 * (c_in.u + t_out);
                if mid == c_in.u || mid == t_out {
                    break;
                }
                match self.contact(v, mid, c_in.v) {
                    Ok(c) if in_aperture(&c) => c_in = c,
                    _ => t_out = mid,
                }
            }
            c_in
        };
        let mut spans = Vec::new();
        let mut i = 0;
        while i <= SCAN {
            let Some(first) = scan[i] else {
                i += 1;
                continue;
            };
            let mut j = i;
            while j < SCAN && scan[j + 1].is_some() {
                j += 1;
            }
            for c in scan[i..=j].iter().flatten() {
                summary.see(c, self);
                summary.see_spread(c, self);
            }
            let start = if i > 0 {
                refine(first, at(i - 1))
            } else {
                first
            };
            let last = scan[j].unwrap_or(first);
            let end = if j < SCAN {
                refine(last, at(j + 1))
            } else {
                last
            };
            summary.see(&start, self);
            summary.see(&end, self);
            if grown {
                // The figures are the aperture's own: where the span
                // crosses the aperture's edge, the contact on the edge is
                // seen too (a convex lens is steepest there).
                let run: Vec<Contact> = std::iter::once(start)
                    .chain(scan[i..=j].iter().flatten().copied())
                    .chain(std::iter::once(end))
                    .collect();
                for w in run.windows(2) {
                    if in_aperture(&w[0]) != in_aperture(&w[1]) {
                        summary.see(&on_edge(&w[0], &w[1]), self);
                    }
                }
            }
            // A plane that only grazes the aperture (its contacts meeting
            // the edge at one point, to rounding) has nothing to cut.
            if end.u - start.u > MIN_SPAN {
                spans.push((start, end));
            }
            i = j + 1;
        }
        if grown && lost.get() {
            return Ok(None);
        }
        Ok(Some(spans))
    }

    /// The contact at each of the `SCAN + 1` positions `at(i)` of the
    /// plane at v: `In` where `inside` holds (in `reach`), `Out` outside
    /// (or failed outside `reach`), `Lost` where it failed in `reach` but
    /// outside the aperture, `Fail` where it failed elsewhere; or the
    /// error that stops the plane.
    fn probe_plane(
        &self,
        aperture: &Domain,
        reach: &Domain,
        v: f64,
        at: &dyn Fn(usize) -> f64,
        inside: &dyn Fn(&Contact) -> bool,
    ) -> Result<Vec<Probe>, RasterError> {
        // The surface must be defined wherever the plane crosses the
        // aperture. A tool whose solve fails has no contact on this plane
        // there (its contact would lie off the surface's domain) unless the
        // tool is too large for the hollow inside the aperture.
        let mut scan: Vec<Probe> = Vec::with_capacity(SCAN + 1);
        let mut guess = v;
        for i in 0..=SCAN {
            let t = at(i);
            let (x, y) = xy(self.along, t, v);
            if aperture.contains(x, y) && !Local::at(self.surface, self.along, t, v).is_finite() {
                // The edge of definition lies between this point and the
                // defined scan point next to it (before it, or else the
                // first one after it).
                let defined = |t: f64| Local::at(self.surface, self.along, t, v).is_finite();
                let ok = if i > 0 && defined(at(i - 1)) {
                    Some(at(i - 1))
                } else {
                    (i + 1..=SCAN).map(at).find(|&t| defined(t))
                };
                return Err(self.edge_of_definition(v, ok, t));
            }
            let probe = match self.contact(v, t, guess) {
                Ok(c) if inside(&c) => Probe::In(c),
                Ok(_) => Probe::Out,
                Err(RasterError::ToolTooLarge {
                    tool_radius,
                    min_radius,
                    x,
                    y,
                }) if aperture.contains(x, y) => {
                    return Err(RasterError::ToolTooLarge {
                        tool_radius,
                        min_radius,
                        x,
                        y,
                    });
                }
                // A contact that fails outside the aperture (a surface
                // undefined beyond it, a tool too large for it there) is
                // not an error: outside the reach it is a contact outside;
                // in it, the rim's continuation is lost, and the plane
                // then cuts as far as the aperture's edge only (`spans`).
                Err(e) => match e.place() {
                    Some((x, y)) if !aperture.contains(x, y) => {
                        if reach.contains(x, y) {
                            Probe::Lost
                        } else {
                            Probe::Out
                        }
                    }
                    _ => Probe::Fail(e),
                },
            };
            guess = match probe {
                Probe::In(c) => c.v,
                _ => v,
            };
            scan.push(probe);
        }
        // A failed solve between contacts inside the aperture would leave
        // a gap in the cut.
        for (i, p) in scan.iter().enumerate() {
            if let Probe::Fail(e) = p {
                let solved = |p: &&Probe| !matches!(p, Probe::Fail(_));
                let before = scan[..i].iter().rev().find(solved);
                let after = scan[i + 1..].iter().find(solved);
                if let (Some(Probe::In(_)), Some(Probe::In(_))) = (before, after) {
                    return Err(e.clone());
                }
            }
        }
        Ok(scan)
    }

    /// The centres `centres` of the pass's contacts `pts` on the plane at
    /// `plane`, moved along Z by `placement`'s offset for the bands of the
    /// chords each joins (`plan::chords`): the exact centre path's height
    /// above each chord at the centres of the contacts a quarter, half and
    /// three quarters of the way along it. Straddling, every chord is held
    /// within half the chords' share `share`, chords split where that takes
    /// more points.
    fn place(
        &self,
        placement: ChordPlacement,
        plane: f64,
        pts: &[Contact],
        centres: &[[f64; 3]],
        share: f64,
    ) -> Result<Vec<[f64; 3]>, RasterError> {
        if placement.straddles() {
            let knots: Vec<chords::Knot> = pts
                .iter()
                .map(|c| chords::Knot {
                    s: c.u,
                    u: c.c[0],
                    z: c.c[1],
                })
                .collect();
            let mut guess = pts.first().map_or(plane, |c| c.v);
            let mut failed = None;
            let mut exact = |s: f64| match self.contact(plane, s, guess) {
                Ok(q) => {
                    guess = q.v;
                    (q.c[0], q.c[1])
                }
                Err(e) => {
                    failed.get_or_insert(e);
                    (f64::NAN, f64::NAN)
                }
            };
            let (knots, _) =
                chords::straddle(&knots, (None, None), 0.5 * share, &mut exact, &|_, _| true);
            if let Some(e) = failed {
                return Err(e);
            }
            return Ok(knots
                .iter()
                .map(|k| {
                    let (x, y) = xy(self.along, k.u, plane);
                    [x, y, k.z]
                })
                .collect());
        }
        let mut bands = Vec::with_capacity(pts.len().saturating_sub(1));
        for w in pts.windows(2) {
            let (c0, c1) = (&w[0], &w[1]);
            let mut inner = [(0.0, 0.0); 3];
            for (k, f) in [0.25, 0.5, 0.75].into_iter().enumerate() {
                let q = self.contact(plane, c0.u + f * (c1.u - c0.u), c0.v + f * (c1.v - c0.v))?;
                inner[k] = (q.c[0], q.c[1]);
            }
            bands.push(Band::between((c0.c[0], c0.c[1]), (c1.c[0], c1.c[1]), inner));
        }
        let mut graph: Vec<(f64, f64)> = pts.iter().map(|c| (c.c[0], c.c[1])).collect();
        chords::place_graph(placement, &mut graph, &bands);
        Ok(centres
            .iter()
            .zip(graph)
            .map(|(c, (_, z))| [c[0], c[1], z])
            .collect())
    }

    /// The contacts of one pass from `a` to `b` (increasing u): bisection
    /// until every chord between consecutive centres meets the tolerance and
    /// the step caps.
    fn sample(
        &self,
        r: &Raster,
        plane: f64,
        a: Contact,
        b: Contact,
        budget: &mut usize,
        summary: &mut Summary,
    ) -> Result<Vec<Contact>, RasterError> {
        let mut out = vec![a];
        // The probes of every chord split so far: a half's probes at 2/8,
        // 4/8 and 6/8 may be its parent's (`Halves`).
        let mut split: Vec<ProbeSet> = Vec::new();
        let mut probes = ProbeSet::EMPTY;
        let mut stack = vec![(a, b, 0u32, None)];
        while let Some((c0, c1, depth, parent)) = stack.pop() {
            let parent = parent
                .filter(|_| self.reuse_probes)
                .map(|(k, side)| (&split[k], side));
            let (coarse, probed) =
                self.too_coarse(r, plane, (&c0, &c1), parent, &mut probes, summary)?;
            if coarse {
                if depth >= MAX_DEPTH {
                    let (x, y) = xy(self.along, c0.u, c0.v);
                    return Err(RasterError::ToleranceUnreachable {
                        x,
                        y,
                        tolerance: r.chord_tolerance,
                    });
                }
                let (t, guess) = (0.5 * (c0.u + c1.u), 0.5 * (c0.v + c1.v));
                // The chord's middle probe, if it was asked for at this
                // very t and guess, is this contact.
                let reused = probed && self.reuse_probes;
                let mid = match reused.then(|| probes.same(PROBES / 2 - 1, t, guess)) {
                    Some(Some(c)) => c,
                    _ => {
                        let mid = self.contact(plane, t, guess)?;
                        summary.see(&mid, self);
                        mid
                    }
                };
                let halves = probed.then(|| {
                    split.push(probes);
                    split.len() - 1
                });
                stack.push((mid, c1, depth + 1, halves.map(|k| (k, Half::Second))));
                stack.push((c0, mid, depth + 1, halves.map(|k| (k, Half::First))));
            } else {
                if *budget == 0 {
                    return Err(RasterError::TooManyPoints { limit: MAX_POINTS });
                }
                *budget -= 1;
                out.push(c1);
            }
        }
        Ok(out)
    }

    /// Whether the chord from c0 to c1 must be split: longer than the step
    /// caps, or straying more than the tolerance from the exact curve
    /// (probed at PROBES − 1 interior points, the peak estimated by a
    /// parabola through the largest probe and its neighbours).
    /// Its probes, with their t and guesses, are left in `set` (and
    /// whether it was probed comes back with the decision: not when a
    /// step cap decided it); `parent`, the probes of the
    /// chord this is a half of, gives the contacts asked for again at
    /// the same t and guess (the half's probes at 2/8, 4/8 and 6/8 fall
    /// on its parent's, often to the last bit) without solving them
    /// again: the same contacts, so the same decision.
    fn too_coarse(
        &self,
        r: &Raster,
        plane: f64,
        (c0, c1): (&Contact, &Contact),
        parent: Option<(&ProbeSet, Half)>,
        set: &mut ProbeSet,
        summary: &mut Summary,
    ) -> Result<(bool, bool), RasterError> {
        let (p0, p1) = (c0.c, c1.c);
        if let Some(m) = r.max_step
            && distance2(p0, p1) > m
        {
            return Ok((true, false));
        }
        if let Some(alpha) = r.lin_angle {
            let cap = |c: &Contact| lin_step(section_radius(c.l.zu, c.l.zuu), alpha, c.l.zu);
            if (c1.u - c0.u).abs() > cap(c0).min(cap(c1)) {
                return Ok((true, false));
            }
        }
        let mut probes = [[0.0; 2]; PROBES + 1];
        let mut quick = [0.0; PROBES + 1];
        let at: [(f64, f64); PROBES - 1] = std::array::from_fn(|k| {
            let s = (k + 1) as f64 / PROBES as f64;
            (c0.u + s * (c1.u - c0.u), c0.v + s * (c1.v - c0.v))
        });
        // Probe k + 1 at (k + 1)/8 of a half is at (k + 1)/16 of its
        // parent: the parent's probe (k + 1)/2 − 1 for the first half,
        // 3 + (k + 1)/2 for the second, when k + 1 is even.
        let mut known = 0u8;
        let mut solves: [Solve; PROBES - 1] = std::array::from_fn(|k| {
            let (t, guess) = at[k];
            // Probe p = k + 1, at p/8 of the half.
            let p = k + 1;
            let j = match parent {
                Some((_, Half::First)) if p % 2 == 0 => Some(p / 2 - 1),
                Some((_, Half::Second)) if p % 2 == 0 => Some(PROBES / 2 - 1 + p / 2),
                _ => None,
            };
            let stage = match parent.zip(j).and_then(|((p, _), j)| p.same(j, t, guess)) {
                Some(c) => {
                    known |= 1 << k;
                    Stage::Done(Ok(c))
                }
                None => Stage::Start,
            };
            Solve {
                t,
                v: if guess.is_finite() { guess } else { plane },
                at: Newton::default(),
                steps: 0,
                stage,
            }
        });
        set.at = at;
        self.run_side_by_side(plane, &mut solves);
        for (i, s) in (1..PROBES).zip(&solves) {
            let q = match &s.stage {
                Stage::Solved => self.solved(s),
                Stage::Done(Ok(q)) => *q,
                Stage::Done(Err(e)) => return Err(e.clone()),
                _ => unreachable!("a solve asks for points until it is done"),
            };
            // A contact known from the parent has been seen already.
            if known & 1 << (i - 1) == 0 {
                summary.see(&q, self);
            }
            set.contacts[i - 1] = q;
            probes[i] = q.c;
        }
        // The probes' distances from the chord, in a loop of their own:
        // its divisions and square roots overlap.
        for (q, d) in probes[1..PROBES].iter().zip(&mut quick[1..PROBES]) {
            let f = foot_on_segment(*q, p0, p1);
            *d = ((f[0] - q[0]).powi(2) + (f[1] - q[1]).powi(2)).sqrt();
        }
        let limit = r.chord_tolerance * crate::plan::optimise::CHORD_SHARE * r.chords.sag_factor();
        // The distances by √(dx² + dy²), within a few ulps of `hypot`'s,
        // settle almost every chord; one those ulps could turn is measured
        // again with `hypot`, so each decision is the one its distances give.
        if let Some(split) = clear_decision(&quick, limit) {
            return Ok((split, true));
        }
        let mut d = [0.0; PROBES + 1];
        for i in 1..PROBES {
            d[i] = distance_to_segment(probes[i], p0, p1);
        }
        Ok((chord_peak(&d) > limit, true))
    }
}

/// The chord's largest distance from the curve, estimated from its probes'
/// distances `d` (the ends' zero): the peak of the parabola through the
/// largest and its neighbours, or the largest itself.
fn chord_peak(d: &[f64; PROBES + 1]) -> f64 {
    let m = (1..PROBES)
        .max_by(|&i, &j| d[i].total_cmp(&d[j]))
        .unwrap_or(1);
    let (lo, mid, hi) = (d[m - 1], d[m], d[m + 1]);
    let bend = 2.0 * mid - lo - hi;
    let peak = if bend > 0.0 {
        mid + (hi - lo) * (hi - lo) / (8.0 * bend)
    } else {
        mid
    };
    peak.max(mid)
}

/// Whether `chord_peak` of the probes' distances exceeds `limit`, decided
/// from distances `d` each within a relative `SLACK` of them (its own
/// rounding included), or `None` if that slack could turn the decision:
/// the largest above the limit by a margin splits the chord; a peak
/// bounded below it (by interval arithmetic on the parabola, the largest
/// probe clear of the others) keeps it.
fn clear_decision(d: &[f64; PROBES + 1], limit: f64) -> Option<bool> {
    const SLACK: f64 = 1e-14;
    const MARGIN: f64 = 1e-9;
    let inner = &d[1..PROBES];
    // Squares that underflow lose the relative bound.
    if inner.iter().any(|&x| !(x >= 1e-150 && x.is_finite())) {
        return None;
    }
    let m = (1..PROBES)
        .max_by(|&i, &j| d[i].total_cmp(&d[j]))
        .unwrap_or(1);
    let top = d[m];
    if top > limit * (1.0 + MARGIN) {
        return Some(true);
    }
    if (1..PROBES).any(|i| i != m && d[i] >= top * (1.0 - 4.0 * SLACK)) {
        return None;
    }
    let up = |x: f64| x * (1.0 + SLACK);
    let down = |x: f64| x * (1.0 - SLACK);
    let (lo, mid, hi) = (d[m - 1], d[m], d[m + 1]);
    let bend_min = 2.0 * down(mid) - up(lo) - up(hi);
    let bend_max = 2.0 * up(mid) - down(lo) - down(hi);
    let peak_max = if bend_max <= 0.0 {
        up(mid)
    } else if bend_min > 0.0 {
        let rise = (hi - lo).abs() + SLACK * (hi + lo);
        up(mid) + rise * rise / (8.0 * bend_min)
    } else {
        return None;
    };
    (peak_max * (1.0 + MARGIN) < limit).then_some(false)
}

/// Figures gathered over every contact point the planner evaluates.
struct Summary {
    along: Axis,
    slope_along: Extremum,
    slope_across: Extremum,
    concave_along: Option<Extremum>,
    /// The smallest concave radius the tool must fit (across the cut for
    /// the knife, principal for the ball).
    tool_limit: Option<Extremum>,
    /// |z_u| and |z_v| at the steepest contacts so far: a contact no
    /// steeper cannot have a larger slope (atan is monotonic), so its
    /// arctangent is never taken (most contacts' are not).
    steepest: [f64; 2],
    /// The aperture whose figures these are: contacts the planes take
    /// beyond it (to cut its rim) are not counted.
    aperture: Option<Domain>,
    /// The largest spread (`Cutter::spread`) at the planes' scanned
    /// contacts in the aperture (1 if none is above 1).
    spread: f64,
    /// How many of the raster's planes each scanned plane stands for: 1
    /// when every plane is scanned (`sampled`).
    weight: f64,
}

impl Summary {
    fn new(along: Axis) -> Summary {
        let zero = Extremum {
            value: 0.0,
            x: f64::NAN,
            y: f64::NAN,
        };
        Summary {
            along,
            slope_along: zero,
            slope_across: zero,
            concave_along: None,
            tool_limit: None,
            steepest: [f64::NEG_INFINITY; 2],
            aperture: None,
            spread: 1.0,
            weight: 1.0,
        }
    }

    /// A summary of the contacts inside `aperture` only.
    fn within(along: Axis, aperture: Domain) -> Summary {
        Summary {
            aperture: Some(aperture),
            ..Summary::new(along)
        }
    }

    fn see(&mut self, c: &Contact, cutter: &Cutter) {
        let (x, y) = xy(self.along, c.u, c.v);
        if self.aperture.is_some_and(|a| !a.contains(x, y)) {
            return;
        }
        let at = |value: f64| Extremum { value, x, y };
        for (k, (slope, extremum)) in [
            (c.l.zu.abs(), &mut self.slope_along),
            (c.l.zv.abs(), &mut self.slope_across),
        ]
        .into_iter()
        .enumerate()
        {
            // atan(s) > atan(steepest) only if s > steepest.
            if slope > self.steepest[k] || extremum.x.is_nan() {
                let angle = slope.atan();
                if angle > extremum.value || extremum.x.is_nan() {
                    *extremum = at(angle);
                    self.steepest[k] = slope;
                }
            }
        }
        let smaller = |old: &Option<Extremum>, radius: f64| {
            radius.is_finite() && radius > 0.0 && old.is_none_or(|e| radius < e.value)
        };
        // A radius is positive only where the section curves towards the
        // tool (its second derivative positive): elsewhere its power and
        // division are not worked out.
        if c.l.zuu > 0.0 {
            let r_along = 1.0 / c.l.curvature_along();
            if smaller(&self.concave_along, r_along) {
                self.concave_along = Some(at(r_along));
            }
        }
        let concave = if cutter.ball {
            !c.l.surely_not_concave()
        } else {
            c.l.zvv > 0.0
        };
        if concave {
            let r_tool = cutter.limiting_radius(&c.l);
            if smaller(&self.tool_limit, r_tool) {
                self.tool_limit = Some(at(r_tool));
            }
        }
    }

    /// Takes the spread at a contact of a plane's scan (`Cutter::spread`)
    /// into `spread`, if the contact lies in the aperture.
    fn see_spread(&mut self, c: &Contact, cutter: &Cutter) {
        let (x, y) = xy(self.along, c.u, c.v);
        if self.aperture.is_none_or(|a| a.contains(x, y)) {
            self.spread = self.spread.max(cutter.spread(&c.l));
        }
    }

    fn check_tool(&self, tool_radius: f64) -> Result<(), RasterError> {
        match self.tool_limit {
            Some(e) if tool_radius > e.value => Err(RasterError::ToolTooLarge {
                tool_radius,
                min_radius: e.value,
                x: e.x,
                y: e.y,
            }),
            _ => Ok(()),
        }
    }
}

fn distance2(a: [f64; 2], b: [f64; 2]) -> f64 {
    (b[0] - a[0]).hypot(b[1] - a[1])
}

fn distance3(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2) + (b[2] - a[2]).powi(2)).sqrt()
}

fn distance_to_segment(q: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    distance2(q, foot_on_segment(q, a, b))
}

/// The point of the segment from a to b nearest to q.
fn foot_on_segment(q: [f64; 2], a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    let ab = [b[0] - a[0], b[1] - a[1]];
    let aq = [q[0] - a[0], q[1] - a[1]];
    let len2 = ab[0] * ab[0] + ab[1] * ab[1];
    if len2 == 0.0 {
        return a;
    }
    let t = ((aq[0] * ab[0] + aq[1] * ab[1]) / len2).clamp(0.0, 1.0);
    [a[0] + t * ab[0], a[1] + t * ab[1]]
}

#[cfg(test)]
mod tests;
