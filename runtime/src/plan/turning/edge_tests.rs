//! Tests of a measured nose edge: a turned asphere cut by a wavy edge
//! misses its form by the waviness unless the path is offset by R + δ at
//! the angle of contact.

use super::*;
use crate::dialect::Dialect;
use crate::machine::edge::{EdgeProfile, Sample};
use crate::machine::tool::{MeasuredEdge, RoundNoseTool};
use crate::surface::{RotationalSurface, Sense, SurfaceInfo};
use crate::verify::simulate::profile_cut_by;
use std::f64::consts::PI;

/// A convex asphere (R 8 mm, k −1, A4, A6) over a 3 mm radius: slopes
/// from 0 to about 21° at the rim.
pub(super) fn asphere() -> RotationalSurface {
    RotationalSurface {
        radius: 8.0,
        conic: -1.0,
        sense: Sense::Convex,
        terms: vec![(4, 2e-4), (6, -1e-6)],
        aperture_radius: 3.0,
    }
}

/// An edge with a 50 nm sinusoid, `periods` over ±40°, sampled each 0.25°.
fn wavy_edge(periods: f64) -> EdgeProfile {
    let samples: Vec<Sample> = (0..=320)
        .map(|i| {
            let a = -40.0 + 0.25 * i as f64;
            Sample {
                angle_deg: a,
                deviation_um: 0.05 * (periods * PI * a / 40.0).sin(),
                line: i + 1,
                at: 0,
            }
        })
        .collect();
    EdgeProfile::from_samples(&samples).unwrap()
}

pub(super) fn job(edge: Option<EdgeProfile>) -> TurningJob {
    TurningJob {
        name: "edge".into(),
        surface_name: "s".into(),
        tool_name: "t".into(),
        machine_name: "m".into(),
        strategy_name: "p".into(),
        surface: SurfaceInfo {
            description: "asphere".into(),
            aperture_radius: 3.0,
        },
        tool: RoundNoseTool {
            nose_radius: 0.5,
            clearance_angle: 0.3,
            centre_height: 0.0,
            rake_angle: 0.0,
            edge: edge.map(|profile| MeasuredEdge {
                profile,
                source: "test".into(),
            }),
        },
        machine: Lathe {
            dialect: Dialect::linuxcnc(),
            resolution: 1e-7,
            travel_x: (-10.0, 100.0),
            travel_z: (-100.0, 100.0),
            max_feed: 100.0,
            max_spindle_speed: 1000.0,
        },
        strategy: ProfileTurning {
            feed: Feed::PerRevolution(0.002 / (2.0 * PI)),
            spindle_speed: 50.0,
            surface_speed: None,
            chord_tolerance: 2e-6,
            start_radius: None,
            end_radius: 0.0,
            retract: 1.0,
            location: ToolLocation::Exact,
            roughing: None,
            chords: crate::plan::chords::ChordPlacement::OnPath,
        },
    }
}

/// PV (nm) of the part the `planned` job's path cuts with the real tool,
/// whose edge is `real`.
fn cut_pv(planned: &TurningJob, real: Option<&EdgeProfile>) -> f64 {
    let s = asphere();
    let path = plan_profile_turning(planned, &s).unwrap();
    let nose = Nose {
        radius: 0.5,
        edge: real,
    };
    let design = |x: f64| s.point(x).z;
    let cut = profile_cut_by(&path.moves, &nose, 1e-7, &design, (0.0, 3.0), 3001);
    assert_eq!(cut.uncut_area, 0.0);
    cut.pv * 1e6
}

#[test]
fn a_wavy_edge_misses_the_form_unless_compensated() {
    let edge = wavy_edge(5.0);
    // The path alone, a perfect circle cutting it: the chords' share.
    let circle = cut_pv(&job(None), None);
    // The real, wavy tool on a path planned for a circle: the waviness
    // is printed into the part (±50 nm over the slopes the cut spans).
    let uncompensated = cut_pv(&job(None), Some(&edge));
    // The path offset by R + δ at each angle of contact.
    let compensated = cut_pv(&job(Some(edge.clone())), Some(&edge));
    eprintln!(
        "PV nm: circle {circle:.2}, uncompensated {uncompensated:.2}, compensated {compensated:.2}"
    );
    assert!(circle < 3.0, "{circle}");
    assert!(uncompensated > 80.0, "{uncompensated}");
    assert!(compensated < 5.0, "{compensated}");
}

#[test]
fn an_edge_that_does_not_cover_the_cut_is_refused() {
    // Measured over ±10° only; the rim meets the nose at about −21°.
    let samples: Vec<Sample> = (0..=20)
        .map(|i| Sample {
            angle_deg: -10.0 + i as f64,
            deviation_um: 0.0,
            line: i + 1,
            at: 0,
        })
        .collect();
    let j = job(Some(EdgeProfile::from_samples(&samples).unwrap()));
    let errs = check_profile_turning(&j, &asphere()).unwrap_err();
    let PlanError::EdgeNotCovering {
        needed, at_radius, ..
    } = errs[0]
    else {
        panic!("{errs:?}")
    };
    assert!(needed.0 < -0.3 && needed.1 <= 0.0, "{needed:?}");
    assert_eq!(at_radius, 3.0);
}
