//! Runtime errors as coded diagnostics: every error the planners, the
//! post-processor, surface lowering and the output can return after a job
//! was checked, mapped in one place to the code, message and help a user
//! reads. Each error type is matched exhaustively (no `_` arm), so a new
//! variant fails to compile until it has its words; no Rust value is ever
//! printed with `{:?}`. It lives here, not in lensc-build, because
//! lowering runs the planners' preconditions (turning's profile checks,
//! the raster's plane scan and clearance, grinding's station scan, the
//! roller's tool check) and reports their errors as `build` does.

use crate::check::trim_num;
use crate::codes;
use crate::lower::surface::LowerError;
use lensc_grammar::{Diagnostic, FileId, Span};
use lensc_runtime::plan::fts::{FtsError, SpeedAdvice, SpindleSpeed};
use lensc_runtime::plan::grinding::GrindingError;
use lensc_runtime::plan::raster::RasterError;
use lensc_runtime::plan::roller::RollerError;
use lensc_runtime::plan::turning::PlanError;
use lensc_runtime::post::ProgramError;
use lensc_runtime::verify::window::TooManyCells;

/// What to do when a job's dialect cannot write its program (E0150).
pub const NOT_PRINTABLE_HELP: &str = "write the program in a dialect of the machine that can (`lensc build --dialect NAME`; `lensc list dialects`), or change the machine (its `resolution`, its `dialect`) so this one can";

/// Every error a build can meet after checking, with what its message
/// needs beyond the error itself.
#[derive(Debug)]
pub enum RuntimeError<'a> {
    /// Profile turning could not be planned.
    Turning(PlanError),
    /// A spiral could not be planned. `speed` is how the job gives its
    /// spindle speed (the help names speeds in the same kind); `axis`
    /// names the axis that carries the surface; `advice`, for a refused
    /// acceleration, what a search over the real check found.
    Spiral {
        error: FtsError,
        speed: &'a SpindleSpeed,
        axis: &'a str,
        advice: Option<SpeedAdvice>,
    },
    /// A raster could not be planned.
    Raster(RasterError),
    /// A grinding pass could not be planned.
    Grinding(GrindingError),
    /// A roller job could not be checked or planned.
    Roller(RollerError),
    /// The job's simulation window makes too large a grid (the
    /// diagnostic points at the window).
    Simulation(TooManyCells),
    /// The program could not be written in the machine's dialect.
    Program(ProgramError),
    /// The surface could not be lowered to something that evaluates it.
    Surface(LowerError),
    /// The settled tool trajectory of a lenslet array could not be built.
    Trajectory(LowerError),
    /// The program could not be written to the output directory.
    Spool(&'a std::io::Error),
}

/// An error's code, words, label and help, before it is placed.
struct Coded {
    code: &'static str,
    message: String,
    label: &'static str,
    help: Option<String>,
}

fn coded(code: &'static str, message: String) -> Coded {
    Coded {
        code,
        message,
        label: "this job",
        help: None,
    }
}

impl Coded {
    fn help(mut self, help: impl Into<String>) -> Coded {
        self.help = Some(help.into());
        self
    }
}

impl RuntimeError<'_> {
    /// The diagnostic, pointing at the job (`file`, `span`: its name).
    pub fn at(self, (file, span): (FileId, Span)) -> Diagnostic {
        let c = match self {
            RuntimeError::Turning(e) => turning(e),
            RuntimeError::Spiral {
                error,
                speed,
                axis,
                advice,
            } => spiral(error, speed, axis, advice),
            RuntimeError::Raster(e) => raster(e),
            RuntimeError::Grinding(e) => grinding(e),
            RuntimeError::Roller(e) => roller(e),
            RuntimeError::Simulation(e) => Coded {
                label: "this window",
                ..coded(
                    codes::SIMULATION_TOO_LARGE,
                    format!(
                        "the simulation would have {} cells in {} tiles, its columns {} rows long: more than the {} cells (its time) or {} rows a column (a tile's memory) it takes",
                        e.cells,
                        e.tiles,
                        e.rows,
                        TooManyCells::CELLS,
                        TooManyCells::ROWS
                    ),
                )
                .help("make the window smaller or its spacing coarser")
            },
            RuntimeError::Program(e) => Coded {
                label: "no program was written for this job",
                ..coded(codes::NOT_PRINTABLE, e.message())
                    .help(NOT_PRINTABLE_HELP)
            },
            RuntimeError::Surface(e) => coded(
                codes::UNSUPPORTED_COMBINATION,
                format!(
                    "this surface cannot be evaluated yet: {}",
                    lowering_words(&e)
                ),
            ),
            RuntimeError::Trajectory(e) => coded(
                codes::UNSUPPORTED_COMBINATION,
                format!(
                    "the tool trajectory cannot be built: {}",
                    lowering_words(&e)
                ),
            ),
            RuntimeError::Spool(e) => coded(
                codes::CANNOT_WRITE,
                format!("cannot write the program: {e}"),
            ),
        };
        let d = Diagnostic::error(c.code, c.message, file, span).with_label(c.label);
        match c.help {
            Some(h) => d.with_help(h),
            None => d,
        }
    }
}

/// Why a surface cannot be lowered, in words (also for `lensc sample`
/// and `lensc analyse`).
pub fn lowering_words(e: &LowerError) -> String {
    match e {
        LowerError::Unsupported(what) => format!("{what} is not supported by the evaluator"),
        LowerError::Aperture(what) => {
            format!("its aperture or domain is of a shape it cannot use ({what})")
        }
    }
}

fn um(mm: f64) -> String {
    trim_num(mm * 1000.0)
}

fn rpm(w: f64) -> String {
    trim_num(w * 60.0 / std::f64::consts::TAU)
}

fn turning(e: PlanError) -> Coded {
    match e {
        PlanError::NoseTooLarge { nose_radius, min_radius, at_radius } => coded(
            codes::NOSE_TOO_LARGE,
            format!(
                "the tool's nose radius ({} um) is larger than the surface's smallest concave radius of curvature ({} um, at r = {} mm): the tool would gouge",
                um(nose_radius),
                um(min_radius),
                trim_num(at_radius)
            ),
        )
        .help("use a tool whose nose radius is below the smallest concave radius of curvature"),
        PlanError::OutOfTravel { axis, value, min, max } => coded(
            codes::OUT_OF_TRAVEL,
            format!(
                "the path moves {axis} to {} mm, outside the machine's travel {} .. {} mm",
                trim_num(value),
                trim_num(min),
                trim_num(max)
            ),
        )
        .help("check the machine's travel, the aperture and the retract height"),
        PlanError::FeedTooHigh { feed, max } => coded(
            codes::FEED_TOO_HIGH,
            format!(
                "the cutting feed ({} mm/min) is above the machine's maximum ({} mm/min)",
                trim_num(feed * 60.0),
                trim_num(max * 60.0)
            ),
        )
        .help("lower the feed or the spindle speed"),
        PlanError::SpindleTooFast { speed, max } => coded(
            codes::SPINDLE_TOO_FAST,
            format!(
                "the spindle speed ({} rpm) is above the machine's maximum ({} rpm)",
                rpm(speed),
                rpm(max)
            ),
        )
        .help(format!("lower `spindle_speed` to at most {} rpm (with `surface_speed`, cap it with `spindle_cap`)", rpm(max))),
        PlanError::Undefined { at_radius } => coded(
            codes::UNDEFINED_ON_PATH,
            format!(
                "the surface or the tool path is undefined at r = {} mm",
                trim_num(at_radius)
            ),
        ),
    }
}

fn spiral(e: FtsError, speed: &SpindleSpeed, axis: &str, advice: Option<SpeedAdvice>) -> Coded {
    match e {
        FtsError::Undefined { x, c } => coded(
            codes::UNDEFINED_ON_PATH,
            format!(
                "the surface is undefined where the nose must go (r = {} mm, C = {}°)",
                trim_num(x),
                trim_num(c.to_degrees() % 360.0)
            ),
        ),
        FtsError::StrokeExceeded { range, stroke } => coded(
            codes::STROKE_EXCEEDED,
            format!(
                "{axis} must travel {} um, more than its {} um stroke",
                um(range),
                um(stroke)
            ),
        )
        .help("use a fast axis with a longer `stroke`, or a surface whose height varies less around each turn"),
        FtsError::AccelerationExceeded {
            acceleration,
            max,
            at_radius,
        } => {
            let words = |v: f64| match speed {
                SpindleSpeed::Constant(_) => format!("{} rpm", rpm(v)),
                SpindleSpeed::SurfaceSpeed { .. } => format!("{} m/min", trim_num(v * 0.06)),
            };
            let kind = match speed {
                SpindleSpeed::Constant(_) => "spindle speed",
                SpindleSpeed::SurfaceSpeed { .. } => "surface speed",
            };
            let help = match advice {
                Some(SpeedAdvice::Found { passes, fails }) => format!(
                    "the highest speed found that respects it is a {kind} of {} (planned and checked; {} is refused)",
                    words(passes),
                    words(fails)
                ),
                Some(SpeedAdvice::NotFound { lowest_tried }) => format!(
                    "no {kind} tried respects it, down to {}: the acceleration does not fall with the speed there (a spindle cap, or the path itself)",
                    words(lowest_tried)
                ),
                None => format!("lower the {kind}"),
            };
            coded(
                codes::ACCELERATION_EXCEEDED,
                format!(
                    "{axis} would accelerate at {} m/s² (at r = {} mm), above its {} m/s² limit",
                    trim_num(acceleration / 1000.0),
                    trim_num(at_radius),
                    trim_num(max / 1000.0)
                ),
            )
            .help(help)
        }
        FtsError::Invalid(why) => coded(codes::UNSUPPORTED_COMBINATION, why.to_string()),
    }
}

fn raster(e: RasterError) -> Coded {
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

fn grinding(e: GrindingError) -> Coded {
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

fn roller(e: RollerError) -> Coded {
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
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn message(e: RuntimeError) -> String {
        e.at((FileId(0), Span::new(0, 0))).message
    }

    /// The errors that used to reach users as Rust values read as words.
    #[test]
    fn no_error_reads_as_a_rust_value() {
        let roller = message(RuntimeError::Roller(RollerError::AllowanceRises {
            pass: 1,
            allowance: 0.01,
            previous: 0.005,
        }));
        assert_eq!(
            roller,
            "helix pass 2 leaves a finish allowance of 10 um, more than the 5 um the pass before it leaves"
        );
        let invalid = message(RuntimeError::Roller(RollerError::Invalid {
            what: "pitch",
            value: -1.0,
        }));
        assert!(
            !invalid.contains('{') && invalid.contains("pitch"),
            "{invalid}"
        );
        let lowering = message(RuntimeError::Surface(LowerError::Unsupported(
            "fringe index above 37",
        )));
        assert!(!lowering.contains("Unsupported("), "{lowering}");
    }

    /// A program the dialect cannot write says no program was written.
    #[test]
    fn a_program_error_says_no_program_was_written() {
        let d = RuntimeError::Program(ProgramError::Unsupported("arcs".into()))
            .at((FileId(0), Span::new(0, 0)));
        assert_eq!(d.code, codes::NOT_PRINTABLE);
        assert_eq!(d.primary().message, "no program was written for this job");
    }
}
