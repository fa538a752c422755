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
}
