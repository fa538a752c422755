//! The `.lens` compiler: loading and name resolution, unit and type
//! checking, lowering to the runtime's job description, diagnostics
//! rendering, and the driver the `lensc` binary calls.

pub mod check;
pub mod codes;
pub mod driver;
pub mod fts_job;
pub mod height_map;
pub mod jit;
pub mod loader;
pub mod lower;
pub mod mill_job;
pub mod parts;
pub mod plots;
pub mod render;
pub mod roller_job;
pub mod schema;
pub mod source;
pub mod surfaces;
pub mod units;
pub mod value;
