//! The compiler's entry points, as the `lensc` command calls them: check a
//! file, build a file's jobs into programs (`plan_and_emit`, from
//! `pipeline`), write them atomically (`output`), analyse and sample a
//! surface (`evaluate`). Nothing in this crate imports this module.

pub use crate::evaluate::{SamplePoints, declared_surface, evaluator, sample};
pub use crate::output::{Built, ProgramText, output_path, put_in_place, write_atomic};
pub use crate::pipeline::{
    Outcome, Request, plan_and_emit, plan_and_emit_outcomes, plan_and_simulate,
};
pub use crate::report::surface_analysis;
pub use lensc_lang::{Checked, check_path, check_path_in, check_text};
