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
