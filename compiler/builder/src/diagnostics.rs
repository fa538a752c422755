//! Runtime errors every strategy can meet as coded diagnostics: the
//! post-processor's, surface lowering's, the simulation window's and the
//! output's, each mapped to the code, message and help a user reads; and
//! `Coded`, the form in which each strategy's `errors.rs` words its own
//! planner's errors. Each error type is matched exhaustively (no `_`
//! arm), so a new variant fails to compile until it has its words; no
//! Rust value is ever printed with `{:?}`.

use lensc_grammar::{Diagnostic, FileId, Span};
use lensc_lang::check::trim_num;
use lensc_lang::codes;
use lensc_lang::lower::surface::LowerError;
use lensc_runtime::post::ProgramError;
use lensc_runtime::verify::window::TooManyCells;

/// What to do when a job's dialect cannot write its program (E0150).
pub const NOT_PRINTABLE_HELP: &str = "write the program in a dialect of the machine that can (`lensc build --dialect NAME`; `lensc list dialects`), or change the machine (its `resolution`, its `dialect`) so this one can";

/// Every error a build can meet after checking, with what its message
/// needs beyond the error itself.
#[derive(Debug)]
pub enum RuntimeError<'a> {
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

/// An error's code, words, label and help, before it is placed: what each
/// strategy's `errors.rs` makes of its planner's errors.
pub(crate) struct Coded {
    pub code: &'static str,
    pub message: String,
    pub label: &'static str,
    pub help: Option<String>,
}

/// An error's code and words, labelled "this job".
pub(crate) fn coded(code: &'static str, message: String) -> Coded {
    Coded {
        code,
        message,
        label: "this job",
        help: None,
    }
}

impl Coded {
    /// The diagnostic, pointing at `file`, `span` (the job's name).
    pub(crate) fn at(self, (file, span): (FileId, Span)) -> Diagnostic {
        let d = Diagnostic::error(self.code, self.message, file, span).with_label(self.label);
        match self.help {
            Some(h) => d.with_help(h),
            None => d,
        }
    }
    pub(crate) fn help(mut self, help: impl Into<String>) -> Coded {
        self.help = Some(help.into());
        self
    }
}

impl RuntimeError<'_> {
    /// The diagnostic, pointing at the job (`file`, `span`: its name).
    pub fn at(self, (file, span): (FileId, Span)) -> Diagnostic {
        let c = match self {
            RuntimeError::Simulation(e) => Coded {
                label: "this window",
                ..coded(
                    codes::SIMULATION_TOO_LARGE,
                    format!(
                        "the simulation would have {}{} cells, its columns {} rows long: more than the {} cells (its time) or {} rows a column (a tile's memory) it takes",
                        if e.at_least { "at least " } else { "" },
                        e.cells,
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
        c.at((file, span))
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
        LowerError::Missing(why) => why.clone(),
    }
}

/// Millimetres in micrometres, for messages.
pub(crate) fn um(mm: f64) -> String {
    trim_num(mm * 1000.0)
}

/// Rad/s in rpm, for messages.
pub(crate) fn rpm(w: f64) -> String {
    trim_num(w * 60.0 / std::f64::consts::TAU)
}

#[cfg(test)]
mod tests {
    use super::*;
    use lensc_runtime::plan::roller::RollerError;

    fn site() -> (FileId, Span) {
        (FileId(0), Span::new(0, 0))
    }

    fn message(e: RuntimeError) -> String {
        e.at(site()).message
    }

    /// The errors that used to reach users as Rust values read as words.
    #[test]
    fn no_error_reads_as_a_rust_value() {
        let roller = crate::strategy::roller::errors::error(
            RollerError::AllowanceRises {
                pass: 1,
                allowance: 0.01,
                previous: 0.005,
            },
            site(),
        )
        .message;
        assert_eq!(
            roller,
            "helix pass 2 leaves a finish allowance of 10 um, more than the 5 um the pass before it leaves"
        );
        let invalid = crate::strategy::roller::errors::error(
            RollerError::Invalid {
                what: "pitch",
                value: -1.0,
            },
            site(),
        )
        .message;
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
