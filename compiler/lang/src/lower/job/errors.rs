//! The runtime's planning errors that lowering meets too (it runs the
//! planners' preconditions), as coded diagnostics at the job's name. The
//! builders use the same mappings for what planning finds.

use lensc_grammar::{Diagnostic, FileId, Span};
use lensc_runtime::plan::roller::RollerError;
use lensc_runtime::plan::turning::PlanError;

use crate::check::trim_num;
use crate::codes;

/// A profile-turning plan error as a diagnostic.
pub fn turning_diagnostic(e: PlanError, (file, span): (FileId, Span)) -> Diagnostic {
    let um = |mm: f64| trim_num(mm * 1000.0);
    match e {
        PlanError::NoseTooLarge { nose_radius, min_radius, at_radius } => Diagnostic::error(
            codes::NOSE_TOO_LARGE,
            format!(
                "the tool's nose radius ({} um) is larger than the surface's smallest concave radius of curvature ({} um, at r = {} mm): the tool would gouge",
                um(nose_radius),
                um(min_radius),
                trim_num(at_radius)
            ),
            file,
            span,
        )
        .with_label("this job")
        .with_help("use a tool whose nose radius is below the smallest concave radius of curvature"),
        PlanError::OutOfTravel { axis, value, min, max } => Diagnostic::error(
            codes::OUT_OF_TRAVEL,
            format!("the path moves {axis} to {} mm, outside the machine's travel {} .. {} mm", trim_num(value), trim_num(min), trim_num(max)),
            file,
            span,
        )
        .with_label("this job")
        .with_help("check the machine's travel, the aperture and the retract height"),
        PlanError::FeedTooHigh { feed, max } => Diagnostic::error(
            codes::FEED_TOO_HIGH,
            format!("the cutting feed ({} mm/min) is above the machine's maximum ({} mm/min)", trim_num(feed * 60.0), trim_num(max * 60.0)),
            file,
            span,
        )
        .with_label("this job")
        .with_help("lower the feed or the spindle speed"),
        PlanError::SpindleTooFast { speed, max } => {
            let rpm = |w: f64| trim_num(w * 60.0 / (2.0 * std::f64::consts::PI));
            Diagnostic::error(
                codes::SPINDLE_TOO_FAST,
                format!("the spindle speed ({} rpm) is above the machine's maximum ({} rpm)", rpm(speed), rpm(max)),
                file,
                span,
            )
            .with_label("this job")
        }
        PlanError::Undefined { at_radius } => Diagnostic::error(
            codes::UNDEFINED_ON_PATH,
            format!("the surface or the tool path is undefined at r = {} mm", trim_num(at_radius)),
            file,
            span,
        )
        .with_label("this job"),
    }
}

/// A roller planning or tool-check error as a diagnostic.
pub fn roller_diagnostic(e: RollerError, (file, span): (FileId, Span)) -> Diagnostic {
    let d = |code, msg: String| Diagnostic::error(code, msg, file, span).with_label("this job");
    match e {
        RollerError::NoseTooLarge {
            nose_radius,
            min_radius,
            x,
            y,
        } => d(
            codes::NOSE_TOO_LARGE,
            format!(
                "the tool's nose radius ({} mm) is not below the design's smallest concave radius of curvature ({} mm, at ({}, {}) mm)",
                trim_num(nose_radius),
                trim_num(min_radius),
                trim_num(x),
                trim_num(y)
            ),
        ),
        RollerError::Overlap {
            circumference,
            design_length,
        } => d(
            codes::WRAP_OVERLAP,
            format!(
                "the design is {} mm around, longer than the roller's {} mm circumference",
                trim_num(design_length),
                trim_num(circumference)
            ),
        ),
        RollerError::Undefined { c, z, .. } => d(
            codes::UNDEFINED_ON_PATH,
            format!(
                "the design is undefined where the nose must go (z = {} mm, C = {}°)",
                trim_num(z),
                trim_num(c.to_degrees() % 360.0)
            ),
        ),
        RollerError::BlankBelowDesign {
            blank_radius,
            design_top,
        } => d(
            codes::OUT_OF_RANGE,
            format!(
                "the blank's radius ({} mm) is below the top of the design ({} mm)",
                trim_num(blank_radius),
                trim_num(design_top)
            ),
        ),
        other => d(codes::UNSUPPORTED_COMBINATION, format!("{other:?}")),
    }
}
