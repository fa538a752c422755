//! The servo's view of a spiral: its points as the program prints them
//! (what the servo is driven by) and the fast axis's following simulated
//! along it. Used by the build and by the speed advice's trials, so
//! neither needs the other.

use super::SpiralSpec;

/// `points` as the program prints them (X and W rounded to the machine's
/// `resolution`, mm), into `printed`: what the servo is driven by.
pub(super) fn as_printed(
    points: &[lensc_runtime::plan::spiral::SpiralPoint],
    resolution: f64,
    printed: &mut Vec<lensc_runtime::plan::spiral::SpiralPoint>,
) {
    let printed_at = lensc_runtime::verify::simulate::Printed::new(resolution);
    let round = |v: f64| printed_at.round(v);
    printed.clear();
    printed.extend(
        points
            .iter()
            .map(|q| lensc_runtime::plan::spiral::SpiralPoint {
                x: round(q.x),
                w: round(q.w),
                ..*q
            }),
    );
}

/// The fast axis's servo following along `spiral` (the job's, or at a
/// trial speed, with the `bounds` its trajectory has there), simulated
/// over radial bins, where it has a servo model: the servo led by its
/// inverse model (velocity and acceleration feed-forward of the commanded
/// path, `FollowingSimulation::led`), as a fast tool servo's controller
/// drives it.
pub(super) fn following(
    spec: &SpiralSpec,
    spiral: &lensc_runtime::plan::spiral::FtsSpiral,
    bounds: &lensc_runtime::plan::spiral::TrajectoryBounds,
    data_rate: f64,
) -> Option<lensc_runtime::verify::follow::FollowingSimulation> {
    use lensc_runtime::verify::follow::{FollowingSimulation, RadialBins};
    let servo = spec.servo.as_ref().filter(|_| !spec.slow)?;
    let (r0, r1) = (spiral.start_radius.abs(), spiral.end_radius.abs());
    FollowingSimulation::new(
        servo,
        data_rate,
        bounds.features.as_deref().unwrap_or_default(),
        // From the axis where the spiral reaches or passes it.
        RadialBins::new(
            if spiral.end_radius <= 0.0 {
                0.0
            } else {
                r0.min(r1)
            },
            r0.max(r1),
            crate::plots::FOLLOWING_BINS,
        ),
    )
    .map(|sim| {
        // Only where the nose cuts: above the part's top (the settling
        // plateau and the lenslets' continuations) it cuts air.
        sim.led(servo)
            .cutting_below(bounds.part_top + spec.nose_radius + 1e-9)
    })
}
