//! lensc-build: checked jobs to programs. The driver loads and checks a
//! file through `lensc-lang`, lowers each job, and hands it to its
//! strategy's builder, which plans with `lensc-runtime`, emits the program
//! (spooled and written atomically), simulates what it will cut and fills
//! the build report; plots draw that report.

pub mod diagnostics;
pub mod driver;
pub mod fts_job;
pub mod height_map;
pub mod mill_job;
pub mod parts;
pub mod plots;
pub mod report;
pub mod roller_job;
