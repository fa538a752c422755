//! A checked, fully resolved job: what the compiler hands the runtime.

use crate::machine::Lathe;
use crate::surface::SurfaceInfo;
use crate::tool::RoundNoseTool;
use crate::toolpath::ProfileTurning;

/// One job with every parameter in internal units (mm, rad, s).
#[derive(Clone, Debug, PartialEq)]
pub struct Job {
    pub name: String,
    /// Names the user gave each part, for the program header.
    pub surface_name: String,
    pub tool_name: String,
    pub machine_name: String,
    pub strategy_name: String,
    /// The surface as the header states it; its geometry reaches the
    /// planner as a `Profile`.
    pub surface: SurfaceInfo,
    pub tool: RoundNoseTool,
    pub machine: Lathe,
    pub strategy: ProfileTurning,
}
