//! Everything that executes a lens-machining job, usable as a Rust library
//! without the language: surfaces, tools, machines, toolpath strategies and
//! the dialect emitters that turn a move stream into a program.
//!
//! Internal units: one per dimension — millimetres, radians, seconds.

pub mod analysis;
pub mod envelope;
pub mod follow;
pub mod forbes;
pub mod format;
pub mod fts;
pub mod grinding;
pub mod heightmap;
pub mod ir;
pub mod job;
pub mod machine;
pub mod moves;
pub mod optimise;
pub mod program;
pub mod raster;
pub mod roller;
pub mod servo;
pub mod simulate;
pub mod surface;
pub mod tool;
pub mod toolpath;

pub use job::Job;
