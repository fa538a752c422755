//! lensc-build: checked jobs to programs. The driver loads and checks a
//! file through `lensc-lang`; the pipeline lowers each job to its typed
//! `JobSpec` with its strategy (`strategy/`, one folder each behind one
//! trait, with the shared head and checks in `job`) and builds it with
//! the same strategy in a `context::BuildContext`: it plans with
//! `lensc-runtime`, emits the program (spooled and written
//! atomically, once read back by the controllers' rules: `read_back`),
//! simulates what it will cut and fills the build report; the acceptance
//! gate (`accept`) holds the simulated part to the job's criteria; plots
//! draw that report.

pub mod accept;
pub mod compensate;
pub mod context;
pub mod delivery;
pub mod diagnostics;
pub mod driver;
pub mod edge;
pub mod evaluate;
pub mod height_map;
pub mod job;
pub(crate) mod job_file;
pub mod json_schema;
pub mod measure;
pub mod output;
pub mod pipeline;
pub mod plausibility;
pub mod plots;
pub mod progress;
pub mod read_along;
pub mod read_back;
pub mod reading;
pub mod report;
pub mod setup_sheet;
pub(crate) mod spool;
pub mod strategy;
pub mod temps;
pub mod view;
