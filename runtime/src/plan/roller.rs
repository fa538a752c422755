//! Slow-tool-servo turning of a freeform pattern on a precision roller
//! (Liu, Cheung, Feng & Wang, seed 002): one helix per pass in C (spindle
//! angle) and Z (along the roller axis), with X (the tool-nose centre's
//! distance from the roller axis) following the pattern, plus the
//! section-4 tool checks and the roller-radius figures of eq 1.
//!
//! Mapping (eqs 2–4). The pattern is designed flat: x along the roller
//! axis, y the arc length around the roller on the design radius R_r,
//! z the height with +z out of the material. The point (x, y, z) goes to
//! axial position x, spindle angle c = y / R_r and radius R_r + z — the
//! paper's eq 2, with c in radians instead of degrees (c = 180 y / π R_r).
//! Eq 4 only renames the axes (Z = x_r, X = r_r, C = c_r): machine Z here
//! IS the design x (no work offset; a program adds its own), and C turning
//! positive brings increasing design y under the tool.
//!
//! Helix (eq 5). In a pass, point k is at c = k · Δc (counted from the
//! start of the pass, not wrapped) and z = z_start + P · c / 2π; the last
//! point is at z_end exactly (c = 2π (z_end − z_start) / P), the step
//! before it shorter when the travel is not a whole number of steps. A
//! pass of N steps has N + 1 points: job 1's rough pass 55 · 360 + 1.
//!
//! Nose centre (eqs 6–9, made exact). The cutting edge is a circle of
//! radius ρ in the plane through the roller axis at the spindle angle c —
//! the cutting plane. In that plane the roller's section is exactly the
//! design's axial section z(·, y) lifted by R_r (radius is linear in z), so
//! the lowest centre that clears it at axial position x is
//!   X = R_r + max over |u − x| < ρ of  z(u, y) + sqrt(ρ² − (u − x)²),
//! the envelope `envelope::piece_max` computes on a `Profile`. For a smooth
//! section with ρ below its concave radius of curvature the function under
//! the max has a single stationary point (its derivative can only cross
//! zero downwards), so Newton's method on the exact derivatives, from the
//! previous point's contact (u = x for a revolution's first point), finds
//! the maximum. Where it peaks on a convex corner instead (the ridge
//! between two dimples of a grid) Newton bounces across it, and the corner
//! is closed in on from both sides (`ridge`); should neither converge,
//! `piece_max` over the whole window does. Sections with concave corners or steps (seams between
//! lenslets) have several local maxima: when the planner's survey finds
//! such corners, each window is scanned first and every local maximum
//! refined (see `centre_height_scanned`). The paper's own method — normals
//! from numerical gradients of a discretised section, offset by ρ, then
//! interpolated — is kept as the reference `liu_offset` / `liu_centre`.
//!
//! Measured edge (`machine::edge`, `plan_roller_helix_edged`). The nose's
//! edge lies in the cutting plane with the tool's axis pointing at the
//! roller axis (−X), its angles counted positive towards +Z (along the
//! roller, the way the helix advances). The lowest centre that clears the
//! section is then X = R_r + max over u of z(u, y) + L(u − x), L the
//! edge's depth below its centre at that axial offset: the same envelope,
//! found by `envelope::edged_max` from the circle's contact. The edge
//! touches a smooth section at θ = atan(∂z/∂x), the axial slope; the slope
//! around the roller does not move that point (the edge lies across the
//! cut). Sections with concave corners (scanned) are refused with an edge.
//!
//! Passes. The paper's blank (3.01 mm for a 3 mm roller) is turned "layer
//! by layer", the X axis offset by the depth of cut each cycle, first
//! rough (1°, 0.1 mm pitch) then finish (0.1°, 0.005 mm). Here each
//! `HelixPass` is one helix over [z_start, z_end] at X = R_r + centre +
//! its `finish_allowance` (rough passes leave it, the finish pass has 0);
//! with a `depth_of_cut` the pass is cut in cycles, the same helix repeated
//! with extra X offsets stepping down by the depth of cut to 0. The points
//! are produced once per pass; the cycles are listed in its summary.
//!
//! Output. `plan_roller_helix` returns every pass's points (job 1's finish
//! pass is 3 960 001 points, ~95 MB); `plan_roller_helix_into` hands them
//! in order, a revolution at a time, to a sink and keeps only the figures.
//! Revolutions are computed in parallel batches; a point's contact search
//! starts from the previous point's contact, and each revolution's first
//! from u = x, so a revolution depends only on its index: the output is
//! identical for any thread count.

use std::f64::consts::TAU;
use std::ops::ControlFlow;

use rayon::prelude::*;

use crate::machine::edge::Nose;
use crate::plan::chords::{self, ChordPlacement};
use crate::plan::envelope;
use crate::surface::ir::SurfaceFn;
use crate::surface::{Profile, ProfilePoint};

mod ridge;
use ridge::Probe;

/// One helix over the whole cut.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HelixPass {
    /// C-axis resolution (rad) between programmed points.
    pub c_step: f64,
    /// Pitch of the helix: Z feed per revolution (mm).
    pub pitch: f64,
    /// Radial stock (mm) this pass leaves for the next: X is raised by it.
    /// 0 for the finish pass.
    pub finish_allowance: f64,
}

/// A roller job: the roller, the cut, and its passes.
#[derive(Clone, Debug, PartialEq)]
pub struct RollerHelix {
    /// Design radius R_r (mm): the radius of the pattern's z = 0 (eq 1).
    pub roller_radius: f64,
    /// Design y (mm) under spindle angle 0: where the design's domain
    /// starts around the roller, so the design wraps from its first row to
    /// its last (`design_y`). A design centred on y = 0 starts at −L/2.
    pub y_start: f64,
    /// Rough passes, then the finish pass; allowances may not rise.
    pub passes: Vec<HelixPass>,
    /// Axial range of the cut in design x (mm), z_start < z_end; the helix
    /// runs from z_start to z_end.
    pub z_start: f64,
    pub z_end: f64,
    /// Radius of the blank before the servo passes (mm).
    pub blank_radius: f64,
    /// Radial depth of cut per cycle (mm); `None`: each pass is one cycle.
    pub depth_of_cut: Option<f64>,
    /// Length of the design around the roller, L_y (mm), if it is to be
    /// checked against the circumference (`check_wrap`).
    pub design_length_around: Option<f64>,
    /// Spindle speed (rad/s), for the cutting times.
    pub spindle_speed: Option<f64>,
    /// Where the points sit across the curve around the roller
    /// (`plan::chords`): each point's X moved by its chords' sag.
    pub chords: ChordPlacement,
}

impl RollerHelix {
    /// The design y (mm) under spindle angle `c` (rad): the arc R_r·c from
    /// the seam, counted from `y_start`, all the way round once.
    pub fn design_y(&self, c: f64) -> f64 {
        self.y_start + self.roller_radius * c.rem_euclid(TAU)
    }
}

/// One programmed point of a pass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RollerPoint {
    /// Spindle angle (rad), counted on from the start of the pass.
    pub c: f64,
    /// Machine Z (mm): axial position of the nose centre (= design x).
    pub z: f64,
    /// Machine X (mm): the nose centre's distance from the roller axis,
    /// R_r + centre height + the pass's finish allowance.
    pub x: f64,
}

/// The figures of one planned pass.
#[derive(Clone, Debug, PartialEq)]
pub struct PassSummary {
    pub c_step: f64,
    pub pitch: f64,
    pub finish_allowance: f64,
    /// Programmed points, the end point included.
    pub points: usize,
    /// Revolutions of the helix, (z_end − z_start) / pitch.
    pub revolutions: f64,
    /// Lowest and highest X of the points (mm).
    pub x_min: f64,
    pub x_max: f64,
    /// Extra X (mm) for each cycle, in cutting order; the last is 0.
    pub cycle_offsets: Vec<f64>,
    /// The deepest radial cut of any cycle (mm), from the stock the pass
    /// starts on (the blank, or the previous pass's allowance).
    pub max_depth_of_cut: f64,
    /// Cutting time (s) of all cycles, if a spindle speed is given.
    pub time: Option<f64>,
    /// FNV-1a 64 over the bits of every point's c, z, x, in order.
    pub fingerprint: u64,
}

/// A planned roller job.
#[derive(Clone, Debug, PartialEq)]
pub struct RollerPath {
    pub passes: Vec<PassSummary>,
    /// Every pass's points; empty when planned into a sink.
    pub points: Vec<Vec<RollerPoint>>,
    /// Lowest and highest design z over the region the nose reaches (mm),
    /// from the survey.
    pub design_z_min: f64,
    pub design_z_max: f64,
    /// Concave corners or steps the survey found in axial sections: when
    /// non-zero every nose window was scanned for several contacts.
    pub concave_corners: usize,
    /// The circumference check, if the design length was given.
    pub wrap: Option<WrapFit>,
}

/// Why a roller job cannot be planned or checked.
#[derive(Clone, Debug, PartialEq)]
pub enum RollerError {
    /// A parameter out of range, with its value.
    Invalid { what: &'static str, value: f64 },
    /// The nose radius is not below the smallest concave radius of
    /// curvature of the axial sections (section 4, eq 12): the nose cannot
    /// follow the pattern there.
    NoseTooLarge {
        nose_radius: f64,
        min_radius: f64,
        x: f64,
        y: f64,
    },
    /// The design is longer than the roller's circumference: its ends
    /// would overlap (R_r below L_y / 2π, eq 1).
    Overlap {
        circumference: f64,
        design_length: f64,
    },
    /// The blank does not cover the top of the design.
    BlankBelowDesign { blank_radius: f64, design_top: f64 },
    /// A pass leaves more allowance than the one before it.
    AllowanceRises {
        pass: usize,
        allowance: f64,
        previous: f64,
    },
    /// The design is undefined where the nose must go.
    Undefined { pass: usize, c: f64, z: f64, y: f64 },
    /// A measured edge over sections with concave corners or steps (the
    /// survey's count): the scanned contact search places a circle only.
    EdgeAtCorners { corners: usize },
}

/// The largest number of points in one pass.
const MAX_POINTS: f64 = 4e9;

/// The roller radius whose circumference is the design length around it
/// (eq 1): R_r = L_y / 2π.
pub fn roller_radius_for(design_length_around: f64) -> f64 {
    design_length_around / TAU
}

/// How a design of length L_y fits around a roller.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WrapFit {
    /// 2π R_r (mm).
    pub circumference: f64,
    pub design_length: f64,
    /// Arc (mm) left undesigned, 0 up to rounding: the design function's
    /// continuation is cut there (the paper: "filled with additional
    /// data").
    pub gap: f64,
}

/// How far (mm) a design's length around may differ from the roller's
/// circumference and still close on itself: 1 µm.
pub const WRAP_TOLERANCE: f64 = 1e-3;

/// Checks a design's length around against the roller's circumference
/// (section 2.1): a design longer by over `WRAP_TOLERANCE` overlaps itself
/// (E0134, an error), one shorter by over it leaves a gap (reported);
/// within it the design closes. This is the rule's one statement: the
/// compiler's checker reports it, and the planner runs it again as its
/// precondition.
pub fn check_wrap(roller_radius: f64, design_length_around: f64) -> Result<WrapFit, RollerError> {
    positive("roller radius", roller_radius)?;
    positive("design length around", design_length_around)?;
    let circumference = TAU * roller_radius;
    let slack = WRAP_TOLERANCE;
    if design_length_around > circumference + slack {
        return Err(RollerError::Overlap {
            circumference,
            design_length: design_length_around,
        });
    }
    let gap = circumference - design_length_around;
    Ok(WrapFit {
        circumference,
        design_length: design_length_around,
        gap: if gap.abs() <= slack { 0.0 } else { gap },
    })
}

/// The largest jumps in z and in ∂z/∂y across the seam where the roller
/// closes (design y = `y_start` + 2π R_r meets y = `y_start`), over
/// `samples` axial positions in [x0, x1]: the paper warns against a
/// discontinuous wrap-around.
pub fn seam_step(
    design: &dyn SurfaceFn,
    roller_radius: f64,
    y_start: f64,
    x: (f64, f64),
    samples: usize,
) -> (f64, f64) {
    let n = samples.max(2);
    let (mut dz, mut ds) = (0.0f64, 0.0f64);
    for i in 0..n {
        let u = x.0 + (x.1 - x.0) * i as f64 / (n - 1) as f64;
        let (a, b) = (
            design.eval(u, y_start),
            design.eval(u, y_start + TAU * roller_radius),
        );
        dz = dz.max((a[0] - b[0]).abs());
        ds = ds.max((a[2] - b[2]).abs());
    }
    (dz, ds)
}

/// The design's axial section at fixed y (the cutting plane at spindle
/// angle c = y / R_r): z(u, y), ∂z/∂x, ∂²z/∂x².
pub struct AxialSection<'a> {
    pub design: &'a dyn SurfaceFn,
    pub y: f64,
}

impl Profile for AxialSection<'_> {
    fn point(&self, u: f64) -> ProfilePoint {
        let o = self.design.eval(u, self.y);
        ProfilePoint {
            z: o[0],
            dz: o[1],
            d2z: o[3],
        }
    }
}

/// φ(u) = z(u) + sqrt(ρ² − (u − x)²) and φ′(u) at one u of the window.
fn phi(section: &dyn Profile, rho: f64, x: f64, u: f64) -> (f64, f64) {
    let p = section.point(u);
    let d = u - x;
    let s = (rho * rho - d * d).max(0.0).sqrt();
    (p.z + s, p.dz - d / s)
}

/// The exact lowest nose-centre height over `section` at axial position
/// `x`, for a section that is smooth (or has convex corners only) with ρ
/// below its concave radius of curvature: Newton's method on
/// φ′(u) = z′(u) − (u − x)/sqrt(ρ² − (u − x)²) from u = x; where Newton
/// bounces across a convex corner (a ridge between dimples) the corner is
/// closed in on (`ridge::corner_max`); else `envelope::piece_max` over the
/// whole window [x − ρ, x + ρ].
pub fn centre_height(section: &dyn Profile, rho: f64, x: f64) -> f64 {
    centre_height_from(section, rho, x, x).0
}

/// `centre_height`, Newton starting at `start` instead of at x (a start
/// outside the open window starts at x), and the contact found: the
/// height and the contact's u. Any start reaches the same stationary
/// point; a start near it (the previous point's contact along a helix)
/// saves iterations, each one a call of the surface's kernel.
pub fn centre_height_from(section: &dyn Profile, rho: f64, x: f64, start: f64) -> (f64, f64) {
    let mut u = if (start - x).abs() < rho { start } else { x };
    let mut p = section.point(u);
    // The nearest points seen on either side of the maximum (φ′ > 0 on
    // the left, < 0 on the right), and how often Newton crossed it.
    let (mut left, mut right): (Option<Probe>, Option<Probe>) = (None, None);
    let mut crossings = 0;
    let mut last_rising = None;
    for _ in 0..12 {
        let d = u - x;
        let s2 = rho * rho - d * d;
        if s2 <= 0.0 || !p.z.is_finite() {
            break;
        }
        let root = s2.sqrt();
        let dphi = p.dz - d / root;
        let ddphi = p.d2z - rho * rho / (root * root * root);
        if ddphi.is_nan() || ddphi >= 0.0 {
            break;
        }
        let step = -dphi / ddphi;
        if step.abs() <= 1e-9 {
            // The single stationary point: φ here is below the maximum by
            // ~|φ″| step² / 2, far below a picometre.
            return (p.z + root, u);
        }
        let here = Probe {
            u,
            z: p.z,
            dz: p.dz,
            d2z: p.d2z,
            phi: p.z + root,
            dphi,
            ddphi,
        };
        let rising = dphi > 0.0;
        if last_rising.is_some_and(|r| r != rising) {
            crossings += 1;
        }
        last_rising = Some(rising);
        if rising {
            left = Some(left.map_or(here, |q| if q.u > u { q } else { here }));
        } else {
            right = Some(right.map_or(here, |q| if q.u < u { q } else { here }));
        }
        u += step;
        if let (Some(lo), Some(hi)) = (left, right)
            && lo.u < hi.u
            && (u <= lo.u || u >= hi.u || crossings > 2)
        {
            // Bouncing across a corner of the section: close in on it.
            if let Some(found) = ridge::corner_max(section, rho, x, lo, hi) {
                return found;
            }
            break;
        }
        if (u - x).abs() >= rho {
            break;
        }
        p = section.point(u);
    }
    envelope::piece_max(section, rho, x, x - rho, x + rho)
}

/// Intervals the nose window is scanned in, for sections with corners.
const SCAN: usize = 64;

/// The lowest nose-centre height over a section that may have concave
/// corners or steps (several local maxima of φ): φ and φ′ at 65 points
/// across the window, every interval where φ′ turns from rising to falling
/// refined with `envelope::piece_max`, the highest kept (the samples
/// themselves included). A contact on a piece narrower than ρ / 32 can be
/// missed.
pub fn centre_height_scanned(section: &dyn Profile, rho: f64, x: f64) -> f64 {
    let inset = 1e-10 * rho.max(1.0);
    let (a, b) = (x - rho + inset, x + rho - inset);
    let mut best = f64::NEG_INFINITY;
    let mut prev: Option<(f64, f64)> = None;
    for i in 0..=SCAN {
        let u = a + (b - a) * i as f64 / SCAN as f64;
        let (f, d) = phi(section, rho, x, u);
        if f.is_nan() {
            return f64::NAN;
        }
        best = best.max(f);
        if let Some((u0, d0)) = prev
            && d0 > 0.0
            && d < 0.0
        {
            best = best.max(envelope::piece_max(section, rho, x, u0, u).0);
        }
        prev = Some((u, d));
    }
    best
}

/// The paper's offset of a discretised section (eqs 6–9): `section` is the
/// cross section in the cutting plane as points (z_c, x_c) — axial, radial
/// — in order along the profile. The numerical gradients G_z, G_x are
/// those of the point sequences (central differences inside, one-sided at
/// the ends, as MATLAB's `gradient`), f_n = 1 / sqrt(G_x² + G_z²) makes
/// (d_z, d_x) the unit tangent, and each point moves by r along the normal
/// (−d_x, d_z): z_t = z_c − r d_x, x_t = x_c + r d_z.
pub fn liu_offset(section: &[(f64, f64)], tool_radius: f64) -> Vec<(f64, f64)> {
    let n = section.len();
    if n < 2 {
        return Vec::new();
    }
    (0..n)
        .map(|i| {
            let (lo, hi, w) = if i == 0 {
                (0, 1, 1.0)
            } else if i == n - 1 {
                (n - 2, n - 1, 1.0)
            } else {
                (i - 1, i + 1, 0.5)
            };
            let g_z = w * (section[hi].0 - section[lo].0);
            let g_x = w * (section[hi].1 - section[lo].1);
            let f_n = 1.0 / (g_x * g_x + g_z * g_z).sqrt();
            let (d_x, d_z) = (g_x * f_n, g_z * f_n);
            let (z_c, x_c) = section[i];
            (z_c - tool_radius * d_x, x_c + tool_radius * d_z)
        })
        .collect()
}

/// The paper's last step: X of the tool centre at axial position `z`,
/// linearly interpolated on the offset profile (the first segment that
/// spans z); `None` outside it.
pub fn liu_centre(offset: &[(f64, f64)], z: f64) -> Option<f64> {
    offset.windows(2).find_map(|w| {
        let ((z0, x0), (z1, x1)) = (w[0], w[1]);
        if z0 <= z && z <= z1 && z1 > z0 {
            Some(x0 + (x1 - x0) * (z - z0) / (z1 - z0))
        } else {
            None
        }
    })
}

/// A diamond tool, as section 4 sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RollerTool {
    /// Nose radius ρ (mm).
    pub nose_radius: f64,
    /// Clearance angle β (rad).
    pub clearance_angle: f64,
    /// Included (opening) angle θ of the nose (rad).
    pub opening_angle: f64,
}

/// Where the design is sampled: x (axial) and y (around) ranges in mm and
/// the number of samples along each, ends included.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DesignRegion {
    pub x: (f64, f64),
    pub y: (f64, f64),
    pub samples: (usize, usize),
}

/// The section-4 figures of a design and whether a tool meets them. Radii
/// are concave (a bowl, where the nose must fit; `INFINITY` if the design
/// has none); slopes are angles (rad). All from samples on a grid.
#[derive(Clone, Debug, PartialEq)]
pub struct ToolCheck {
    /// Smallest concave radius of curvature of the axial sections, eq 12
    /// (the cutting plane), and where (x, y).
    pub min_radius_axial: f64,
    pub min_radius_axial_at: (f64, f64),
    /// Smallest concave principal radius of curvature of the flat design.
    pub min_radius_overall: f64,
    pub min_radius_overall_at: (f64, f64),
    /// Steepest slope in the cutting direction on the flat design,
    /// atan |∂z/∂y| (the paper's figure).
    pub max_slope_cutting: f64,
    /// The same on the roller, against the circle through the point:
    /// atan(R_r |∂z/∂y| / (R_r + z)).
    pub max_slope_cutting_on_roller: f64,
    /// Steepest slope of the axial sections, atan |∂z/∂x|.
    pub max_slope_axial: f64,
    /// Concave corners or steps found between neighbouring axial samples:
    /// the nose leaves them as fillets of its radius.
    pub concave_corners: usize,
    /// Samples where the design is undefined (skipped).
    pub undefined_samples: usize,
    pub z_min: f64,
    pub z_max: f64,
    /// ρ < `min_radius_axial`.
    pub radius_ok: bool,
    /// β > `max_slope_cutting_on_roller`.
    pub clearance_ok: bool,
    /// θ / 2 > `max_slope_axial`.
    pub opening_ok: bool,
}

impl ToolCheck {
    /// Whether the tool meets all three section-4 constraints.
    pub fn passes(&self) -> bool {
        self.radius_ok && self.clearance_ok && self.opening_ok
    }
}

/// The sampled figures of a design (shared by the check and the planner).
#[derive(Clone, Debug, PartialEq)]
struct Survey {
    z_min: f64,
    z_max: f64,
    /// (value, x, y).
    radius_axial: (f64, f64, f64),
    radius_overall: (f64, f64, f64),
    /// Largest |∂z/∂x|, |∂z/∂y| and R_r |∂z/∂y| / (R_r + z).
    slope_axial: f64,
    slope_around: f64,
    slope_around_roller: f64,
    corners: usize,
    undefined: usize,
}

impl Survey {
    fn empty() -> Survey {
        Survey {
            z_min: f64::INFINITY,
            z_max: f64::NEG_INFINITY,
            radius_axial: (f64::INFINITY, f64::NAN, f64::NAN),
            radius_overall: (f64::INFINITY, f64::NAN, f64::NAN),
            slope_axial: 0.0,
            slope_around: 0.0,
            slope_around_roller: 0.0,
            corners: 0,
            undefined: 0,
        }
    }

    /// Folds `o` in; ties keep the earlier sample.
    fn merge(&mut self, o: &Survey) {
        self.z_min = self.z_min.min(o.z_min);
        self.z_max = self.z_max.max(o.z_max);
        if o.radius_axial.0 < self.radius_axial.0 {
            self.radius_axial = o.radius_axial;
        }
        if o.radius_overall.0 < self.radius_overall.0 {
            self.radius_overall = o.radius_overall;
        }
        self.slope_axial = self.slope_axial.max(o.slope_axial);
        self.slope_around = self.slope_around.max(o.slope_around);
        self.slope_around_roller = self.slope_around_roller.max(o.slope_around_roller);
        self.corners += o.corners;
        self.undefined += o.undefined;
    }
}

/// The largest concave principal curvature of the graph z(x, y) from its
/// derivatives [z, p, q, r, s, t] (0 or less where there is none).
fn max_principal_curvature(o: &[f64]) -> f64 {
    let (p, q, r, s, t) = (o[1], o[2], o[3], o[4], o[5]);
    let (e, f, g) = (1.0 + p * p, p * q, 1.0 + q * q);
    let w = (1.0 + p * p + q * q).sqrt();
    let (l, m, n) = (r / w, s / w, t / w);
    let det = e * g - f * f;
    let mean = (e * n - 2.0 * f * m + g * l) / (2.0 * det);
    let gauss = (l * n - m * m) / det;
    mean + (mean * mean - gauss).max(0.0).sqrt()
}

/// Samples one row y of the region: every figure, and the concave corners
/// or steps between neighbouring samples (a slope rise or a change of z
/// that the trapezoid rule on the exact derivatives does not explain).
fn survey_row(design: &dyn SurfaceFn, xs: &[f64], y: f64, roller_radius: f64) -> Survey {
    let ys = vec![y; xs.len()];
    let mut out = vec![0.0; 6 * xs.len()];
    design.eval_batch(xs, &ys, &mut out);
    let mut s = Survey::empty();
    let mut prev: Option<(f64, &[f64])> = None;
    for (&x, o) in xs.iter().zip(out.chunks_exact(6)) {
        if !o.iter().all(|v| v.is_finite()) {
            s.undefined += 1;
            prev = None;
            continue;
        }
        let (z, p, q, r) = (o[0], o[1], o[2], o[3]);
        s.z_min = s.z_min.min(z);
        s.z_max = s.z_max.max(z);
        if r > 0.0 {
            let rc = (1.0 + p * p).powf(1.5) / r;
            if rc < s.radius_axial.0 {
                s.radius_axial = (rc, x, y);
            }
        }
        let k = max_principal_curvature(o);
        if k > 0.0 && 1.0 / k < s.radius_overall.0 {
            s.radius_overall = (1.0 / k, x, y);
        }
        s.slope_axial = s.slope_axial.max(p.abs());
        s.slope_around = s.slope_around.max(q.abs());
        s.slope_around_roller = s
            .slope_around_roller
            .max(roller_radius * q.abs() / (roller_radius + z));
        if let Some((x0, o0)) = prev {
            let h = x - x0;
            let slope_rise = (p - o0[1]) - 0.5 * (r + o0[3]) * h;
            // A continuous section rises between the two end slopes times
            // h (whatever kink lies between), give or take its curvature:
            // only a rise outside that is a step. A convex kink (a ridge
            // where neighbouring dimples meet) is neither.
            let dz = z - o0[0];
            let bend = 0.5 * r.abs().max(o0[3].abs()) * h * h + 1e-9;
            let step = dz < p.min(o0[1]) * h - bend || dz > p.max(o0[1]) * h + bend;
            if slope_rise > 1e-4 + 0.1 * (p - o0[1]).abs() || step {
                s.corners += 1;
            }
        }
        prev = Some((x, o));
    }
    s
}

/// Samples the region row by row in parallel; folded in row order.
fn survey(design: &(dyn SurfaceFn + Sync), region: &DesignRegion, roller_radius: f64) -> Survey {
    let (nx, ny) = region.samples;
    let at = |r: (f64, f64), n: usize, i: usize| r.0 + (r.1 - r.0) * i as f64 / (n - 1) as f64;
    let xs: Vec<f64> = (0..nx).map(|i| at(region.x, nx, i)).collect();
    let rows: Vec<Survey> = (0..ny)
        .into_par_iter()
        .map(|j| survey_row(design, &xs, at(region.y, ny, j), roller_radius))
        .collect();
    let mut s = Survey::empty();
    for r in &rows {
        s.merge(r);
    }
    s
}

fn positive(what: &'static str, value: f64) -> Result<f64, RollerError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(RollerError::Invalid { what, value })
    }
}

fn valid_region(region: &DesignRegion) -> Result<(), RollerError> {
    for (what, r) in [("region x", region.x), ("region y", region.y)] {
        if !(r.0.is_finite() && r.1.is_finite() && r.1 > r.0) {
            return Err(RollerError::Invalid { what, value: r.1 });
        }
    }
    let (nx, ny) = region.samples;
    if nx.min(ny) < 2 || nx.saturating_mul(ny) > 1 << 28 {
        return Err(RollerError::Invalid {
            what: "region samples (2 to 2^28 in all)",
            value: nx.min(ny) as f64,
        });
    }
    Ok(())
}

/// The section-4 tool checks over a region of the design (the paper:
/// tool radius below the minimum radius of curvature, eq 12; clearance
/// angle above the steepest slope in the cutting direction; half the
/// opening angle above the steepest axial slope).
pub fn check_roller_tool(
    design: &(dyn SurfaceFn + Sync),
    region: &DesignRegion,
    roller_radius: f64,
    tool: &RollerTool,
) -> Result<ToolCheck, RollerError> {
    positive("roller radius", roller_radius)?;
    positive("nose radius", tool.nose_radius)?;
    positive("clearance angle", tool.clearance_angle)?;
    positive("opening angle", tool.opening_angle)?;
    valid_region(region)?;
    let s = survey(design, region, roller_radius);
    let slope_cut_roller = s.slope_around_roller.atan();
    let slope_axial = s.slope_axial.atan();
    Ok(ToolCheck {
        min_radius_axial: s.radius_axial.0,
        min_radius_axial_at: (s.radius_axial.1, s.radius_axial.2),
        min_radius_overall: s.radius_overall.0,
        min_radius_overall_at: (s.radius_overall.1, s.radius_overall.2),
        max_slope_cutting: s.slope_around.atan(),
        max_slope_cutting_on_roller: slope_cut_roller,
        max_slope_axial: slope_axial,
        concave_corners: s.corners,
        undefined_samples: s.undefined,
        z_min: s.z_min,
        z_max: s.z_max,
        radius_ok: tool.nose_radius < s.radius_axial.0,
        clearance_ok: tool.clearance_angle > slope_cut_roller,
        opening_ok: 0.5 * tool.opening_angle > slope_axial,
    })
}

/// Largest spacing (mm) of the planner's survey of the design.
const SURVEY_STEP: f64 = 0.01;
/// Largest number of survey samples along either direction.
const SURVEY_MAX: usize = 4097;

/// The number of steps of a pass (its points are steps + 1) and its total
/// spindle angle.
fn pass_steps(h: &RollerHelix, pass: &HelixPass) -> Result<(usize, f64), RollerError> {
    let total = TAU * (h.z_end - h.z_start) / pass.pitch;
    let ratio = total / pass.c_step;
    if !(ratio.is_finite() && ratio < MAX_POINTS) {
        return Err(RollerError::Invalid {
            what: "points per pass (at most 4e9)",
            value: ratio,
        });
    }
    // A whole number of steps up to rounding is that number.
    let steps = (ratio - 1e-9 * ratio.max(1.0)).ceil().max(1.0) as usize;
    Ok((steps, total))
}

fn validate(h: &RollerHelix, rho: f64) -> Result<(), RollerError> {
    positive("roller radius", h.roller_radius)?;
    positive("nose radius", rho)?;
    positive("blank radius", h.blank_radius)?;
    if !(h.z_start.is_finite() && h.z_end.is_finite() && h.z_end > h.z_start) {
        return Err(RollerError::Invalid {
            what: "z_end (must lie beyond z_start)",
            value: h.z_end,
        });
    }
    if let Some(d) = h.depth_of_cut {
        positive("depth of cut", d)?;
    }
    if let Some(w) = h.spindle_speed {
        positive("spindle speed", w)?;
    }
    if h.passes.is_empty() {
        return Err(RollerError::Invalid {
            what: "number of passes",
            value: 0.0,
        });
    }
    for (i, p) in h.passes.iter().enumerate() {
        positive("pitch", p.pitch)?;
        positive("c step", p.c_step)?;
        if p.c_step > TAU {
            return Err(RollerError::Invalid {
                what: "c step (at most one revolution)",
                value: p.c_step,
            });
        }
        if !(p.finish_allowance.is_finite() && p.finish_allowance >= 0.0) {
            return Err(RollerError::Invalid {
                what: "finish allowance",
                value: p.finish_allowance,
            });
        }
        if i > 0 && p.finish_allowance > h.passes[i - 1].finish_allowance {
            return Err(RollerError::AllowanceRises {
                pass: i,
                allowance: p.finish_allowance,
                previous: h.passes[i - 1].finish_allowance,
            });
        }
        pass_steps(h, p)?;
    }
    Ok(())
}

/// The cycles of a pass that starts on `stock` (mm of radius above the
/// design) and leaves `allowance`: extra X offsets stepping down by the
/// depth of cut to 0 (the first cycle cuts at most the depth of cut), and
/// the deepest cut.
fn cycles(stock: f64, allowance: f64, depth: Option<f64>) -> (Vec<f64>, f64) {
    let removed = (stock - allowance).max(0.0);
    match depth {
        None => (vec![0.0], removed),
        Some(d) => {
            let n = ((removed / d - 1e-9).ceil().max(1.0)) as usize;
            let offsets = (0..n).rev().map(|j| j as f64 * d).collect();
            (offsets, removed.min(d))
        }
    }
}

/// The helix's cutting time at the spindle's pace (s), before any point is
/// planned: each pass's cycles (from the design's survey, as
/// `plan_roller_helix_sectioned` takes them) times its turns over the
/// spindle speed; `None` without a spindle speed. What a header states;
/// moves the feed limit slows (known once planned) add to it.
pub fn spindle_time(
    h: &RollerHelix,
    nose_radius: f64,
    design: &(dyn SurfaceFn + Sync),
) -> Result<Option<f64>, RollerError> {
    validate(h, nose_radius)?;
    let Some(w) = h.spindle_speed else {
        return Ok(None);
    };
    let s = survey_reach(h, nose_radius, design)?;
    let mut stock = h.blank_radius - (h.roller_radius + s.z_min);
    let mut time = 0.0;
    for pass in &h.passes {
        let (_, total) = pass_steps(h, pass)?;
        let (offsets, _) = cycles(stock, pass.finish_allowance, h.depth_of_cut);
        stock = pass.finish_allowance;
        time += offsets.len() as f64 * total / w;
    }
    Ok(Some(time))
}

/// Plans every pass and returns their points, one `Vec` per pass (see
/// `plan_roller_helix_into` for the figures and the streaming form).
pub fn plan_roller_helix(
    h: &RollerHelix,
    nose_radius: f64,
    design: &(dyn SurfaceFn + Sync),
) -> Result<RollerPath, RollerError> {
    let mut points: Vec<Vec<RollerPoint>> = vec![Vec::new(); h.passes.len()];
    let mut path = plan_roller_helix_into(h, nose_radius, design, |pass, pts| {
        points[pass].extend_from_slice(pts)
    })?;
    path.points = points;
    Ok(path)
}

/// Plans every pass, handing its points in order to `sink(pass, points)`
/// a revolution at a time (a chunk of ⌈2π / Δc⌉ points). Before any
/// point, the design is surveyed over the nose's reach (axial
/// [z_start − ρ, z_end + ρ], all the way around, samples at most 0.01 mm
/// and ρ/16 apart, up to 4097 each way): the nose must be below the
/// smallest concave axial radius of curvature, the blank above the design,
/// and concave corners switch the contact search to the scanned one. The
/// design must be defined over every nose window; where it is not, the
/// point is reported as `RollerError::Undefined`.
pub fn plan_roller_helix_into(
    h: &RollerHelix,
    nose_radius: f64,
    design: &(dyn SurfaceFn + Sync),
    sink: impl FnMut(usize, &[RollerPoint]) + Send,
) -> Result<RollerPath, RollerError> {
    plan_roller_helix_sectioned(h, nose_radius, design, design, sink)
}

/// `plan_roller_helix_into`, the contact searches evaluating the design's
/// axial sections with `section`: the design's own evaluator, or one that
/// computes only z, ∂z/∂x and ∂²z/∂x² of it, bit for bit as the design's
/// does (a kernel compiled from `SurfaceTape::axial_section`, with half
/// the work per call). The survey and the wrap's seam use `design`.
pub fn plan_roller_helix_sectioned(
    h: &RollerHelix,
    nose_radius: f64,
    design: &(dyn SurfaceFn + Sync),
    section: &(dyn SurfaceFn + Sync),
    sink: impl FnMut(usize, &[RollerPoint]) + Send,
) -> Result<RollerPath, RollerError> {
    plan_roller_helix_edged(h, &Nose::circle(nose_radius), design, section, sink)
}

/// `plan_roller_helix_sectioned` with the nose as measured: where `nose`
/// has an edge, each centre is the lowest that clears the axial section
/// with that edge (`envelope::edged_max` from the circle's contact; the
/// module doc, "Measured edge"). A design whose sections have concave
/// corners or steps is refused with an edge (`RollerError::EdgeAtCorners`):
/// its scanned contact search places a circle only.
pub fn plan_roller_helix_edged(
    h: &RollerHelix,
    nose: &Nose,
    design: &(dyn SurfaceFn + Sync),
    section: &(dyn SurfaceFn + Sync),
    mut sink: impl FnMut(usize, &[RollerPoint]) + Send,
) -> Result<RollerPath, RollerError> {
    let rho = nose.radius;
    validate(h, rho)?;
    let wrap = match h.design_length_around {
        Some(l) => Some(check_wrap(h.roller_radius, l)?),
        None => None,
    };
    let s = survey_reach(h, rho, design)?;
    let scanned = s.corners > 0;
    if scanned && nose.edge.is_some() {
        return Err(RollerError::EdgeAtCorners { corners: s.corners });
    }
    let centre = |y: f64, x: f64, start: f64| {
        let section = AxialSection { design: section, y };
        let (w, u) = if scanned {
            (centre_height_scanned(&section, rho, x), x)
        } else {
            centre_height_from(&section, rho, x, start)
        };
        match nose.edge {
            Some(_) if w.is_finite() => {
                envelope::edged_max(&section, nose, x, u).unwrap_or((f64::NAN, u))
            }
            _ => (w, u),
        }
    };
    let mut summaries = Vec::with_capacity(h.passes.len());
    // The radial stock above the design's lowest point.
    let mut stock = h.blank_radius - (h.roller_radius + s.z_min);
    for (i, pass) in h.passes.iter().enumerate() {
        let (steps, total) = pass_steps(h, pass)?;
        let cycles = cycles(stock, pass.finish_allowance, h.depth_of_cut);
        stock = pass.finish_allowance;
        let plan = PassPlan {
            h,
            index: i,
            pass,
            steps,
            total,
        };
        summaries.push(plan.run(&centre, cycles, &mut sink)?);
    }
    Ok(RollerPath {
        passes: summaries,
        points: Vec::new(),
        design_z_min: s.z_min,
        design_z_max: s.z_max,
        concave_corners: s.corners,
        wrap,
    })
}

/// The design surveyed over the nose's reach (see
/// `plan_roller_helix_into`), or why the nose or the blank cannot cut it.
fn survey_reach(
    h: &RollerHelix,
    rho: f64,
    design: &(dyn SurfaceFn + Sync),
) -> Result<Survey, RollerError> {
    let r_r = h.roller_radius;
    let step = SURVEY_STEP.min(rho / 16.0);
    let count = |len: f64| ((len / step).ceil() as usize + 1).clamp(2, SURVEY_MAX);
    let x_range = (h.z_start - rho, h.z_end + rho);
    let region = DesignRegion {
        x: x_range,
        y: (h.y_start, h.y_start + TAU * r_r),
        samples: (count(x_range.1 - x_range.0), count(TAU * r_r)),
    };
    let s = survey(design, &region, r_r);
    if rho >= s.radius_axial.0 {
        return Err(RollerError::NoseTooLarge {
            nose_radius: rho,
            min_radius: s.radius_axial.0,
            x: s.radius_axial.1,
            y: s.radius_axial.2,
        });
    }
    if h.blank_radius < r_r + s.z_max {
        return Err(RollerError::BlankBelowDesign {
            blank_radius: h.blank_radius,
            design_top: r_r + s.z_max,
        });
    }
    Ok(s)
}

/// One pass of a helix: `steps` C steps to its end at C = `total` (rad).
struct PassPlan<'a> {
    h: &'a RollerHelix,
    index: usize,
    pass: &'a HelixPass,
    steps: usize,
    total: f64,
}

impl PassPlan<'_> {
    /// Plans the pass's points, a revolution at a time in parallel
    /// batches, hands them to `sink` in order, and sums them up.
    /// `centre(y, x, start)` is the nose-centre height over the design
    /// and the contact's u, its search started at u = `start`;
    /// `(cycle_offsets, max_depth_of_cut)` come from `cycles`.
    fn run(
        &self,
        centre: &(impl Fn(f64, f64, f64) -> (f64, f64) + Sync),
        (cycle_offsets, max_depth_of_cut): (Vec<f64>, f64),
        sink: &mut (impl FnMut(usize, &[RollerPoint]) + Send),
    ) -> Result<PassSummary, RollerError> {
        let (h, pass, steps, total) = (self.h, self.pass, self.steps, self.total);
        let r_r = h.roller_radius;
        // X on the exact path at spindle angle c and axial position z,
        // and the contact's u, its search started at u = `start`.
        let exact_from = |c: f64, z: f64, start: f64| -> (f64, f64) {
            let (height, contact) = centre(h.design_y(c), z, start);
            (r_r + height + pass.finish_allowance, contact)
        };
        let exact = |c: f64, z: f64| exact_from(c, z, z).0;
        // Point k, its contact searched from the previous point's contact
        // `offset` (u − x) on: one C step on, it has moved a fraction of a
        // micrometre.
        let point = |k: usize, offset: &mut f64| -> Result<RollerPoint, RollerError> {
            let (c, z) = if k == steps {
                (total, h.z_end)
            } else {
                let c = k as f64 * pass.c_step;
                (c, h.z_start + pass.pitch * c / TAU)
            };
            let (x, contact) = exact_from(c, z, z + *offset);
            *offset = contact - z;
            if x.is_finite() {
                Ok(RollerPoint { c, z, x })
            } else {
                Err(RollerError::Undefined {
                    pass: self.index,
                    c,
                    z,
                    y: h.design_y(c),
                })
            }
        };
        // ⌈2π / Δc⌉, a whole number up to rounding being that number.
        let per_chunk = ((TAU / pass.c_step * (1.0 - 1e-12)).ceil() as usize).max(1);
        let chunks = (steps + 1).div_ceil(per_chunk);
        let mut sum = PassSummary {
            c_step: pass.c_step,
            pitch: pass.pitch,
            finish_allowance: pass.finish_allowance,
            points: 0,
            revolutions: (h.z_end - h.z_start) / pass.pitch,
            x_min: f64::INFINITY,
            x_max: f64::NEG_INFINITY,
            time: h
                .spindle_speed
                .map(|w| cycle_offsets.len() as f64 * total / w),
            cycle_offsets,
            max_depth_of_cut,
            fingerprint: 0xcbf2_9ce4_8422_2325,
        };
        let mut undefined = None;
        let make = |j: usize| -> Result<Vec<RollerPoint>, RollerError> {
            let k0 = j * per_chunk;
            // Each revolution starts its search at u = x: its points depend
            // on their index alone, whichever thread makes them.
            let mut offset = 0.0;
            let k1 = (k0 + per_chunk).min(steps + 1);
            if h.chords == ChordPlacement::OnPath {
                return (k0..k1).map(|k| point(k, &mut offset)).collect();
            }
            // A point beyond each end, for the end chords.
            let lo = k0.saturating_sub(1);
            let around: Vec<RollerPoint> = (lo..(k1 + 1).min(steps + 1))
                .map(|k| point(k, &mut offset))
                .collect::<Result<_, _>>()?;
            Ok(placed(h.chords, &around, k0 - lo, k1 - k0, &exact))
        };
        let take = |pts: Result<Vec<RollerPoint>, RollerError>| match pts {
            Ok(pts) => {
                sum.tally(&pts);
                sink(self.index, &pts);
                ControlFlow::Continue(())
            }
            Err(e) => {
                undefined = Some(e);
                ControlFlow::Break(())
            }
        };
        crate::plan::stream::in_order(chunks, 32, make, take);
        if let Some(e) = undefined {
            return Err(e);
        }
        Ok(sum)
    }
}

/// `count` points of `around` from `first` on, each X moved by the bands
/// of the chords it joins (`plan::chords`): how far the exact path, X =
/// `exact(c, z)`, lies above each chord at its quarters and middle. (Not
/// from the points' second differences: where dimples meet in a sharp
/// ridge around the roller those say nothing of the chord across it.)
fn placed(
    placement: ChordPlacement,
    around: &[RollerPoint],
    first: usize,
    count: usize,
    exact: &impl Fn(f64, f64) -> f64,
) -> Vec<RollerPoint> {
    let band = |i: Option<usize>| -> Option<chords::Band> {
        let i = i.filter(|&i| i + 1 < around.len())?;
        let (p, q) = (around[i], around[i + 1]);
        let above = |t: f64| {
            let at = |a: f64, b: f64| a + t * (b - a);
            exact(at(p.c, q.c), at(p.z, q.z)) - at(p.x, q.x)
        };
        let d = [above(0.25), above(0.5), above(0.75)];
        // An undefined path between two defined points moves nothing.
        Some(chords::Band::from_quarters(
            d.map(|v| if v.is_finite() { v } else { 0.0 }),
        ))
    };
    (first..first + count)
        .map(|i| {
            let mut p = around[i];
            p.x += placement.offset(band(i.checked_sub(1)), band(Some(i)));
            p
        })
        .collect()
}

impl PassSummary {
    /// Counts `pts`, widens the X range over them and folds their bits
    /// into the fingerprint (FNV-1a over c, z, x of each point).
    fn tally(&mut self, pts: &[RollerPoint]) {
        for p in pts {
            self.points += 1;
            self.x_min = self.x_min.min(p.x);
            self.x_max = self.x_max.max(p.x);
            for v in [p.c, p.z, p.x] {
                for b in v.to_bits().to_le_bytes() {
                    self.fingerprint ^= u64::from(b);
                    self.fingerprint = self.fingerprint.wrapping_mul(0x0100_0000_01b3);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests;
