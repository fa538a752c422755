//! One file per subcommand: each turns its arguments into calls on
//! lensc-build and lensc-lang and returns the exit code.

pub mod analyse;
pub mod build;
pub mod check;
pub mod explain;
pub mod fmt;
pub mod import;
pub mod list;
pub mod measure;
pub mod report;
pub mod sample;
pub mod verify;
pub mod view;
