//! One builder per strategy: each plans a lowered job with lensc-runtime,
//! emits its program, simulates what it will cut and fills its report.

pub mod fts;
pub mod grinding;
pub mod raster;
pub mod roller;
pub mod turning;
