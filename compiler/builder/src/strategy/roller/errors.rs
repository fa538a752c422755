//! The roller-helix planner's errors in the words a user reads.
use lensc_grammar::{Diagnostic, FileId, Span};
use lensc_lang::check::trim_num;
use lensc_lang::codes;

use crate::diagnostics::{Coded, coded, um};
use lensc_runtime::plan::roller::RollerError;

/// A roller planner error as its diagnostic at `site`.
pub(crate) fn error(e: RollerError, site: (FileId, Span)) -> Diagnostic {
    coded_error(e).at(site)
}

/// A roller planner error as its diagnostic: an edge's at the tool's
/// `edge_profile` (`edge_site`, where it names one), the rest at `site`.
pub(crate) fn planned_error(
    e: RollerError,
    site: (FileId, Span),
    edge_site: Option<(FileId, Span)>,
) -> Diagnostic {
    match (&e, edge_site) {
        (RollerError::EdgeAtCorners { .. }, Some(at)) => Coded {
            label: "the edge profile this tool names",
            ..coded_error(e)
        }
        .at(at),
        _ => error(e, site),
    }
}

fn coded_error(e: RollerError) -> Coded {
    match e {
        RollerError::NoseTooLarge {
            nose_radius,
            min_radius,
            x,
            y,
        } => coded(
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
        } => coded(
            codes::WRAP_OVERLAP,
            format!(
                "the design is {} mm around, longer than the roller's {} mm circumference",
                trim_num(design_length),
                trim_num(circumference)
            ),
        ),
        RollerError::Undefined { c, z, .. } => coded(
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
        } => coded(
            codes::OUT_OF_RANGE,
            format!(
                "the blank's radius ({} mm) is below the top of the design ({} mm)",
                trim_num(blank_radius),
                trim_num(design_top)
            ),
        ),
        RollerError::Invalid { what, value } => coded(
            codes::UNSUPPORTED_COMBINATION,
            format!(
                "the roller helix cannot be planned: its {what} is out of range ({})",
                trim_num(value)
            ),
        ),
        RollerError::AllowanceRises {
            pass,
            allowance,
            previous,
        } => coded(
            codes::UNSUPPORTED_COMBINATION,
            format!(
                "helix pass {} leaves a finish allowance of {} um, more than the {} um the pass before it leaves",
                pass + 1,
                um(allowance),
                um(previous)
            ),
        )
        .help("each pass must leave no more material than the one before it"),
        RollerError::EdgeAtCorners { corners } => coded(
            codes::EDGE_ANGLES,
            format!(
                "the design's sections along the roller have concave corners or steps ({corners} found by the planner's survey): a measured edge is compensated only along smooth sections, where one angle of the edge touches them"
            ),
        )
        .help("leave the tool's `edge_profile` out for this job (the nose is then a circle)"),
    }
}
