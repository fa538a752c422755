//! lensc-runtime: a CAM library with no language in it. The pipeline runs
//! through its folders in order:
//!
//! - `surface/`: the surface IR, its interpreter and (feature `jit`, on by
//!   default) its cranelift compiler, Forbes polynomials, profiles and
//!   analysis (curvature, slopes);
//! - `machine/`: machines, tools and the servo model;
//! - `plan/`: one planner per strategy, giving neutral tool-centre points;
//! - `emit/`: each planner's output to the dialect-independent move stream
//!   (`moves`) and a program;
//! - `post/`: the move stream (`moves`) to program text in a dialect
//!   given as data (`dialect`, which a machine also names);
//! - `reader/`: a program read back from its text as its controller
//!   reads it (modal state, the controllers' refusals);
//! - `verify/`: what the program will cut (simulation, height maps,
//!   following error).
//!
//! Internal units: one per dimension — millimetres, radians, seconds.

pub mod dialect;
pub mod emit;
pub mod machine;
pub mod moves;
pub mod plan;
pub mod post;
pub mod reader;
pub mod surface;
pub mod verify;
