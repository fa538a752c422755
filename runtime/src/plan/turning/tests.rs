//! Tests of profile turning on rotational surfaces.

use super::*;
use crate::surface::{RotationalSurface, Sense};

fn sphere(sense: Sense) -> RotationalSurface {
    RotationalSurface {
        radius: 5.0,
        conic: 0.0,
        sense,
        terms: vec![],
        aperture_radius: 2.0,
    }
}

#[test]
fn convex_sphere_offset_is_a_larger_sphere() {
    // The nose centre over a convex sphere of radius R lies on a sphere of
    // radius R + ρ about the same centre (0, −R).
    let s = sphere(Sense::Convex);
    for r in [0.0, 0.5, 1.9] {
        let c = tool_centre(&s, 0.3, r);
        let d = (c - Vector2::new(0.0, -5.0)).norm();
        assert!((d - 5.3).abs() < 1e-12, "r={r}: {d}");
    }
}

#[test]
fn concave_sphere_offset_is_a_smaller_sphere() {
    let s = sphere(Sense::Concave);
    let c = tool_centre(&s, 0.3, 1.2);
    assert!(((c - Vector2::new(0.0, 5.0)).norm() - 4.7).abs() < 1e-12);
}

#[test]
fn samples_stay_within_chord_tolerance() {
    let s = sphere(Sense::Convex);
    let f = |t: f64| tool_centre(&s, 0.3, t);
    let pts = sample_offset_curve(&f, 2.0, 0.0, 1e-5);
    // Every chord's midpoint on the exact circle R + ρ is within tolerance:
    // sagitta of a chord of length L on radius Rc is L²/(8 Rc).
    for w in pts.windows(2) {
        let l = (w[1] - w[0]).norm();
        assert!(l * l / (8.0 * 5.3) <= 1e-5 * 1.0001, "chord {l}");
    }
    assert!(pts.len() > 10);
    assert_eq!(pts[0].x, f(2.0).x);
    assert_eq!(pts.last().unwrap().x, 0.0);
}

/// Lei's searches are counted before planning (issue #33): a
/// `search_spacing` of 1e-12 mm asks for 3.5e12 discretised points here
/// (`lensc build` aborted on their allocation); a `search_step` of
/// 1e-15 mm over 1e12 steps at each centre (a build ran on past a
/// minute). Each is refused
/// (`SearchTooFine`) naming its parameter and count, by the check and by
/// the planner, before anything is allocated.
#[test]
fn searches_too_fine_to_count_are_refused_before_planning() {
    let s = super::edge_tests::asphere();
    let mut job = super::edge_tests::job(None);
    job.strategy.location = ToolLocation::Sequential {
        spacing: 1e-12,
        step: 1e-15,
    };
    for errors in [
        check_profile_turning(&job, &s).expect_err("refused"),
        plan_profile_turning(&job, &s).expect_err("refused"),
    ] {
        let found: Vec<(&str, f64)> = errors
            .iter()
            .filter_map(|e| match e {
                PlanError::SearchTooFine {
                    parameter, count, ..
                } => Some((*parameter, *count)),
                _ => None,
            })
            .collect();
        assert_eq!(found.len(), 2, "{errors:?}");
        assert_eq!(found[0].0, "search_spacing");
        assert!(found[0].1 > 3e12, "{found:?}");
        assert_eq!(found[1].0, "search_step");
        assert!(found[1].1 > 1e12, "{found:?}");
    }
    // A binary search's spacing is counted the same way; its tolerance
    // only halves a bracket, which stops where floating point does.
    job.strategy.location = ToolLocation::Binary {
        spacing: 1e-300,
        tolerance: 1e-300,
    };
    let errors = check_profile_turning(&job, &s).expect_err("refused");
    assert!(
        matches!(
            errors[..],
            [PlanError::SearchTooFine {
                parameter: "search_spacing",
                ..
            }]
        ),
        "{errors:?}"
    );
    // At Lei's own spacing and step the job is counted and planned.
    job.strategy.location = ToolLocation::Sequential {
        spacing: 1e-3,
        step: 1e-4,
    };
    assert!(check_profile_turning(&job, &s).is_ok());
}
