//! The profile-grinding planner's errors in the words a user reads.
use lensc_grammar::{Diagnostic, FileId, Span};
use lensc_lang::check::trim_num;
use lensc_lang::codes;

use crate::diagnostics::{Coded, coded, um};
use lensc_runtime::plan::grinding::GrindingError;

/// A grinding planner error as its diagnostic at `site`.
pub(crate) fn error(e: GrindingError, site: (FileId, Span)) -> Diagnostic {
    coded_error(e).at(site)
}

fn coded_error(e: GrindingError) -> Coded {
    match e {
        GrindingError::WheelTooLarge {
            x,
            wheel_radius,
            curvature_radius,
        } => coded(
            codes::NOSE_TOO_LARGE,
            format!(
                "the wheel's radius ({} um) is larger than the surface's smallest concave radius of curvature ({} um, at x = {} mm): the wheel would gouge",
                um(wheel_radius),
                um(curvature_radius),
                trim_num(x)
            ),
        )
        .help("use a smaller wheel"),
        GrindingError::NonFiniteSurface { x } => coded(
            codes::UNDEFINED_ON_PATH,
            format!("the surface is undefined at x = {} mm", trim_num(x)),
        ),
        GrindingError::InvalidParameter { .. }
        | GrindingError::EmptyRange { .. }
        | GrindingError::TooManySegments { .. } => {
            coded(codes::UNSUPPORTED_COMBINATION, e.to_string())
        }
    }
}
