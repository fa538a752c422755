//! Tests of the cut simulation.

use super::*;
use crate::moves::{Feed, Position};

const RHO: f64 = 0.5;

/// A sphere of radius `r` (convex, vertex at 0): the nose centre runs
/// on the sphere of radius r + ρ.
fn convex(r: f64) -> impl Fn(f64) -> f64 {
    move |x: f64| (r * r - x * x).sqrt() - r
}

fn linear(x: f64, z: f64) -> Move {
    Move::Linear {
        to: Position::xz(x, z),
        feed: Some(Feed::PerTime(1.0)),
    }
}

#[test]
fn one_exact_arc_cuts_the_sphere_it_offsets() {
    let r = 10.0;
    let rc = r + RHO;
    let start = (2.0f64, (rc * rc - 4.0).sqrt() - r);
    let stream = [
        Move::Rapid(Position::xz(start.0, 5.0)),
        linear(start.0, start.1),
        Move::Arc {
            to: Position::xz(0.0, RHO),
            centre: Position::xz(0.0, -r),
            plane: Plane::Zx,
            ccw: false,
            feed: None,
        },
    ];
    let cut = profile_cut(&stream, RHO, 1e-9, &convex(r), (0.0, 1.5), 301);
    assert_eq!(cut.samples.len(), 301);
    assert!(cut.pv < 1e-9 && cut.rms < 1e-9, "{} {}", cut.pv, cut.rms);
}

/// The same arc set 44 nm too deep (the sphere, which reported
/// "PV 6.03 nm, RMS 42.6 nm"): the form is perfect (PV and RMS about the
/// mean below a picometre, never RMS > PV) and the shift is the mean and
/// the largest deviation, a gouge of 44 nm.
#[test]
fn an_arc_set_too_deep_shows_its_shift_in_the_mean() {
    let (r, deep) = (10.0, 44e-6);
    let rc = r + RHO;
    let start = (2.0f64, (rc * rc - 4.0).sqrt() - r - deep);
    let stream = [
        Move::Rapid(Position::xz(start.0, 5.0)),
        linear(start.0, start.1),
        Move::Arc {
            to: Position::xz(0.0, RHO - deep),
            centre: Position::xz(0.0, -r - deep),
            plane: Plane::Zx,
            ccw: false,
            feed: None,
        },
    ];
    let cut = profile_cut(&stream, RHO, 1e-9, &convex(r), (0.0, 1.5), 301);
    assert!(cut.pv < 1e-9 && cut.rms < 1e-9, "{} {}", cut.pv, cut.rms);
    assert!(cut.rms <= cut.pv);
    assert!((cut.mean + deep).abs() < 1e-9, "{}", cut.mean);
    assert!(
        (cut.largest_deviation.0 + deep).abs() < 1e-9,
        "{:?}",
        cut.largest_deviation
    );
    assert!((cut.max_gouge.0 - deep).abs() < 1e-9, "{:?}", cut.max_gouge);
}

#[test]
fn the_centre_path_follows_the_printed_moves_and_breaks_at_rapids() {
    let stream = [
        Move::Rapid(Position::xz(2.0, 5.0)),
        linear(2.0, 0.0004),
        Move::Arc {
            to: Position::xz(0.0, 2.0),
            centre: Position::xz(0.0, 0.0),
            plane: Plane::Zx,
            ccw: false,
            feed: None,
        },
        Move::Rapid(Position::xz(3.0, 5.0)),
        linear(3.0, 1.0),
        linear(2.5, 1.0),
    ];
    let runs = centre_path(&stream, 1e-3);
    assert_eq!(runs.len(), 2);
    // The plunge's end as printed to 1 µm, then the quarter arc up to
    // the axis at 1° steps, every point on its circle.
    assert_eq!(runs[0][0], (2.0, 5.0));
    assert_eq!(runs[0][1], (2.0, 0.0));
    let arc = &runs[0][1..];
    assert_eq!(arc.len(), 91);
    for p in arc {
        assert!((p.0.hypot(p.1) - 2.0).abs() < 1e-12, "{p:?}");
    }
    assert!(arc.windows(2).all(|w| w[1].0 < w[0].0 && w[1].1 > w[0].1));
    assert_eq!(runs[1], vec![(3.0, 5.0), (3.0, 1.0), (2.5, 1.0)]);
}

#[test]
fn chords_cut_a_convex_part_by_their_sag_and_rounding_shows() {
    // Lines through points on the nose-centre sphere lie inside it, on
    // the material's side: the cut dips below the design between points
    // by the chord's sag, L²/(8 Rc).
    let r = 10.0;
    let rc = r + RHO;
    let step = 0.1;
    let mut stream = vec![Move::Rapid(Position::xz(2.0, 5.0))];
    let mut x = 2.0f64;
    while x > -1e-12 {
        stream.push(linear(x.max(0.0), (rc * rc - x * x).sqrt() - r));
        x -= step;
    }
    let cut = profile_cut(&stream, RHO, 1e-9, &convex(r), (0.0, 1.5), 3001);
    // The chord of length ≈ 0.1 on radius rc, offset by the nose.
    let sag = step * step / (8.0 * rc);
    assert!(cut.max_residual.0 < 1e-9, "{:?}", cut.max_residual);
    assert!(
        (cut.max_gouge.0 - sag).abs() < 0.1 * sag,
        "{:?} vs {sag}",
        cut.max_gouge
    );
    // Rounded to 1 µm, the same path is off by up to half of it.
    let coarse = profile_cut(&stream, RHO, 1e-3, &convex(r), (0.0, 1.5), 3001);
    assert!(coarse.pv > cut.pv + 1e-4, "{} vs {}", coarse.pv, cut.pv);
}

#[test]
fn a_path_dropped_too_low_is_a_gouge_where_it_drops() {
    let r = 10.0;
    let rc = r + RHO;
    let z = |x: f64| (rc * rc - x * x).sqrt() - r;
    // Points every 10 µm (chord sag 5 pm), one of them 1 µm low.
    let mut stream = vec![Move::Rapid(Position::xz(1.0, 5.0))];
    for k in 0..=100 {
        let x = 1.0 - 0.01 * k as f64;
        let low = if k == 20 { 0.001 } else { 0.0 };
        stream.push(linear(x, z(x) - low));
    }
    let cut = profile_cut(&stream, RHO, 1e-9, &convex(r), (0.0, 1.0), 2001);
    assert!(
        (cut.max_gouge.0 - 0.001).abs() < 2e-5,
        "{:?}",
        cut.max_gouge
    );
    // Seen through the nose, the dip is where the nose below (0.8, …)
    // touches the design: at about x = 0.8 · r / rc.
    assert!(
        (cut.max_gouge.1 - 0.8 * r / rc).abs() < 0.01,
        "{:?}",
        cut.max_gouge
    );
}
