//! Each strategy's planned path to the dialect-independent move stream and
//! a program: the adapters between `plan/` and `post/`, one file per
//! strategy, and the header words they share.

pub mod grinding;
pub mod raster;
pub mod roller;
pub mod spiral;
pub mod turning;

use crate::dialect::Dialect;
use crate::moves;
use crate::plan::optimise;
use crate::post::header::{exact_in, num};
use crate::post::{ProgramError, ProgramWriter, Setup};

/// A program, the move stream it was written from, and what
/// optimisation did to that stream.
pub struct Emitted {
    pub text: String,
    pub stream: Vec<moves::Move>,
    pub optimised: optimise::Summary,
}

/// The header line of a program written with splines: which, how many,
/// how close, and the control option they need (none where none was
/// written).
pub fn spline_words(dialect: &crate::dialect::Dialect, s: &crate::plan::spline::Summary) -> String {
    use crate::plan::spline::ORDER;
    let form = match dialect.spline {
        Some(crate::dialect::SplineForm::Bspline) => {
            format!("B spline (BSPLINE SD={}, knots PL apart)", ORDER - 1)
        }
        _ => format!("NURBS (G06.2, order {ORDER})"),
    };
    let option = if dialect.spline_option.is_empty() {
        "spline interpolation"
    } else {
        &dialect.spline_option
    };
    format!(
        "interpolation: {form} where shorter than lines and arcs: {} splines for {} straight moves, {} blocks of moves from {} planned, largest deviation {} nm (limit {} nm); {}",
        s.splines,
        s.lines_replaced,
        s.blocks_after,
        s.blocks_before,
        crate::post::header::num((s.max_deviation * 1e7).round() / 10.0),
        crate::post::header::num((s.limit * 1e7).round() / 10.0),
        // A program with no spline in it runs without the option: a
        // machinist told it needs one would not load it on a control
        // without.
        if s.splines == 0 {
            format!("no spline written: runs without the control's {option}")
        } else {
            format!("needs the control's {option}")
        }
    )
}

/// How a path's tolerance T is stated in a header (exactly, in nm as a
/// `.lens` file reads nm), with its shares (figures for people).
pub fn tolerance_words(t: f64) -> String {
    format!(
        "path tolerance {} nm [chords {}, fitting {}, blending {} nm]",
        exact_in(t, 1e-6),
        num(t * optimise::CHORD_SHARE * 1e6),
        num(t * optimise::FIT_SHARE * 1e6),
        num(t * optimise::BLEND_SHARE * 1e6)
    )
}

/// What optimisation did, for a header.
pub fn optimisation_words(s: &optimise::Summary) -> String {
    format!(
        "optimised from {} to {} moves: {} arcs, {} merged lines, largest deviation {} nm",
        s.moves_before,
        s.moves_after,
        s.arcs,
        s.merged_lines,
        num((s.max_deviation * 1e9).round() / 1e3)
    )
}

/// What a lathe program's X word is in `dialect`, for its header.
pub fn x_word(dialect: &Dialect) -> &'static str {
    if dialect.lathe_x_diameter {
        "the diameter"
    } else {
        "the radius"
    }
}

/// A lathe program on the X, Z and C axes (the spiral and helix
/// strategies), its controller blending corners by at most
/// `path_tolerance` (mm).
/// Its tool is called by the program's owner (`call_tool`) before any move.
fn xzc_lathe_writer(
    dialect: &Dialect,
    job: &str,
    header: &[String],
    resolution: f64,
    path_tolerance: f64,
) -> Result<ProgramWriter, ProgramError> {
    ProgramWriter::new(
        dialect,
        Setup::Lathe,
        job,
        header,
        "XZC",
        resolution,
        path_tolerance,
    )
}
