//! Tests of the measured edge: the spline, its derivative, the support
//! point and the lowest point against brute force, and the text format.

use super::*;
use std::f64::consts::PI;

/// A sinusoidal edge: `amplitude` (mm) with `periods` over ±`half` (rad),
/// sampled every `step` degrees.
fn wavy(amplitude: f64, periods: f64, half: f64, step: f64) -> EdgeProfile {
    let n = (2.0 * half.to_degrees() / step).round() as usize;
    let samples: Vec<Sample> = (0..=n)
        .map(|i| {
            let a = -half + 2.0 * half * i as f64 / n as f64;
            Sample {
                angle_deg: a.to_degrees(),
                deviation_um: amplitude * 1e3 * (periods * PI * a / half).sin(),
                line: i + 1,
                at: 0,
            }
        })
        .collect();
    EdgeProfile::from_samples(&samples).unwrap()
}

#[test]
fn the_spline_passes_through_every_sample() {
    let e = wavy(50e-6, 4.0, 1.0, 0.5);
    for (a, d) in e.angles.iter().zip(&e.deviations) {
        assert!((e.deviation(*a).0 - d).abs() < 1e-15);
    }
}

#[test]
fn the_slope_matches_finite_differences() {
    let e = wavy(50e-6, 4.0, 1.0, 0.5);
    let h = 1e-6;
    let mut worst: f64 = 0.0;
    for k in 0..997 {
        let t = -0.99 + 1.98 * k as f64 / 997.0;
        let fd = (e.deviation(t + h).0 - e.deviation(t - h).0) / (2.0 * h);
        let scale = 50e-6 * 4.0 * PI; // the sinusoid's largest slope (mm/rad)
        worst = worst.max((fd - e.deviation(t).1).abs() / scale);
    }
    assert!(worst < 1e-6, "slope off by {worst} of its largest");
}

#[test]
fn the_spline_follows_a_sampled_sinusoid() {
    // 0.5° samples of 4 periods over ±1 rad: the spline between them is
    // within a thousandth of the amplitude of the sinusoid.
    let e = wavy(50e-6, 4.0, 1.0, 0.5);
    for k in 0..1000 {
        let t = -0.95 + 1.9 * k as f64 / 1000.0;
        let exact = 50e-6 * (4.0 * PI * t).sin();
        assert!((e.deviation(t).0 - exact).abs() < 5e-8, "at {t}");
    }
}

#[test]
fn the_support_is_the_brute_force_maximum() {
    let e = wavy(50e-6, 4.0, 1.0, 0.5);
    let nose = Nose {
        radius: 0.5,
        edge: Some(&e),
    };
    for phi in [-0.8, -0.3, 0.0, 0.11, 0.6] {
        let (_, h) = nose.support(phi);
        let brute = (0..200_001)
            .map(|i| {
                let t = phi - 0.01 + 0.02 * i as f64 / 200_000.0;
                nose.rho(t).0 * (t - phi).cos()
            })
            .fold(f64::NEG_INFINITY, f64::max);
        assert!((h - brute).abs() < 1e-12, "at {phi}: {h} vs {brute}");
        // h ≈ R + δ(φ): the second-order term is below a nanometre here.
        assert!((h - 0.5 - e.deviation(phi).0).abs() < 1e-6);
    }
}

#[test]
fn the_lowest_point_is_on_the_edge() {
    let e = wavy(50e-6, 4.0, 1.0, 0.5);
    let nose = Nose {
        radius: 0.5,
        edge: Some(&e),
    };
    for x in [-0.4, -0.1, 0.0, 0.05, 0.3] {
        let z = nose.bottom((0.0, 1.0), x).unwrap();
        let theta = x.atan2(1.0 - z);
        let r = x.hypot(1.0 - z);
        assert!((r - nose.rho(theta).0).abs() < 1e-12, "at {x}");
    }
    // A circle's is the circle's.
    let c = Nose::circle(0.5);
    assert!((c.bottom((0.0, 0.0), 0.3).unwrap() + 0.4).abs() < 1e-15);
}

#[test]
fn the_depth_below_the_centre_and_its_slope_match_finite_differences() {
    let e = wavy(50e-6, 4.0, 1.0, 0.5);
    let nose = Nose {
        radius: 0.5,
        edge: Some(&e),
    };
    let h = 1e-7;
    for d in [-0.4, -0.12, 0.0, 0.07, 0.33] {
        let (l, slope) = nose.lift(d).unwrap();
        assert_eq!(nose.bottom((0.0, 0.0), d), Some(-l));
        let fd = (nose.lift(d + h).unwrap().0 - nose.lift(d - h).unwrap().0) / (2.0 * h);
        assert!((fd - slope).abs() < 1e-6, "at {d}: {fd} vs {slope}");
        // The wavy edge's depth is the circle's plus about δ / cos θ.
        let circle = Nose::circle(0.5).lift(d).unwrap().0;
        let theta = (d / 0.5_f64).asin();
        let expected = e.deviation(theta).0 / theta.cos();
        assert!((l - circle - expected).abs() < 2e-7, "at {d}");
    }
    assert_eq!(nose.lift(0.6), None);
}

#[test]
fn the_text_format_reads_a_certificate() {
    let text =
        "# edge of insert 4711\nangle_deg, deviation_um\n-60, 0.01\n0;0.02\n60\t-0.03 # end\n\n";
    let s = parse(text).unwrap();
    assert_eq!(s.len(), 3);
    assert_eq!(
        (s[1].angle_deg, s[1].deviation_um, s[1].line),
        (0.0, 0.02, 4)
    );
    assert_eq!(s[2].deviation_um, -0.03);
}

#[test]
fn bad_text_is_refused_with_its_line() {
    let e = parse("-60 0.01\n0 x\n").unwrap_err();
    assert!(
        matches!(e, EdgeError::Malformed { line: 2, at: 9, .. }),
        "{e:?}"
    );
    let e = parse("-60 0.01 3\n").unwrap_err();
    assert!(matches!(e, EdgeError::Malformed { line: 1, .. }));
    let s = parse("-60 0\n10 0\n5 0\n").unwrap();
    let e = EdgeProfile::from_samples(&s).unwrap_err();
    assert!(
        matches!(e, EdgeError::NotIncreasing { line: 3, .. }),
        "{e:?}"
    );
    let s = parse("-60 0\n10 0\n").unwrap();
    assert_eq!(
        EdgeProfile::from_samples(&s).unwrap_err(),
        EdgeError::TooFew { samples: 2 }
    );
}
