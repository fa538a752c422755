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
//! ends where the contact point reaches the aperture edge. Lin's
//! approximate compensations (eq 4, eqs 5–6) are provided as functions to
//! compare against; the planner itself does not use them.
//!
//! Units: mm and rad. +z points out of the material, towards the tool.

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

/// Plans the raster over `aperture`: path planes at v0 + k·stepover (v is y
/// when cutting along x), each pass running between the points where the
/// contact point meets the aperture edge.
pub fn plan_raster(
    r: &Raster,
    tool: &RasterTool,
    surface: &dyn SurfaceFn,
    aperture: &Domain,
) -> Result<RasterPath, RasterError> {
    validate(r, tool, aperture)?;
    let cutter = Cutter::new(tool, surface, r.along);
    let ((x0, x1), (y0, y1)) = aperture.bounds();
    let ((u0, u1), (v0, v1)) = match r.along {
        Axis::X => ((x0, x1), (y0, y1)),
        Axis::Y => ((y0, y1), (x0, x1)),
    };
    // The contact lies off its plane by up to the tool's radius, so the
    // planes reach a radius beyond the aperture on either side.
    let last = ((v1 - v0) / r.stepover + 1e-9).floor();
    let extra = (cutter.radius / r.stepover).ceil();
    let paths = last + 1.0 + 2.0 * extra;
    if paths > MAX_PATHS as f64 {
        return Err(RasterError::TooManyPaths {
            paths,
            limit: MAX_PATHS,
        });
    }
    let (last, extra) = (last as i64, extra as i64);

    // Phase 1: where each plane cuts, with the surface checked there.
    let mut summary = Summary::new(r.along);
    let mut lines = Vec::new();
    for k in -extra..=last + extra {
        let mut v = v0 + k as f64 * r.stepover;
        if k == last {
            v = v.min(v1);
        }
        let spans = cutter.spans(aperture, v, (u0, u1), &mut summary)?;
        if !spans.is_empty() {
            lines.push((v, spans));
        }
    }
    if lines.is_empty() {
        return Err(RasterError::NothingToCut);
    }
    summary.check_tool(cutter.radius)?;

    // Phase 2: the exact centres of each pass, chord by chord.
    let mut budget = MAX_POINTS;
    let mut passes = Vec::new();
    for (j, (v, spans)) in lines.iter().enumerate() {
        let mut line = Vec::with_capacity(spans.len());
        for &(a, b) in spans {
            let pts = cutter.sample(r, *v, a, b, &mut budget, &mut summary)?;
            line.push(
                pts.iter()
                    .map(|c| cutter.centre_xyz(*v, c))
                    .collect::<Vec<_>>(),
            );
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
#[derive(Clone, Copy, Debug, PartialEq)]
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
        let o = surface.eval(x, y);
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

/// One point of a ball plane's scan.
enum Probe {
    /// The contact lies in the aperture.
    In(Contact),
    /// The contact lies outside it.
    Out,
    /// No contact was found.
    Fail(RasterError),
}

struct Cutter<'a> {
    surface: &'a dyn SurfaceFn,
    along: Axis,
    radius: f64,
    ball: bool,
}

impl<'a> Cutter<'a> {
    fn new(tool: &RasterTool, surface: &'a dyn SurfaceFn, along: Axis) -> Cutter<'a> {
        Cutter {
            surface,
            along,
            radius: tool.radius(),
            ball: matches!(tool, RasterTool::Ball { .. }),
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
        let rho = self.radius;
        // The slope along the cut that tilts the tool's normal: the ball's
        // contact normal is the surface's; the knife's edge, across the cut,
        // sees only the cross-section (its normal in the plane u = t).
        let zu = |l: &Local| if self.ball { l.zu } else { 0.0 };
        // Find v with g(v) = v − ρ z_v/W − plane = 0 (the centre's v on
        // the plane), W = √(1 + z_u² + z_v²) (z_u = 0 for the knife), by
        // damped Newton with g'(v) = 1 − ρ ∂(z_v/W)/∂v.
        let scale = 1.0 + plane.abs() + rho;
        let resid = |v: f64, l: &Local| {
            let w = (1.0 + zu(l) * zu(l) + l.zv * l.zv).sqrt();
            v - rho * l.zv / w - plane
        };
        let mut v = if guess.is_finite() { guess } else { plane };
        let mut l = Local::at(self.surface, self.along, t, v);
        if !l.is_finite() {
            return Err(self.error_at(t, v, false));
        }
        let mut g = resid(v, &l);
        for _ in 0..60 {
            if g.abs() <= 1e-16 * scale {
                break;
            }
            let w2 = 1.0 + zu(&l) * zu(&l) + l.zv * l.zv;
            let w = w2.sqrt();
            let dq = l.zvv / w - l.zv * (zu(&l) * l.zuv + l.zv * l.zvv) / (w2 * w);
            let jac = 1.0 - rho * dq;
            if jac.is_nan() || jac <= 0.0 {
                // The plane's offset folds over: the tool is too large for
                // the hollow here, or no contact lies on this plane.
                let min_radius = self.limiting_radius(&l);
                if min_radius > 0.0 && rho > min_radius {
                    let (x, y) = xy(self.along, t, v);
                    return Err(RasterError::ToolTooLarge {
                        tool_radius: rho,
                        min_radius,
                        x,
                        y,
                    });
                }
                return Err(self.error_at(t, v, true));
            }
            let mut step = -g / jac;
            let mut improved = false;
            for _ in 0..40 {
                let vn = v + step;
                let ln = Local::at(self.surface, self.along, t, vn);
                if ln.is_finite() {
                    let gn = resid(vn, &ln);
                    if gn.abs() < g.abs() {
                        (v, l, g) = (vn, ln, gn);
                        improved = true;
                        break;
                    }
                }
                step *= 0.5;
            }
            if !improved {
                break;
            }
        }
        if g.is_nan() || g.abs() > 1e-13 * scale {
            return Err(self.error_at(t, v, true));
        }
        let w = (1.0 + zu(&l) * zu(&l) + l.zv * l.zv).sqrt();
        Ok(Contact {
            u: t,
            v,
            l,
            c: [t - rho * zu(&l) / w, l.z + rho / w],
        })
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
    /// point lies in the aperture, their ends refined to the edge.
    fn spans(
        &self,
        aperture: &Domain,
        v: f64,
        (u0, u1): (f64, f64),
        summary: &mut Summary,
    ) -> Result<Vec<(Contact, Contact)>, RasterError> {
        // The ball's centre is up to a radius along the cut from its
        // contact; the knife's is at the contact's u.
        let margin = if self.ball { self.radius } else { 0.0 };
        let (a, b) = (u0 - margin, u1 + margin);
        let at = |i: usize| a + (b - a) * i as f64 / SCAN as f64;
        let inside = |c: &Contact| {
            let (x, y) = xy(self.along, c.u, c.v);
            aperture.contains(x, y)
        };
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
                Err(e) => Probe::Fail(e),
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
        let scan: Vec<Option<Contact>> = scan
            .into_iter()
            .map(|p| match p {
                Probe::In(c) => Some(c),
                _ => None,
            })
            .collect();
        // Moves from an inside contact towards an outside position until
        // the contact sits on the aperture edge.
        let refine = |mut c_in: Contact, mut t_out: f64| {
            for _ in 0..64 {
                let mid = 0.5 * (c_in.u + t_out);
                if mid == c_in.u || mid == t_out {
                    break;
                }
                match self.contact(v, mid, c_in.v) {
                    Ok(c) if inside(&c) => c_in = c,
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
            // A plane that only grazes the aperture (its contacts meeting
            // the edge at one point, to rounding) has nothing to cut.
            if end.u - start.u > MIN_SPAN {
                spans.push((start, end));
            }
            i = j + 1;
        }
        Ok(spans)
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
        let mut stack = vec![(a, b, 0u32)];
        while let Some((c0, c1, depth)) = stack.pop() {
            if self.too_coarse(r, plane, &c0, &c1, summary)? {
                if depth >= MAX_DEPTH {
                    let (x, y) = xy(self.along, c0.u, c0.v);
                    return Err(RasterError::ToleranceUnreachable {
                        x,
                        y,
                        tolerance: r.chord_tolerance,
                    });
                }
                let mid = self.contact(plane, 0.5 * (c0.u + c1.u), 0.5 * (c0.v + c1.v))?;
                summary.see(&mid, self);
                stack.push((mid, c1, depth + 1));
                stack.push((c0, mid, depth + 1));
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
    fn too_coarse(
        &self,
        r: &Raster,
        plane: f64,
        c0: &Contact,
        c1: &Contact,
        summary: &mut Summary,
    ) -> Result<bool, RasterError> {
        let (p0, p1) = (c0.c, c1.c);
        if let Some(m) = r.max_step
            && distance2(p0, p1) > m
        {
            return Ok(true);
        }
        if let Some(alpha) = r.lin_angle {
            let cap = |c: &Contact| lin_step(section_radius(c.l.zu, c.l.zuu), alpha, c.l.zu);
            if (c1.u - c0.u).abs() > cap(c0).min(cap(c1)) {
                return Ok(true);
            }
        }
        let mut d = [0.0; PROBES + 1];
        for (i, di) in d.iter_mut().enumerate().take(PROBES).skip(1) {
            let s = i as f64 / PROBES as f64;
            let q = self.contact(plane, c0.u + s * (c1.u - c0.u), c0.v + s * (c1.v - c0.v))?;
            summary.see(&q, self);
            *di = distance_to_segment(q.c, p0, p1);
        }
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
        Ok(peak.max(mid) > r.chord_tolerance * crate::plan::optimise::CHORD_SHARE)
    }
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
        }
    }

    fn see(&mut self, c: &Contact, cutter: &Cutter) {
        let (x, y) = xy(self.along, c.u, c.v);
        let at = |value: f64| Extremum { value, x, y };
        let along = c.l.zu.abs().atan();
        if along > self.slope_along.value || self.slope_along.x.is_nan() {
            self.slope_along = at(along);
        }
        let across = c.l.zv.abs().atan();
        if across > self.slope_across.value || self.slope_across.x.is_nan() {
            self.slope_across = at(across);
        }
        let smaller = |old: &Option<Extremum>, radius: f64| {
            radius.is_finite() && radius > 0.0 && old.is_none_or(|e| radius < e.value)
        };
        let r_along = 1.0 / c.l.curvature_along();
        if smaller(&self.concave_along, r_along) {
            self.concave_along = Some(at(r_along));
        }
        let r_tool = cutter.limiting_radius(&c.l);
        if smaller(&self.tool_limit, r_tool) {
            self.tool_limit = Some(at(r_tool));
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
    let ab = [b[0] - a[0], b[1] - a[1]];
    let aq = [q[0] - a[0], q[1] - a[1]];
    let len2 = ab[0] * ab[0] + ab[1] * ab[1];
    if len2 == 0.0 {
        return distance2(q, a);
    }
    let t = ((aq[0] * ab[0] + aq[1] * ab[1]) / len2).clamp(0.0, 1.0);
    distance2(q, [a[0] + t * ab[0], a[1] + t * ab[1]])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::ir::{Graph, Interpreter, SurfaceTape};

    /// Lin 2022 (seed 000) eq 8, a conic of revolution in closed form:
    /// z = s c q² / (1 + √(1 − (1+k) c² q²)), c = 1/R, s = +1 concave,
    /// −1 convex, with exact derivatives (g = ∂z/∂x / x, h as below):
    /// z_x = g x, z_xx = g + h x², z_xy = h x y, z_yy = g + h y².
    struct Conic {
        radius: f64,
        k: f64,
        s: f64,
    }

    impl SurfaceFn for Conic {
        fn eval_batch(&self, xs: &[f64], ys: &[f64], out: &mut [f64]) {
            for (i, (&x, &y)) in xs.iter().zip(ys).enumerate() {
                let c = 1.0 / self.radius;
                let u = 1.0 - (1.0 + self.k) * c * c * (x * x + y * y);
                let root = u.sqrt();
                let z = self.s * c * (x * x + y * y) / (1.0 + root);
                let g = self.s * c / root;
                let h = self.s * (1.0 + self.k) * c * c * c / (u * root);
                out[6 * i..6 * i + 6].copy_from_slice(&[
                    z,
                    g * x,
                    g * y,
                    g + h * x * x,
                    h * x * y,
                    g + h * y * y,
                ]);
            }
        }
    }

    fn convex(radius: f64, k: f64) -> Conic {
        Conic { radius, k, s: -1.0 }
    }

    /// An inclined plane z = a x + b y: every section is straight.
    struct Ramp {
        a: f64,
        b: f64,
    }

    impl SurfaceFn for Ramp {
        fn eval_batch(&self, xs: &[f64], ys: &[f64], out: &mut [f64]) {
            for (i, (&x, &y)) in xs.iter().zip(ys).enumerate() {
                out[6 * i..6 * i + 6].copy_from_slice(&[
                    self.a * x + self.b * y,
                    self.a,
                    self.b,
                    0.0,
                    0.0,
                    0.0,
                ]);
            }
        }
    }

    /// Lin's microshaper: nose radius 85 µm (seed 000, Fig. 1).
    const LIN_NOSE: f64 = 0.085;
    const KNIFE: RasterTool = RasterTool::Knife {
        nose_radius: LIN_NOSE,
    };

    fn raster(along: Axis, stepover: f64, tol: f64) -> Raster {
        Raster {
            along,
            zigzag: false,
            stepover,
            chord_tolerance: tol,
            max_step: None,
            lin_angle: None,
            retract: 0.5,
        }
    }

    fn plane_of(along: Axis, p: [f64; 3]) -> f64 {
        match along {
            Axis::X => p[1],
            Axis::Y => p[0],
        }
    }

    fn u_of(along: Axis, p: [f64; 3]) -> f64 {
        match along {
            Axis::X => p[0],
            Axis::Y => p[1],
        }
    }

    /// Knife centres over a sphere of radius R: at u along the cut the
    /// edge sees the cross-section, a circle of radius √(R² − u²) about the
    /// sphere's axis, offset by ρ (outward on the dome, inward in the bowl);
    /// the centre lies on that offset circle and on its plane — a closed
    /// form, so exact.
    #[test]
    fn knife_centres_on_a_sphere_lie_on_the_offset_cross_section() {
        for (s, along) in [(-1.0, Axis::X), (-1.0, Axis::Y), (1.0, Axis::X)] {
            let sphere = Conic {
                radius: 1.0,
                k: 0.0,
                s,
            };
            let r = raster(along, 0.05, 1e-5);
            let path = plan_raster(&r, &KNIFE, &sphere, &Domain::Circle { radius: 0.8 }).unwrap();
            let mut worst = 0.0f64;
            for pass in &path.passes {
                let v = plane_of(along, pass[0]);
                for &p in pass {
                    assert_eq!(plane_of(along, p), v);
                    let rs = (1.0 - u_of(along, p).powi(2)).sqrt();
                    let d = v.hypot(p[2] - s);
                    worst = worst.max((d - (rs - s * LIN_NOSE)).abs());
                }
            }
            assert!(worst < 1e-12, "s={s} {along:?}: {worst:e}");
        }
    }

    /// Ball centres over a sphere of radius R lie on the sphere of radius
    /// R ± ρ about its centre, each on its path plane.
    #[test]
    fn ball_centres_on_a_sphere_lie_on_the_offset_sphere() {
        let ball = RasterTool::Ball { radius: 0.1 };
        for (s, along) in [(-1.0, Axis::X), (-1.0, Axis::Y), (1.0, Axis::Y)] {
            let sphere = Conic {
                radius: 1.0,
                k: 0.0,
                s,
            };
            let r = raster(along, 0.05, 1e-5);
            let path = plan_raster(&r, &ball, &sphere, &Domain::Circle { radius: 0.8 }).unwrap();
            let mut worst = 0.0f64;
            for pass in &path.passes {
                let v = plane_of(along, pass[0]);
                // Planes are v0 + k·stepover, k possibly negative for the ball.
                let k = (v + 0.8) / 0.05;
                assert!((k - k.round()).abs() < 1e-9, "plane {v}");
                for &p in pass {
                    assert_eq!(plane_of(along, p), v);
                    let d = (p[0] * p[0] + p[1] * p[1] + (p[2] - s).powi(2)).sqrt();
                    worst = worst.max((d - (1.0 - s * 0.1)).abs());
                }
            }
            assert!(worst < 1e-12, "s={s} {along:?}: {worst:e}");
        }
    }

    /// Every chord's midpoint is within the tolerance of the exact centre
    /// curve (on a sphere: a circle of known radius in each plane), and on
    /// the inside of it.
    #[test]
    fn chords_stay_within_tolerance_on_a_sphere() {
        let sphere = convex(1.0, 0.0);
        let tol = 1e-5;
        for tool in [KNIFE, RasterTool::Ball { radius: 0.1 }] {
            let r = raster(Axis::X, 0.05, tol);
            let path = plan_raster(&r, &tool, &sphere, &Domain::Circle { radius: 0.8 }).unwrap();
            let mut worst = 0.0f64;
            for pass in &path.passes {
                let v = pass[0][1];
                // The exact centre height at u on this plane: on the offset
                // cross-section (knife) or the offset sphere (ball).
                let exact = |u: f64| {
                    match tool {
                        RasterTool::Knife { nose_radius } => {
                            ((1.0 - u * u).sqrt() + nose_radius).powi(2) - v * v
                        }
                        RasterTool::Ball { radius } => (1.0 + radius).powi(2) - v * v - u * u,
                    }
                    .sqrt()
                        - 1.0
                };
                for w in pass.windows(2) {
                    let (du, dz) = (w[1][0] - w[0][0], w[1][2] - w[0][2]);
                    let m = [0.5 * (w[0][0] + w[1][0]), 0.5 * (w[0][2] + w[1][2])];
                    // Vertical gap times the cosine of the chord's slope:
                    // the distance to the (locally straight) curve.
                    let dev = (exact(m[0]) - m[1]) * du.abs() / du.hypot(dz);
                    assert!(dev > -1e-12, "chord outside the curve by {dev:e}");
                    worst = worst.max(dev);
                }
            }
            // The chords' share of the path's tolerance, and tight: the
            // sampling uses most of it.
            let share = tol * crate::plan::optimise::CHORD_SHARE;
            assert!(worst <= share * (1.0 + 1e-9), "{tool:?}: {worst:e}");
            assert!(worst > 0.5 * share, "{tool:?}: {worst:e}");
        }
    }

    /// Lin's model of the knife (his Fig. 5): the nose circle in the plane
    /// of the path (y = `v`), touching the section at x = `t`; its centre is
    /// the contact moved by the nose radius along the section's normal.
    /// Returns (contact, centre).
    fn lin_plane_contact(surface: &dyn SurfaceFn, v: f64, t: f64) -> ([f64; 3], [f64; 3]) {
        let o = surface.eval(t, v);
        let w = (1.0 + o[1] * o[1]).sqrt();
        (
            [t, v, o[0]],
            [t - LIN_NOSE * o[1] / w, v, o[0] + LIN_NOSE / w],
        )
    }

    /// The exact centre curve of Lin's in-plane model on the plane at y =
    /// `v` at centre position x = `xc`: the contact whose centre is at xc,
    /// found by bisection (the centre's x rises with the contact's x where
    /// the nose fits the section).
    fn knife_centre_at(surface: &dyn SurfaceFn, v: f64, xc: f64) -> ([f64; 3], [f64; 3]) {
        let at = |t: f64| {
            let (contact, centre) = lin_plane_contact(surface, v, t);
            ToolContact { contact, centre }
        };
        let (mut lo, mut hi) = (xc - LIN_NOSE, xc + LIN_NOSE);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid == lo || mid == hi {
                break;
            }
            if at(mid).centre[0] < xc {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let c = at(0.5 * (lo + hi));
        (c.contact, c.centre)
    }

    /// Lin's hyperboloid job (R = 1 mm, k = −20): chord midpoints against
    /// the exact centre curve, and no surface point ever inside the knife's
    /// edge (the nose arc across the cut) at a planned centre, and inside it
    /// by at most the chord tolerance along a chord.
    #[test]
    fn hyperboloid_chords_and_gouge() {
        let surf = convex(1.0, -20.0);
        let tol = 1e-5;
        let r = raster(Axis::X, 0.05, tol);
        let path = plan_raster(&r, &KNIFE, &surf, &Domain::Circle { radius: 0.8 }).unwrap();
        let mut worst_chord = 0.0f64;
        let mut worst_gouge = f64::NEG_INFINITY;
        let mut worst_chord_gouge = f64::NEG_INFINITY;
        for pass in path.passes.iter().step_by(4) {
            let v = pass[0][1];
            let clearance = |c: [f64; 3]| {
                (0..=400)
                    .map(|i| {
                        let y = c[1] - LIN_NOSE + 2.0 * LIN_NOSE * i as f64 / 400.0;
                        let z = surf.eval(c[0], y)[0];
                        LIN_NOSE - (y - c[1]).hypot(z - c[2])
                    })
                    .fold(f64::NEG_INFINITY, f64::max)
            };
            for w in pass.windows(2) {
                worst_gouge = worst_gouge.max(clearance(w[0]));
                let m = [0.5 * (w[0][0] + w[1][0]), v, 0.5 * (w[0][2] + w[1][2])];
                worst_chord_gouge = worst_chord_gouge.max(clearance(m));
                let exact = tool_contact(&KNIFE, &surf, Axis::X, v, m[0])
                    .unwrap()
                    .centre;
                assert_eq!(exact[0], m[0]);
                let (du, dz) = (w[1][0] - w[0][0], w[1][2] - w[0][2]);
                // Vertical gap times cos of the chord's inclination: the
                // distance to the (locally straight) curve.
                worst_chord = worst_chord.max((exact[2] - m[2]).abs() * du.abs() / du.hypot(dz));
            }
        }
        assert!(worst_chord <= tol * (1.0 + 1e-6), "{worst_chord:e}");
        assert!(worst_gouge <= 1e-12, "gouge at a centre {worst_gouge:e}");
        assert!(
            worst_chord_gouge <= tol * (1.0 + 1e-6),
            "gouge along a chord {worst_chord_gouge:e}"
        );
    }

    #[test]
    fn ball_is_gouge_free_at_its_centres() {
        let surf = convex(1.0, -20.0);
        let rho = 0.1;
        let r = raster(Axis::Y, 0.05, 1e-5);
        let path = plan_raster(
            &r,
            &RasterTool::Ball { radius: rho },
            &surf,
            &Domain::Circle { radius: 0.8 },
        )
        .unwrap();
        let mut worst = f64::NEG_INFINITY;
        for pass in path.passes.iter().step_by(5) {
            for c in pass.iter().step_by(7) {
                for i in 0..=40 {
                    for j in 0..=40 {
                        let x = c[0] - rho + 2.0 * rho * i as f64 / 40.0;
                        let y = c[1] - rho + 2.0 * rho * j as f64 / 40.0;
                        let z = surf.eval(x, y)[0];
                        let d =
                            ((x - c[0]).powi(2) + (y - c[1]).powi(2) + (z - c[2]).powi(2)).sqrt();
                        worst = worst.max(rho - d);
                    }
                }
            }
        }
        assert!(worst <= 1e-12, "{worst:e}");
    }

    /// Lin's three convex jobs (seed 000, Figs 8 and 10) with the 85 µm
    /// microshaper: oblate ellipsoid R = 3 mm k = 10, paraboloid R = 1 mm
    /// k = −1, hyperboloid R = 1 mm k = −20; stepover 10 µm, chord
    /// tolerance 10 nm, aperture radius 0.8 mm.
    #[test]
    fn lin_jobs_plan() {
        let r = raster(Axis::X, 0.01, 1e-5);
        let aperture = Domain::Circle { radius: 0.8 };
        for (radius, k, slope_deg) in [
            (1.0, -20.0, 12.436),
            (1.0, -1.0, 38.660),
            (3.0, 10.0, 29.745),
        ] {
            let path = plan_raster(&r, &KNIFE, &convex(radius, k), &aperture).unwrap();
            eprintln!(
                "R={radius} k={k}: {} passes, {} points, cut {:.3} mm, max slope along {:.3}°, across {:.3}°, safe z {:.4}",
                path.pass_count,
                path.point_count,
                path.cut_length,
                path.max_slope_along.value.to_degrees(),
                path.max_slope_across.value.to_degrees(),
                path.safe_z
            );
            // Planes at −0.8 + 0.01 k. The knife's contact on the plane
            // at v lies ρ sin φ nearer the axis, φ the slope across, so
            // planes out to 0.8 mm + ρ sin φ(0.8 mm) cut (φ at the edge on
            // the y axis, where the contact is nearest the axis).
            let phi = (0.8 / (radius * radius - (1.0 + k) * 0.64f64).sqrt()).atan();
            let reach = 0.8 + LIN_NOSE * phi.sin();
            let planes = (-9..=169)
                .filter(|&j| (-0.8 + 0.01 * f64::from(j)).abs() < reach)
                .count();
            eprintln!("  {planes} planes reach {reach:.5} mm");
            assert_eq!(path.pass_count, planes);
            assert_eq!(path.passes.len(), planes);
            // A convex lens has no concave section.
            assert_eq!(path.min_concave_radius_along, None);
            // Steepest along the cut at the aperture edge on y ≈ 0:
            // atan(q/√(R² − (1+k) q²)) at q = 0.8.
            let want = (0.8 / (radius * radius - (1.0 + k) * 0.64f64).sqrt()).atan();
            assert!((want.to_degrees() - slope_deg).abs() < 1e-3);
            assert!(
                (path.max_slope_along.value - want).abs() < 1e-6,
                "{}",
                path.max_slope_along.value.to_degrees()
            );
            // The vertex centre is the highest: z = ρ above the vertex.
            assert!((path.safe_z - (LIN_NOSE + 0.5)).abs() < 1e-6);
        }
    }

    /// The conic root 1 − (1+k) c² r² vanishes at r = R/√(1+k) (0.9045 mm
    /// for Lin's oblate ellipsoid R = 3 mm, k = 10): an aperture inside it
    /// plans, one beyond it is undefined there.
    #[test]
    fn oblate_ellipsoid_aperture_is_limited_by_the_conic_root() {
        let surf = convex(3.0, 10.0);
        let limit = 3.0 / 11f64.sqrt();
        let r = raster(Axis::X, 0.01, 1e-5);
        assert!(plan_raster(&r, &KNIFE, &surf, &Domain::Circle { radius: 0.9 }).is_ok());
        match plan_raster(&r, &KNIFE, &surf, &Domain::Circle { radius: 0.95 }) {
            Err(RasterError::Undefined { x, y }) => {
                let q = x.hypot(y);
                assert!(q >= limit && q <= 0.95 + 1e-12, "({x}, {y})");
            }
            other => panic!("{other:?}"),
        }
        // A path that runs from defined into undefined ground reports the
        // edge of definition itself.
        let strip = Domain::Rect {
            x: (-0.95, 0.95),
            y: (0.0, 0.005),
        };
        match plan_raster(&r, &KNIFE, &surf, &strip) {
            Err(RasterError::Undefined { x, y }) => {
                assert_eq!(y, 0.0);
                assert!((x.abs() - limit).abs() < 1e-9, "{x} vs {limit}");
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn zigzag_reverses_alternate_passes() {
        let surf = convex(1.0, -1.0);
        let aperture = Domain::Circle { radius: 0.5 };
        let mut r = raster(Axis::Y, 0.05, 1e-4);
        let one_way = plan_raster(&r, &KNIFE, &surf, &aperture).unwrap();
        r.zigzag = true;
        let zigzag = plan_raster(&r, &KNIFE, &surf, &aperture).unwrap();
        assert_eq!(one_way.pass_count, zigzag.pass_count);
        for (j, (a, b)) in one_way.passes.iter().zip(&zigzag.passes).enumerate() {
            assert!(a.windows(2).all(|w| w[1][1] > w[0][1]), "one-way runs +y");
            if j % 2 == 1 {
                let mut rev = a.clone();
                rev.reverse();
                assert_eq!(&rev, b);
            } else {
                assert_eq!(a, b);
            }
        }
        assert_eq!(one_way.cut_length, zigzag.cut_length);
    }

    #[test]
    fn invalid_inputs_give_errors() {
        let surf = convex(1.0, 0.0);
        let aperture = Domain::Circle { radius: 0.5 };
        let base = raster(Axis::X, 0.05, 1e-4);
        let bad = |r: Raster, name: &str| match plan_raster(&r, &KNIFE, &surf, &aperture) {
            Err(RasterError::InvalidParameter { name: n, .. }) => assert_eq!(n, name),
            other => panic!("{name}: {other:?}"),
        };
        for v in [0.0, -0.01, f64::NAN, f64::INFINITY] {
            bad(
                Raster {
                    stepover: v,
                    ..base.clone()
                },
                "stepover",
            );
            bad(
                Raster {
                    chord_tolerance: v,
                    ..base.clone()
                },
                "chord tolerance",
            );
            bad(
                Raster {
                    max_step: Some(v),
                    ..base.clone()
                },
                "max step",
            );
        }
        bad(
            Raster {
                lin_angle: Some(4.0),
                ..base.clone()
            },
            "Lin step angle",
        );
        bad(
            Raster {
                retract: -1.0,
                ..base.clone()
            },
            "retract",
        );
        let err = |tool: RasterTool, ap: Domain| plan_raster(&base, &tool, &surf, &ap).unwrap_err();
        assert!(matches!(
            err(RasterTool::Knife { nose_radius: 0.0 }, aperture),
            RasterError::InvalidParameter {
                name: "nose radius",
                ..
            }
        ));
        assert!(matches!(
            err(RasterTool::Ball { radius: -1.0 }, aperture),
            RasterError::InvalidParameter {
                name: "ball radius",
                ..
            }
        ));
        assert!(matches!(
            err(KNIFE, Domain::Circle { radius: 0.0 }),
            RasterError::InvalidParameter { .. }
        ));
        assert!(matches!(
            err(
                KNIFE,
                Domain::Annulus {
                    inner: 0.5,
                    outer: 0.4
                }
            ),
            RasterError::InvalidParameter {
                name: "aperture inner radius",
                ..
            }
        ));
        assert!(matches!(
            err(
                KNIFE,
                Domain::Rect {
                    x: (1.0, 0.0),
                    y: (0.0, 1.0)
                }
            ),
            RasterError::InvalidParameter { .. }
        ));
        assert!(matches!(
            plan_raster(
                &Raster {
                    stepover: 1e-12,
                    ..base.clone()
                },
                &KNIFE,
                &surf,
                &aperture
            ),
            Err(RasterError::TooManyPaths { .. })
        ));
        assert!(matches!(
            plan_raster(
                &Raster {
                    chord_tolerance: 1e-30,
                    ..base.clone()
                },
                &KNIFE,
                &surf,
                &aperture
            ),
            Err(RasterError::ToleranceUnreachable { .. })
        ));
        // The one plane of a tiny aperture only touches its edge (on a
        // surface level across the cut, the contact is on the plane).
        assert_eq!(
            plan_raster(
                &base,
                &KNIFE,
                &Ramp { a: 0.1, b: 0.0 },
                &Domain::Circle { radius: 0.001 }
            )
            .unwrap_err(),
            RasterError::NothingToCut
        );
    }

    /// A concave sphere R = 1 mm: the cross-section at x = u, the knife
    /// edge's, is a circle of radius √(1 − u²), down to 0.6 mm at the
    /// aperture's edge (0.8 mm). A 0.7 mm knife does not fit there (it is
    /// refused where it first meets a cross-section tighter than itself); a
    /// 0.7 mm ball does (principal radius 1 mm); a 1.2 mm ball does not.
    #[test]
    fn tool_larger_than_the_hollow_is_refused() {
        let bowl = Conic {
            radius: 1.0,
            k: 0.0,
            s: 1.0,
        };
        let aperture = Domain::Circle { radius: 0.8 };
        let r = raster(Axis::X, 0.01, 1e-4);
        match plan_raster(
            &r,
            &RasterTool::Knife { nose_radius: 0.7 },
            &bowl,
            &aperture,
        ) {
            Err(RasterError::ToolTooLarge {
                tool_radius,
                min_radius,
                x,
                y,
            }) => {
                assert_eq!(tool_radius, 0.7);
                assert!(min_radius < 0.7 && min_radius > 0.6 - 1e-9, "{min_radius}");
                let want = (1.0 - x * x).sqrt();
                assert!((min_radius - want).abs() < 1e-9, "{min_radius} at x {x}");
                assert!(x.hypot(y) <= 0.8 + 1e-12, "({x}, {y})");
            }
            other => panic!("{other:?}"),
        }
        let r = raster(Axis::X, 0.05, 1e-4);
        assert!(plan_raster(&r, &RasterTool::Ball { radius: 0.7 }, &bowl, &aperture).is_ok());
        match plan_raster(&r, &RasterTool::Ball { radius: 1.2 }, &bowl, &aperture) {
            Err(RasterError::ToolTooLarge { min_radius, .. }) => {
                assert!((min_radius - 1.0).abs() < 1e-9, "{min_radius}")
            }
            other => panic!("{other:?}"),
        }
    }

    /// Each pass starts and ends with the contact point exactly on the
    /// aperture edge.
    #[test]
    fn passes_end_where_the_contact_reaches_the_edge() {
        let surf = convex(1.0, -20.0);
        let r = raster(Axis::X, 0.05, 1e-5);
        let path = plan_raster(&r, &KNIFE, &surf, &Domain::Circle { radius: 0.8 }).unwrap();
        for pass in &path.passes {
            for p in [pass[0], *pass.last().unwrap()] {
                // The knife's contact is at the centre's x.
                let c = tool_contact(&KNIFE, &surf, Axis::X, p[1], p[0]).unwrap();
                assert!(distance3(p, c.centre) < 1e-15);
                assert!(
                    (c.contact[0].hypot(c.contact[1]) - 0.8).abs() < 1e-9,
                    "{c:?}"
                );
            }
        }
        let ball = RasterTool::Ball { radius: 0.1 };
        let path = plan_raster(&r, &ball, &surf, &Domain::Circle { radius: 0.8 }).unwrap();
        for pass in &path.passes {
            for p in [pass[0], *pass.last().unwrap()] {
                // Recover the contact: the ball touches where the normal
                // through the centre meets the surface.
                let on = |t: f64| tool_contact(&ball, &surf, Axis::X, p[1], t).unwrap();
                let (mut lo, mut hi) = (p[0] - 0.1, p[0] + 0.1);
                for _ in 0..200 {
                    let mid = 0.5 * (lo + hi);
                    if on(mid).centre[0] < p[0] {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                let c = on(0.5 * (lo + hi)).contact;
                assert!((c[0].hypot(c[1]) - 0.8).abs() < 1e-9, "{c:?}");
            }
        }
    }

    /// The exact raise of the knife tip above S when the nose is centred
    /// over S (the quantity of Lin's eq 4), from the exact centre curve.
    fn exact_raise(surface: &dyn SurfaceFn, xs: f64) -> f64 {
        let (_, centre) = knife_centre_at(surface, 0.0, xs);
        centre[2] - LIN_NOSE - surface.eval(xs, 0.0)[0]
    }

    /// Eq 4 (for Lin's in-plane nose) is exact where the section is
    /// straight (δ2 = 0, δ1 exact), and close on a curved one: on a circle
    /// of signed radius ρ the exact raise is
    /// ρ cos θ − r − sgn ρ √((ρ − r)² − ρ² sin² θ), which eq 4 matches to
    /// first order in r/ρ. lensc's knife, its edge across the cut, needs no
    /// raise where the cross-section is level: its tip is on S.
    #[test]
    fn eq4_against_the_exact_centre() {
        for (surf, xs) in [
            (convex(1.0, -20.0), 0.8),
            (convex(1.0, 0.0), 0.5),
            (convex(3.0, 10.0), -0.7),
        ] {
            let c = tool_contact(&KNIFE, &surf, Axis::X, 0.0, xs).unwrap();
            assert_eq!(c.centre[0], xs);
            let raise = c.centre[2] - LIN_NOSE - surf.eval(xs, 0.0)[0];
            assert!(raise.abs() < 1e-15, "{raise:e}");
        }
        // Straight: a ramp of slope 0.3 along x.
        let ramp = Ramp { a: -0.3, b: 0.0 };
        for xs in [-0.5, 0.0, 0.7] {
            let exact = exact_raise(&ramp, xs);
            let lin = lin_interference_offset(LIN_NOSE, f64::INFINITY, -0.3);
            assert!((exact - lin).abs() < 1e-15, "{exact} vs {lin}");
        }
        // Level: nothing to raise.
        assert_eq!(lin_interference_offset(LIN_NOSE, -1.0, 0.0), 0.0);
        // Curved: a convex and a concave sphere R = 1 mm (section at y = 0
        // is a circle of radius 1), r = 85 µm, at slopes θ up to 30°.
        let r = LIN_NOSE;
        for s in [-1.0f64, 1.0] {
            let sphere = Conic {
                radius: 1.0,
                k: 0.0,
                s,
            };
            for (deg, max_rel) in [(5.0, 7.4e-3), (12.43, 7.9e-3), (30.0, 1.23e-2)] {
                let theta = f64::to_radians(deg);
                let xs = theta.sin();
                let o = sphere.eval(xs, 0.0);
                let rho = section_radius(o[1], o[3]);
                assert!((rho - s).abs() < 1e-12);
                let closed = rho * theta.cos()
                    - r
                    - rho.signum() * ((rho - r).powi(2) - (rho * theta.sin()).powi(2)).sqrt();
                let exact = exact_raise(&sphere, xs);
                assert!((exact - closed).abs() < 1e-12, "{exact} vs {closed}");
                let lin = lin_interference_offset(r, rho, o[1]);
                let rel = (lin - exact) / exact;
                eprintln!(
                    "eq 4, s={s} θ={deg}°: exact {:.4} nm, eq 4 {:.4} nm, differ {:.4} nm ({:.3e})",
                    exact * 1e6,
                    lin * 1e6,
                    (lin - exact) * 1e6,
                    rel
                );
                // Eq 4 is exact to first order in r/ρ; what remains is
                // about −(r/ρ)², growing with θ.
                assert!(rel < -0.9 * (r / rho).powi(2) && rel > -max_rel, "{rel}");
            }
        }
        // Lin's hyperboloid at its 0.8 mm edge, with the local ρ.
        let hyp = convex(1.0, -20.0);
        let o = hyp.eval(0.8, 0.0);
        let exact = exact_raise(&hyp, 0.8);
        let lin = lin_interference_offset(r, section_radius(o[1], o[3]), o[1]);
        eprintln!(
            "eq 4, k=-20 at 0.8 mm: exact {:.4} nm, eq 4 {:.4} nm, differ {:.3e} nm",
            exact * 1e6,
            lin * 1e6,
            (lin - exact) * 1e6
        );
        assert!(((lin - exact) / exact).abs() < 1e-3);
    }

    /// The exact counterpart of eqs 5–6: how far inside the edge the
    /// contact must stop for the knife tip to stay at the edge's height.
    fn exact_inset(surface: &dyn SurfaceFn, edge: f64) -> f64 {
        let z_edge = surface.eval(edge, 0.0)[0];
        let tip = |t: f64| lin_plane_contact(surface, 0.0, t).1[2] - LIN_NOSE;
        // The tip falls towards the edge of the dome (edge > 0).
        let (mut lo, mut hi) = (0.0, edge);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if tip(mid) > z_edge {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        edge - 0.5 * (lo + hi)
    }

    /// Eqs 5–6 (for Lin's in-plane nose) are exact for a straight section;
    /// on Lin's curved sections they differ from the exact inset. lensc's
    /// knife, its edge across the cut, needs none: the pass ends with the
    /// contact on the edge, the centre straight above it and the tip at the
    /// edge's height.
    #[test]
    fn eqs5_6_against_the_exact_centre() {
        let ramp = Ramp { a: -0.3, b: 0.0 };
        let exact = exact_inset(&ramp, 0.5);
        let lin = lin_boundary_offset(LIN_NOSE, -0.3).abs();
        assert!((exact - lin).abs() < 1e-14, "{exact} vs {lin}");
        assert_eq!(lin_boundary_offset(LIN_NOSE, 0.0), 0.0);
        for (name, surf) in [
            ("sphere R=1", convex(1.0, 0.0)),
            ("k=-20", convex(1.0, -20.0)),
            ("k=-1", convex(1.0, -1.0)),
            ("R=3 k=10", convex(3.0, 10.0)),
        ] {
            let o = surf.eval(0.8, 0.0);
            let exact = exact_inset(&surf, 0.8);
            let lin = lin_boundary_offset(LIN_NOSE, o[1]).abs();
            let c = tool_contact(&KNIFE, &surf, Axis::X, 0.0, 0.8).unwrap();
            let theta = o[1].atan();
            assert_eq!(c.centre[0], 0.8);
            assert!((c.centre[2] - LIN_NOSE - o[0]).abs() < 1e-15);
            eprintln!(
                "eqs 5-6, {name} at 0.8 mm (θ {:.3}°): exact inset {:.4} µm, eq 6 {:.4} µm, \
                 differ {:.4} µm",
                theta.to_degrees().abs(),
                exact * 1e3,
                lin * 1e3,
                (lin - exact) * 1e3,
            );
            // On a dome the surface falls faster than its tangent, so the
            // exact inset is shorter than the straight-line estimate.
            assert!(lin > exact && exact > 0.0);
        }
    }

    /// Eq 2 is the chord of a circle exactly; eq 3 takes its horizontal
    /// projection with the slope at the step's start. With `lin_angle` set,
    /// no planned step between contact points exceeds eq 2–3 at either end.
    #[test]
    fn lin_step_caps_the_planned_step() {
        let (rho, alpha) = (2.0, 0.1);
        let (p, q): (f64, f64) = (0.3, 0.3 + alpha);
        let chord = rho * (q.sin() - p.sin()).hypot(q.cos() - p.cos());
        assert!((lin_chord(rho, alpha) - chord).abs() < 1e-15);
        assert!((lin_step(rho, alpha, 0.0) - 2.0 * rho * 0.05f64.sin()).abs() < 1e-15);
        assert!((lin_step(-rho, alpha, 1.0) - lin_chord(rho, alpha) / 2f64.sqrt()).abs() < 1e-15);
        assert_eq!(lin_step(f64::INFINITY, alpha, 0.0), f64::INFINITY);

        // Knife on a convex sphere R = 1: the contact is where the radius
        // through the centre meets the section circle.
        let sphere = convex(1.0, 0.0);
        let alpha = 0.5f64.to_radians();
        let mut r = raster(Axis::X, 0.1, 1e-2);
        r.lin_angle = Some(alpha);
        let path = plan_raster(&r, &KNIFE, &sphere, &Domain::Circle { radius: 0.8 }).unwrap();
        let mut tightest = 0.0f64;
        for pass in &path.passes {
            let rs = (1.0 - pass[0][1].powi(2)).sqrt();
            let contact = |p: [f64; 3]| {
                let (dx, dz) = (p[0], p[2] + 1.0);
                let n = dx.hypot(dz);
                let (x, z) = (rs * dx / n, rs * dz / n - 1.0);
                (x, -x / (z + 1.0))
            };
            for w in pass.windows(2) {
                let ((x0, s0), (x1, s1)) = (contact(w[0]), contact(w[1]));
                let cap = lin_step(-rs, alpha, s0).min(lin_step(-rs, alpha, s1));
                assert!(
                    (x1 - x0).abs() <= cap * (1.0 + 1e-12),
                    "{} > {cap}",
                    x1 - x0
                );
                tightest = tightest.max((x1 - x0).abs() / cap);
            }
        }
        assert!(tightest > 0.5, "{tightest}");
        // A fixed step cap holds too.
        let mut r = raster(Axis::X, 0.1, 1e-2);
        r.max_step = Some(0.003);
        let path = plan_raster(&r, &KNIFE, &sphere, &Domain::Circle { radius: 0.8 }).unwrap();
        assert!(
            path.passes
                .iter()
                .flat_map(|p| p.windows(2))
                .all(|w| distance3(w[0], w[1]) <= 0.003)
        );
    }

    /// The same paraboloid as an IR tape (z = −(x² + y²)/(2R), Lin's eq 8
    /// with k = −1, s = −1) and in closed form plan the same path.
    #[test]
    fn ir_surface_plans_like_the_closed_form() {
        let mut g = Graph::new();
        let (x, y) = (g.x(), g.y());
        let x2 = g.powi(x, 2);
        let y2 = g.powi(y, 2);
        let q2 = g.add(x2, y2);
        let k = g.constant_node(-0.5);
        let z = g.mul(k, q2);
        let f = Interpreter::new(&SurfaceTape::new(g, z));
        let r = raster(Axis::X, 0.05, 1e-5);
        let aperture = Domain::Circle { radius: 0.8 };
        let a = plan_raster(&r, &KNIFE, &f, &aperture).unwrap();
        let b = plan_raster(&r, &KNIFE, &convex(1.0, -1.0), &aperture).unwrap();
        assert_eq!(a.point_count, b.point_count);
        for (p, q) in a.passes.iter().flatten().zip(b.passes.iter().flatten()) {
            assert!(distance3(*p, *q) < 1e-13, "{p:?} vs {q:?}");
        }
    }

    /// Annulus apertures split the inner planes into two passes, each
    /// ending on the inner and outer edges.
    #[test]
    fn annulus_splits_inner_planes() {
        let surf = convex(1.0, -1.0);
        let r = raster(Axis::X, 0.1, 1e-4);
        let ap = Domain::Annulus {
            inner: 0.25,
            outer: 0.8,
        };
        let path = plan_raster(&r, &KNIFE, &surf, &ap).unwrap();
        // Planes −0.8 … 0.8 (17): on the paraboloid z = −q²/2 the contact
        // lies ρ q/√(1 + q²) nearer the axis than its plane (0.747 mm for the
        // plane at 0.8, 0.843 mm for 0.9, outside). Of them −0.2 … 0.2 (5)
        // are split: the plane at 0.3 has its contacts at 0.276 mm, outside
        // the 0.25 mm hole.
        assert_eq!(path.pass_count, 22);
    }

    /// Seed 000 appendix eq A1 as printed gives dz/dq = s q (2Q² − (1+k) q²)/Q³
    /// with Q = R + √(R² − (1+k) q²); the derivative of eq 8 is
    /// s q / √(R² − (1+k) q²). They agree only for the paraboloid (k = −1),
    /// which is why the planner uses the surface's exact derivatives.
    #[test]
    fn appendix_a1_as_printed() {
        let a1 = |radius: f64, k: f64, q: f64| {
            let big_q = radius + (radius * radius - (1.0 + k) * q * q).sqrt();
            -(2.0 * q * big_q - (1.0 + k) * q.powi(3) / big_q) / (big_q * big_q)
        };
        let exact = |radius: f64, k: f64, q: f64| convex(radius, k).eval(q, 0.0)[1];
        assert!((a1(1.0, -1.0, 0.8) - exact(1.0, -1.0, 0.8)).abs() < 1e-15);
        let (p, e) = (a1(1.0, -20.0, 0.8), exact(1.0, -20.0, 0.8));
        eprintln!("A1 at k=-20, q=0.8: printed {p}, exact {e}");
        assert!((p - e).abs() > 0.05);
    }
}
