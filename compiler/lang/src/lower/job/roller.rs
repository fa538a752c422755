//! Lowering a `roller_helix` job: a flat design wrapped onto a roller, cut
//! on a slow-tool-servo lathe. The section-4 tool checks (Liu et al.: the
//! nose against the design's concave radius in the cutting plane, the
//! clearance and included angles against its slopes) and the spindle limit
//! are made here, before the helix is planned.

use lensc_grammar::Diagnostic;
use lensc_runtime::plan::roller::{
    DesignRegion, HelixPass, RollerHelix, RollerTool, ToolCheck, check_roller_tool,
};
use lensc_runtime::post::Dialect;
use lensc_runtime::surface::analysis::Domain;

use super::{Evaluate, JobHead, Parts};
use crate::check::trim_num;
use crate::codes;
use crate::value;

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
}

pub(super) fn lower(
    p: &Parts,
    dialect: Dialect,
    evaluate: Evaluate,
) -> Result<RollerSpec, Vec<Diagnostic>> {
    let (surface, tool, machine, strategy) = (p.surface, p.tool, p.machine, p.strategy);
    let err = |code: &'static str, msg: String| p.error(code, msg);
    let mut errors = Vec::new();
    if machine.kind.name != "sts_lathe" {
        errors.push(err(
            codes::UNSUPPORTED_COMBINATION,
            format!(
                "roller helix turning needs an `sts_lathe` (C, Z, X); this machine is a `{}`",
                machine.kind.name
            ),
        ));
    }
    if tool.kind.name != "round_nose" {
        errors.push(err(
            codes::UNSUPPORTED_COMBINATION,
            format!(
                "roller helix turning needs a `round_nose` tool; this is a `{}`",
                tool.kind.name
            ),
        ));
    }
    let roller = (surface.kind.name == "wrap")
        .then(|| value::object(&surface.fields, "onto"))
        .flatten()
        .and_then(|r| value::num(&r.fields, "radius"));
    if roller.is_none() {
        errors.push(
            err(
                codes::UNSUPPORTED_COMBINATION,
                format!(
                    "roller helix turning needs a design wrapped onto a roller; this surface is a `{}`",
                    surface.kind.name
                ),
            )
            .with_help("write `wrap(design, onto: roller(radius: …))`"),
        );
    }
    let Some(roller_radius) = roller.filter(|_| errors.is_empty()) else {
        return Err(errors);
    };
    let (t, st) = (&tool.fields, &strategy.fields);
    let lowered = p.lowered().map_err(|d| vec![d])?;
    let Domain::Rect {
        x: design_x,
        y: design_y,
    } = lowered.domain
    else {
        return Err(vec![err(
            codes::UNSUPPORTED_COMBINATION,
            "a wrapped design needs a rectangular domain (x along the roller, y around it)".into(),
        )]);
    };
    let kernel = evaluate(&lowered.tape);
    let rt = RollerTool {
        nose_radius: value::num(t, "nose_radius").expect("required"),
        clearance_angle: value::num(t, "clearance").expect("required"),
        opening_angle: value::num(t, "included_angle").unwrap_or(std::f64::consts::PI),
    };
    let region = DesignRegion {
        x: design_x,
        y: design_y,
        samples: (401, 401),
    };
    let check = check_roller_tool(kernel.as_ref(), &region, roller_radius, &rt)
        .map_err(|e| vec![super::roller_diagnostic(e, p.site())])?;
    errors.extend(tool_errors(p, &rt, &check));
    let spindle_speed = value::num(st, "spindle_speed").expect("required");
    let max_spindle = p.max_spindle_speed();
    if spindle_speed > max_spindle {
        let rpm = |w: f64| trim_num(w * 60.0 / (2.0 * std::f64::consts::PI));
        errors.push(err(
            codes::SPINDLE_TOO_FAST,
            format!(
                "the spindle speed ({} rpm) is above the machine's maximum ({} rpm)",
                rpm(spindle_speed),
                rpm(max_spindle)
            ),
        ));
    }
    if !errors.is_empty() {
        return Err(errors);
    }
    let (z_start, z_end) = value::range(st, "z").unwrap_or(design_x);
    let helix = RollerHelix {
        roller_radius,
        passes: passes(st),
        z_start,
        z_end,
        // By default the blank just covers the design: its highest point,
        // found on the tool check's grid and by the refined analysis, or
        // the roller's own radius (an array's land, z = 0, around it).
        blank_radius: value::num(st, "blank_radius").unwrap_or_else(|| {
            let top =
                lensc_runtime::surface::analysis::analyse(kernel.as_ref(), &lowered.domain, 201)
                    .sag_max
                    .value;
            roller_radius + check.z_max.max(top).max(0.0) + 1e-6
        }),
        depth_of_cut: None,
        design_length_around: Some(design_y.1 - design_y.0),
        spindle_speed: Some(spindle_speed),
    };
    let retract = value::num(st, "retract").unwrap_or(1.0);
    Ok(RollerSpec {
        head: p.head(dialect, lowered),
        safe_x: helix.blank_radius + rt.nose_radius + retract,
        helix,
        tool: rt,
        check,
        design_y,
        spindle_speed,
    })
}

/// The rough pass, if the strategy has one, then the finish pass.
fn passes(st: &[value::Field]) -> Vec<HelixPass> {
    let finish = value::block(st, "finish").expect("required");
    let mut passes = Vec::new();
    if let Some(rough) = value::block(st, "rough") {
        passes.push(HelixPass {
            c_step: value::num(rough, "c_step").expect("required"),
            pitch: value::num(rough, "pitch").expect("required"),
            finish_allowance: value::num(rough, "finish_allowance").expect("required"),
        });
    }
    passes.push(HelixPass {
        c_step: value::num(finish, "c_step").expect("required"),
        pitch: value::num(finish, "pitch").expect("required"),
        finish_allowance: 0.0,
    });
    passes
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
        ));
    }
    if !check.clearance_ok {
        errors.push(p.error(
            codes::CLEARANCE_TOO_SMALL,
            format!(
                "the clearance angle ({}°) is not above the steepest slope in the cutting direction, around the roller ({}°)",
                deg(rt.clearance_angle),
                deg(check.max_slope_cutting_on_roller)
            ),
        ));
    }
    if !check.opening_ok {
        errors.push(p.error(
            codes::CLEARANCE_TOO_SMALL,
            format!(
                "half the tool's included angle ({}°) is not above the steepest axial slope ({}°)",
                deg(rt.opening_angle / 2.0),
                deg(check.max_slope_axial)
            ),
        ));
    }
    errors
}
