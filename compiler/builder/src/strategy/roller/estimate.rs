//! A roller helix's point count and program size, estimated before
//! planning (`job::estimate`): counted exactly.

use crate::job::estimate::Estimate;

/// Bytes of one motion block (measured on the examples).
const ROLLER_BLOCK: f64 = 38.0;

/// A roller helix: each pass a point per C step over its helix, one block
/// each.
pub(crate) fn estimate(s: &super::RollerSpec) -> Estimate {
    let h = &s.helix;
    let tau = std::f64::consts::TAU;
    let points: f64 = h
        .passes
        .iter()
        .map(|p| (tau * (h.z_end - h.z_start) / p.pitch / p.c_step).ceil() + 1.0)
        .sum();
    Estimate {
        servo_samples: 0.0,
        points,
        program_bytes: points * ROLLER_BLOCK,
        driver: "c_step",
    }
}
