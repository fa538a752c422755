//! Planners: one file per strategy, each turning a surface and a machine's
//! limits into neutral tool-centre points and moves. No program text here:
//! `emit/` turns their output into the move stream.

pub mod approach;
pub mod chords;
pub mod count;
pub mod envelope;
pub mod grinding;
pub mod optimise;
pub mod raster;
pub mod roller;
pub mod spiral;
pub mod spline;
pub mod stream;
pub mod turning;
