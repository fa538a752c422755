//! Machines: their kinematics, limits and the dialect they speak.

pub mod edge;
pub mod lead;
pub mod servo;
pub mod tool;

use crate::dialect::Dialect;

/// A 2-axis (X radius, Z along the spindle) turning machine.
#[derive(Clone, Debug, PartialEq)]
pub struct Lathe {
    pub dialect: Dialect,
    /// Smallest programmable step (mm); sets the decimals of every coordinate.
    pub resolution: f64,
    /// X travel (radius, mm) as (min, max).
    pub travel_x: (f64, f64),
    /// Z travel (mm) as (min, max).
    pub travel_z: (f64, f64),
    /// Highest programmable cutting feed (mm/s).
    pub max_feed: f64,
    /// Highest spindle speed (rad/s).
    pub max_spindle_speed: f64,
}
