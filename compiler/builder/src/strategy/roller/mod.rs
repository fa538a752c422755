//! Lowering a `roller_helix` job: a flat design wrapped onto a roller, cut
//! on a slow-tool-servo lathe. The section-4 tool checks (Liu et al.: the
//! nose against the design's concave radius in the cutting plane, the
//! clearance and included angles against its slopes) and the spindle limit
//! are made here, before the helix is planned; so is a measured edge's
//! (`edge_profile`) cover of the angles of contact.

mod build;
pub(crate) mod errors;
mod estimate;
pub mod report;

use lensc_grammar::Diagnostic;
use lensc_runtime::machine::tool::MeasuredEdge;
use lensc_runtime::plan::chords::ChordPlacement;
use lensc_runtime::plan::roller::{
    DesignRegion, HelixPass, RollerHelix, RollerTool, ToolCheck, check_roller_tool,
};
use lensc_runtime::post::Dialect;
use lensc_runtime::surface::analysis::Domain;
use lensc_runtime::surface::ir::SurfaceFn;

use crate::job::{Evaluate, JobHead, Parts, all_clear};
use lensc_lang::check::trim_num;
use lensc_lang::codes;
use lensc_lang::schema::Surface;
use lensc_lang::schema::strategies::{HelixPassParams, RollerHelixParams};

/// A roller job, typed.
pub struct RollerSpec {
    pub head: JobHead,
    pub helix: RollerHelix,
    pub tool: RollerTool,
    /// What the tool check found on the design (for the report).
    pub check: ToolCheck,
    /// The design's extent around the roller, design y (mm).
    pub design_y: (f64, f64),
    /// The nose centre's radius (mm) clear of the blank.
    pub safe_x: f64,
    /// The spindle speed (rad/s).
    pub spindle_speed: f64,
    /// The machine's feed limit (mm/s): moves the spindle's pace would
    /// take faster are slowed to it.
    pub max_feed: f64,
    /// The nose's measured edge, if the tool names one (the planner
    /// places each centre by it, the simulation sweeps it), its report,
    /// and where the tool names it.
    pub edge: Option<(MeasuredEdge, crate::edge::EdgeReport)>,
    pub edge_site: Option<(lensc_grammar::FileId, lensc_grammar::Span)>,
}

impl crate::strategy::Strategy for RollerSpec {
    const NAMES: &'static [&'static str] = &["roller_helix"];
    const SETUP: lensc_runtime::post::Setup = lensc_runtime::post::Setup::Lathe;
    const WINDOWED: bool = true;
    const LENGTH_AXES: Option<u32> = None;
    fn lower(p: &Parts, dialect: Dialect, evaluate: Evaluate) -> Result<Self, Vec<Diagnostic>> {
        lower(p, dialect, evaluate)
    }
    fn head(&self) -> &JobHead {
        &self.head
    }
    fn path_tolerance(&self) -> Option<f64> {
        None
    }
    fn estimate(&self, _evaluate: Evaluate) -> crate::job::Estimate {
        estimate::estimate(self)
    }
    fn tiles(
        &self,
        window: &lensc_runtime::verify::window::Window,
    ) -> Option<Vec<lensc_runtime::verify::window::Tile>> {
        Some(lensc_runtime::verify::window::split(
            &window.roller(self.helix.roller_radius, self.helix.y_start),
            None,
        ))
    }
    fn part_extent(&self) -> ((f64, f64), (f64, f64)) {
        crate::job::window::roller_extent(
            &self.head.surface.lowered.domain,
            (self.helix.z_start, self.helix.z_end),
            self.design_y,
        )
    }
    fn warnings_before_planning(&self) -> Vec<Diagnostic> {
        let (design, _) = crate::evaluate::evaluator(&self.head.surface.lowered.tape);
        build::seam_warning(self, design.as_ref())
            .into_iter()
            .collect()
    }
    fn build(
        &self,
        cx: &crate::context::BuildContext,
    ) -> Result<crate::output::Built, Vec<Diagnostic>> {
        build::build(self, cx)
    }
}

pub(crate) fn lower(
    p: &Parts,
    dialect: Dialect,
    evaluate: Evaluate,
) -> Result<RollerSpec, Vec<Diagnostic>> {
    let roller_radius = roller_radius(p)?;
    let st = RollerHelixParams::read(p.strategy).map_err(|d| vec![d])?;
    let t = &p.tool_params;
    let lowered = p.lowered().map_err(|d| vec![d])?;
    let Domain::Rect {
        x: design_x,
        y: design_y,
    } = lowered.domain
    else {
        return Err(vec![p.error(
            codes::UNSUPPORTED_COMBINATION,
            "a wrapped design needs a rectangular domain (x along the roller, y around it)".into(),
        )]);
    };
    let kernel = evaluate(&lowered.tape);
    let rt = RollerTool {
        nose_radius: p.tool_needs(t.nose_radius, "nose_radius")?,
        clearance_angle: p.tool_needs(t.clearance, "clearance")?,
        opening_angle: t.included_angle.unwrap_or(std::f64::consts::PI),
    };
    let region = DesignRegion {
        x: design_x,
        y: design_y,
        samples: (401, 401),
    };
    let check = check_roller_tool(kernel.as_ref(), &region, roller_radius, &rt)
        .map_err(|e| vec![errors::error(e, p.site())])?;
    let mut errors = tool_errors(p, &rt, &check);
    let spindle_speed = st.spindle_speed;
    errors.extend(p.spindle_limit(spindle_speed));
    let edge = crate::edge::measured_edge(p).map_err(|d| vec![d])?;
    let (z_start, z_end) = st.z.unwrap_or(design_x);
    if let Some((measured, _)) = &edge {
        // The contacts lie within ρ·sin of the steepest axial slope of
        // the nose centres' axial range.
        let reach = rt.nose_radius * check.max_slope_axial.sin();
        let x = (
            (z_start - reach).max(design_x.0),
            (z_end + reach).min(design_x.1),
        );
        errors.extend(crate::edge::uncovered_roller(
            p,
            &measured.profile,
            kernel.as_ref(),
            x,
            design_y,
        ));
    }
    all_clear(errors)?;
    let helix = RollerHelix {
        roller_radius,
        // Spindle angle 0 is the design's first row: a design centred on
        // y = 0 wraps from −L/2, not from its middle.
        y_start: design_y.0,
        passes: passes(&st),
        z_start,
        z_end,
        // By default the blank just covers the design: its highest point,
        // found on the tool check's grid and by the refined analysis, or
        // the roller's own radius (an array's land, z = 0, around it).
        blank_radius: st.blank_radius.unwrap_or_else(|| {
            let top =
                lensc_runtime::surface::analysis::analyse(kernel.as_ref(), &lowered.domain, 201)
                    .sag_max
                    .value;
            roller_radius + check.z_max.max(top).max(0.0) + 1e-6
        }),
        depth_of_cut: None,
        design_length_around: Some(design_y.1 - design_y.0),
        spindle_speed: Some(spindle_speed),
        chords: ChordPlacement::OnPath,
    };
    let finish_step = helix.passes.last().map_or(0.0, |f| f.c_step);
    let sag = chord_sag(kernel.as_ref(), &region, roller_radius * finish_step);
    let helix = RollerHelix {
        chords: crate::job::chords::placement(
            p,
            crate::job::chords::ChordPath {
                tolerance: None,
                sag,
                fit: 0.0,
                long_chords: false,
                holds: p.holds(<RollerSpec as crate::strategy::Strategy>::LENGTH_AXES),
            },
        ),
        ..helix
    };
    let retract = st.retract.unwrap_or(1.0);
    Ok(RollerSpec {
        head: p.head(dialect, lowered),
        safe_x: helix.blank_radius + rt.nose_radius + retract,
        helix,
        tool: rt,
        check,
        design_y,
        spindle_speed,
        max_feed: p.machine_params.max_feed,
        edge,
        edge_site: p.tool_params.edge_profile.as_ref().map(|e| e.site),
    })
}

/// The largest sag (mm) of a chord `arc` mm long around the roller where
/// the design bulges out of the material (∂²z/∂y² < 0), on the tool
/// check's grid: −arc² ∂²z/∂y² / 8. The nose centre's path is flatter
/// than the design there (its radius of curvature the design's plus ρ),
/// so its chords sag no more than this.
fn chord_sag(design: &dyn SurfaceFn, region: &DesignRegion, arc: f64) -> f64 {
    let (nx, ny) = region.samples;
    let at = |(a, b): (f64, f64), i: usize, n: usize| a + (b - a) * i as f64 / (n - 1) as f64;
    let mut bulge = 0.0f64;
    for i in 0..nx {
        for j in 0..ny {
            let o = design.eval(at(region.x, i, nx), at(region.y, j, ny));
            if o[5].is_finite() {
                bulge = bulge.max(-o[5]);
            }
        }
    }
    arc * arc * bulge / 8.0
}

/// The roller's radius (mm), or E0131 for each part that cannot make a
/// roller helix: it needs an `sts_lathe`, a round nose, and a design
/// wrapped onto a roller.
fn roller_radius(p: &Parts) -> Result<f64, Vec<Diagnostic>> {
    let surface = p.surface;
    let mut errors = p.needs_servo_lathe("roller helix turning", "sts_lathe", " (C, Z, X)");
    let roller = match &p.surface_params {
        Surface::Wrap(w) => Some(w.onto.radius),
        _ => None,
    };
    if roller.is_none() {
        errors.push(
            p.error(
                codes::UNSUPPORTED_COMBINATION,
                format!(
                    "roller helix turning needs a design wrapped onto a roller; this surface is a `{}`",
                    surface.kind.name
                ),
            )
            .with_help("write `wrap(design, onto: roller(radius: …))`"),
        );
    }
    roller.filter(|_| errors.is_empty()).ok_or(errors)
}

/// The rough pass, if the strategy has one, then the finish pass.
fn passes(st: &RollerHelixParams) -> Vec<HelixPass> {
    let pass = |p: HelixPassParams, finish_allowance: f64| HelixPass {
        c_step: p.c_step,
        pitch: p.pitch,
        finish_allowance,
    };
    let rough = st.rough.map(|(rough, allowance)| pass(rough, allowance));
    rough.into_iter().chain([pass(st.finish, 0.0)]).collect()
}

/// What the tool check found wrong: the nose, the clearance, the opening.
fn tool_errors(p: &Parts, rt: &RollerTool, check: &ToolCheck) -> Vec<Diagnostic> {
    let deg = |a: f64| trim_num(a.to_degrees());
    let mut errors = Vec::new();
    if !check.radius_ok {
        errors.push(p.error(
            codes::NOSE_TOO_LARGE,
            format!(
                "the tool's nose radius ({} mm) is not below the design's smallest concave radius of curvature in the cutting plane ({} mm, at ({}, {}) mm; Liu et al. eq 12)",
                trim_num(rt.nose_radius),
                trim_num(check.min_radius_axial),
                trim_num(check.min_radius_axial_at.0),
                trim_num(check.min_radius_axial_at.1)
            ),
        ).with_help(format!("use a tool whose `nose_radius` is below {} mm", trim_num(check.min_radius_axial))));
    }
    if !check.clearance_ok {
        errors.push(p.error(
            codes::CLEARANCE_TOO_SMALL,
            format!(
                "the clearance angle ({}°) is not above the steepest slope in the cutting direction, around the roller ({}°)",
                deg(rt.clearance_angle),
                deg(check.max_slope_cutting_on_roller)
            ),
        ).with_help(format!("use a tool whose `clearance` is above {}°", deg(check.max_slope_cutting_on_roller))));
    }
    if !check.opening_ok {
        errors.push(p.error(
            codes::CLEARANCE_TOO_SMALL,
            format!(
                "half the tool's included angle ({}°) is not above the steepest axial slope ({}°)",
                deg(rt.opening_angle / 2.0),
                deg(check.max_slope_axial)
            ),
        ).with_help(format!("use a tool whose `included_angle` is above {}°", deg(2.0 * check.max_slope_axial))));
    }
    errors
}
