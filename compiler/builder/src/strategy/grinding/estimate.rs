//! A profile-grinding job's point count and program size, estimated before
//! planning (`job::estimate`): counted exactly.

use crate::job::estimate::Estimate;

/// Bytes of one motion block (measured on the examples).
const GRINDING_BLOCK: f64 = 33.0;

/// Profile grinding: one point per interval and one more, one block each.
pub(crate) fn estimate(s: &super::GrindingSpec) -> Estimate {
    let g = &s.grinding;
    let points = ((g.end - g.start).abs() / g.interval).ceil() + 1.0;
    Estimate {
        servo_samples: 0.0,
        points,
        program_bytes: points * GRINDING_BLOCK,
        driver: "interval",
    }
}
