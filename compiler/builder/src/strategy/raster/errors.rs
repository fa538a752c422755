//! The raster planner's errors in the words a user reads.
use lensc_grammar::{Diagnostic, FileId, Span};
use lensc_lang::check::trim_num;
use lensc_lang::codes;

use crate::diagnostics::{Coded, coded, um};
use lensc_runtime::plan::raster::RasterError;

/// A raster planner error as its diagnostic at `site`.
pub(crate) fn error(e: RasterError, site: (FileId, Span)) -> Diagnostic {
    coded_error(e).at(site)
}

fn coded_error(e: RasterError) -> Coded {
    match e {
        RasterError::ToolTooLarge {
            tool_radius,
            min_radius,
            x,
            y,
        } => coded(
            codes::NOSE_TOO_LARGE,
            format!(
                "the tool's radius ({} um) is larger than the surface's smallest concave radius of curvature ({} um, at ({}, {}) mm): the tool would gouge",
                um(tool_radius),
                um(min_radius),
                trim_num(x),
                trim_num(y)
            ),
        )
        .help("use a tool whose radius is below the smallest concave radius of curvature"),
        RasterError::ClearanceTooSmall {
            clearance,
            slope,
            x,
            y,
        } => coded(
            codes::CLEARANCE_TOO_SMALL,
            format!(
                "the clearance angle ({}°) is not above the surface's steepest slope along the cut ({}°, at ({}, {}) mm): the flank would rub",
                trim_num(clearance.to_degrees()),
                trim_num(slope.to_degrees()),
                trim_num(x),
                trim_num(y)
            ),
        )
        .help(format!("use a tool whose `clearance` is above {}°", trim_num(slope.to_degrees()))),
        RasterError::Undefined { x, y } | RasterError::NoContact { x, y } => coded(
            codes::UNDEFINED_ON_PATH,
            format!(
                "the surface or the tool path is undefined at ({}, {}) mm",
                trim_num(x),
                trim_num(y)
            ),
        ),
        RasterError::InvalidParameter { .. }
        | RasterError::ToleranceUnreachable { .. }
        | RasterError::TooManyPaths { .. }
        | RasterError::TooManyPoints { .. }
        | RasterError::NothingToCut => coded(codes::UNSUPPORTED_COMBINATION, e.to_string()),
    }
}
