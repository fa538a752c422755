//! Cutting tools.

/// A round-nose (single-point diamond) turning tool, referenced at the
/// centre of its nose circle.
#[derive(Clone, Debug, PartialEq)]
pub struct RoundNoseTool {
    /// Nose radius ρ (mm).
    pub nose_radius: f64,
    /// Clearance angle (rad): the steepest surface slope the flank clears.
    pub clearance_angle: f64,
    /// Height (mm) of the cutting edge above the spindle axis (negative:
    /// below) as the tool is set: the edge then cuts radius sqrt(X² + h²),
    /// so profile turning programs X = sqrt(r² − h²); radii below |h| are
    /// out of its reach.
    pub centre_height: f64,
    /// Rake angle (rad); recorded in the header, not used by planning.
    pub rake_angle: f64,
    /// The edge as measured, when the tool names its profile: the path is
    /// offset by R + δ at the angle of contact, and the simulation sweeps
    /// this edge.
    pub edge: Option<MeasuredEdge>,
}

/// A measured edge profile and which one it is, for the header.
#[derive(Clone, Debug, PartialEq)]
pub struct MeasuredEdge {
    pub profile: super::edge::EdgeProfile,
    /// The file it was read from and its hash, as the header says them.
    pub source: String,
}

impl RoundNoseTool {
    /// The nose as the planner and the simulation see it.
    pub fn nose(&self) -> super::edge::Nose<'_> {
        super::edge::Nose {
            radius: self.nose_radius,
            edge: self.edge.as_ref().map(|e| &e.profile),
        }
    }
}
