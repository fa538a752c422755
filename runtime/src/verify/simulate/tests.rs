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

/// An arc about (0, 10) through its lowest point (0, 0), ±0.2 rad about
/// it, printed with its end `delta` mm further from the centre than its
/// start, as the reader hands it over.
fn blended_arc(delta: f64) -> Vec<Executed> {
    let (o, r) = ((0.0, 10.0), 10.0);
    let at = |ang: f64, rr: f64| {
        [
            Some(o.0 + rr * ang.sin()),
            None,
            Some(o.1 + rr * ang.cos()),
            None,
        ]
    };
    vec![Executed {
        from: at(PI - 0.2, r),
        to: at(PI + 0.2, r + delta),
        path: Path::Arc {
            plane: Plane::Zx,
            centre: (o.1, o.0),
            cw: false,
            turn: 0.4,
        },
    }]
}

#[test]
fn an_arc_whose_end_radius_differs_is_cut_as_the_controller_blends_it() {
    let delta = 1e-4;
    let pieces = executed_pieces(&blended_arc(delta));
    assert_eq!(pieces.len(), 1);
    let bottom = |x: f64| pieces[0].bottom(&Nose::circle(RHO), x).expect("reached");
    // Halfway round, the radius is halfway from start to end (LinuxCNC's
    // pmCirclePoint); a sweep at the start radius would cut -0.5.
    let mid = bottom(0.0);
    // (The spiral's normal tilts by r′/r: 0.16 pm lower.)
    assert!((mid - (-0.5 - delta / 2.0)).abs() < 1e-9, "{mid}");
    // A quarter of the way from the start and from the end: a quarter and
    // three quarters of the difference.
    for (f, share) in [(0.25, 0.25), (0.75, 0.75)] {
        let ang = PI - 0.2 + 0.4 * f;
        let rr = 10.0 + RHO + delta * share;
        let x = rr * ang.sin();
        let z = bottom(x);
        let want = 10.0 + rr * ang.cos();
        assert!((z - want).abs() < 1e-9, "{f}: {z} {want}");
    }
    // With no difference, the circle of the start radius.
    let circle = executed_pieces(&blended_arc(0.0));
    assert!((circle[0].bottom(&Nose::circle(RHO), 0.0).expect("reached") + 0.5).abs() < 1e-12);
}

#[test]
fn the_program_cut_of_a_blended_arc_follows_the_spiral_not_the_start_circle() {
    let delta = 5.7e-5;
    let moves = blended_arc(delta);
    // The design: the lower envelope of 200 001 discs along the spiral
    // r = 10 + δ θ / 0.4 about (0, 10) (their spacing leaves < 0.1 nm).
    let n = 200_000;
    let centres: Vec<(f64, f64)> = (0..=n)
        .map(|i| {
            let f = i as f64 / n as f64;
            let (ang, rr) = (PI - 0.2 + 0.4 * f, 10.0 + delta * f);
            (rr * ang.sin(), 10.0 + rr * ang.cos())
        })
        .collect();
    let envelope = |x: f64| {
        centres
            .iter()
            .filter_map(|&c| Nose::circle(RHO).bottom(c, x))
            .fold(f64::INFINITY, f64::min)
    };
    let cut = program_cut(&moves, RHO, &envelope, (-1.5, 1.5), 61);
    assert!(
        cut.pv < 1e-9 && cut.mean.abs() < 1e-9,
        "{} {}",
        cut.pv,
        cut.mean
    );
    // The circle of the start radius would leave δ-sized errors near the
    // end of the arc.
    let mut circle = executed_pieces(&moves);
    if let Piece::Arc { r, r_end, .. } = &mut circle[0] {
        *r_end = *r;
    }
    let circle_cut = cut_of(&circle, &Nose::circle(RHO), &envelope, (-1.5, 1.5), 61);
    assert!(circle_cut.pv > 0.5 * delta, "{}", circle_cut.pv);
}

/// `Printed` rounds as the writer's own `fixed_units` scaled back, for
/// every resolution the machines use and values of every magnitude,
/// halves and non-finite ones included.
#[test]
fn printed_rounds_as_the_writer_prints() {
    use crate::post::format::{decimals_for, fixed_units};
    let mut values = vec![
        0.0,
        -0.0,
        3.0717655,
        -2.9999995,
        0.0000005,
        1e17,
        1e30,
        f64::NAN,
        f64::INFINITY,
    ];
    let mut state = 0x2545_f491_4f6c_dd1du64;
    for _ in 0..20_000 {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        values.push((state % 20_000_000_000) as f64 * 1e-9 - 10.0);
        values.push(f64::from_bits(state));
    }
    for resolution in [1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 1.0, 5e-7, 1e-9] {
        let d = decimals_for(resolution);
        let p = Printed::new(resolution);
        for &v in &values {
            let expected = match fixed_units(v, d) {
                Some(n) => n as f64 / 10f64.powi(d as i32),
                None => v,
            };
            let got = p.round(v);
            assert!(
                got.to_bits() == expected.to_bits() || (got.is_nan() && expected.is_nan()),
                "{v:e} at {resolution:e}: {got:e} vs {expected:e}"
            );
            assert!(got.to_bits() == as_printed(v, resolution).to_bits() || got.is_nan());
        }
    }
}

/// A measured edge: 50 nm, 5 periods over ±40°, sampled each 0.25°.
fn wavy_edge() -> crate::machine::edge::EdgeProfile {
    use crate::machine::edge::{EdgeProfile, Sample};
    let samples: Vec<Sample> = (0..=320)
        .map(|i| {
            let a = -40.0 + 0.25 * i as f64;
            Sample {
                angle_deg: a,
                deviation_um: 0.05 * (5.0 * PI * a / 40.0).sin(),
                line: i + 1,
                at: 0,
            }
        })
        .collect();
    EdgeProfile::from_samples(&samples).unwrap()
}

#[test]
fn a_measured_edge_swept_along_an_arc_and_a_line_is_its_brute_force_envelope() {
    // The lowest point of the wavy nose swept along each piece, against
    // the lowest of the nose placed at 200,001 points along it.
    let edge = wavy_edge();
    let nose = Nose {
        radius: RHO,
        edge: Some(&edge),
    };
    // An arc about (0, −10), radius 10.5, from −8° to +8° (G18 angles
    // from +Z towards +X), blended to radius 10.5003; and a sloped line.
    let (o, r0, r1, start, sweep) = ((0.0, -10.0), 10.5, 10.5003, -0.14, 0.28);
    let at = |t: f64| {
        let (ang, r) = (start + sweep * t, r0 + (r1 - r0) * t);
        (o.0 + r * ang.sin(), o.1 + r * ang.cos())
    };
    let arc = Piece::Arc {
        o,
        r: r0,
        r_end: r1,
        start,
        sweep,
        a: at(0.0),
        b: at(1.0),
    };
    let line = Piece::Line {
        a: (-1.0, 0.3),
        b: (1.0, -0.2),
    };
    let line_at = |t: f64| (-1.0 + 2.0 * t, 0.3 - 0.5 * t);
    for (piece, path) in [
        (arc, &at as &dyn Fn(f64) -> (f64, f64)),
        (line, &line_at as &dyn Fn(f64) -> (f64, f64)),
    ] {
        for x in [-1.2, -0.7, -0.2, 0.0, 0.35, 0.9] {
            let swept = piece.bottom(&nose, x).expect("reached");
            let brute = (0..=200_000)
                .filter_map(|i| nose.bottom(path(i as f64 / 200_000.0), x))
                .fold(f64::INFINITY, f64::min);
            assert!(
                (swept - brute).abs() < 2e-9,
                "{piece:?} at {x}: {swept} vs {brute}"
            );
        }
    }
}
