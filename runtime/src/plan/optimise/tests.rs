//! Tests of the program optimiser: lines and arcs fitted within tolerance.

use super::*;

const TOL: f64 = 2.5e-6;

/// A lathe-like stream: spindle on, rapid to the start, cutting moves
/// through `pts` (X, Z) with the feed on every move, spindle off.
fn lathe_stream(pts: &[(f64, f64)]) -> Vec<Move> {
    let feed = Some(Feed::PerRevolution(0.001));
    let mut s = vec![
        Move::SpindleOn(100.0),
        Move::Rapid(Position::xz(pts[0].0, pts[0].1 + 1.0)),
        Move::Linear {
            to: Position::xz(pts[0].0, pts[0].1),
            feed,
        },
    ];
    s.extend(pts[1..].iter().map(|&(x, z)| Move::Linear {
        to: Position::xz(x, z),
        feed,
    }));
    s.push(Move::SpindleOff);
    s
}

/// Where a move's path is after the fraction `t` of it, in X and Z.
fn along(from: (f64, f64), m: &Move, t: f64) -> (f64, f64) {
    match *m {
        Move::Linear { to, .. } => (from.0 + t * (to.x - from.0), from.1 + t * (to.z - from.1)),
        Move::Arc {
            to, centre, ccw, ..
        } => {
            // Plane ZX: first axis Z, second X.
            let (cz, cx) = (centre.z, centre.x);
            let a0 = (from.0 - cx).atan2(from.1 - cz);
            let a1 = (to.x - cx).atan2(to.z - cz);
            let mut sweep = a1 - a0;
            if ccw {
                sweep = sweep.rem_euclid(2.0 * PI);
            } else {
                sweep = -(-sweep).rem_euclid(2.0 * PI);
            }
            let r = ((from.0 - cx).powi(2) + (from.1 - cz).powi(2)).sqrt();
            let a = a0 + t * sweep;
            (cx + r * a.sin(), cz + r * a.cos())
        }
        _ => from,
    }
}

/// The largest distance from any of `pts` to the optimised path, and
/// from the optimised path (sampled) to the polyline through `pts`.
fn hausdorff(pts: &[(f64, f64)], out: &[Move]) -> f64 {
    let mut path = vec![pts[0]];
    let mut from = pts[0];
    for m in out
        .iter()
        .skip_while(|m| !matches!(m, Move::Linear { .. }))
        .skip(1)
    {
        if let Move::Linear { .. } | Move::Arc { .. } = m {
            // Fine enough that the samples' own chords sag far below
            // the tolerance (1 mm at radius 2 mm: 0.3 nm).
            for k in 1..=2048 {
                path.push(along(from, m, k as f64 / 2048.0));
            }
            from = along(from, m, 1.0);
        }
    }
    let seg_dist = |p: (f64, f64), a: (f64, f64), b: (f64, f64)| {
        let (dx, dz) = (b.0 - a.0, b.1 - a.1);
        let l2 = dx * dx + dz * dz;
        let t = if l2 == 0.0 {
            0.0
        } else {
            (((p.0 - a.0) * dx + (p.1 - a.1) * dz) / l2).clamp(0.0, 1.0)
        };
        ((p.0 - a.0 - t * dx).powi(2) + (p.1 - a.1 - t * dz).powi(2)).sqrt()
    };
    let to_poly = |p: (f64, f64), poly: &[(f64, f64)]| {
        poly.windows(2)
            .map(|w| seg_dist(p, w[0], w[1]))
            .fold(f64::INFINITY, f64::min)
    };
    let a = pts.iter().map(|&p| to_poly(p, &path)).fold(0.0, f64::max);
    let b = path.iter().map(|&p| to_poly(p, pts)).fold(0.0, f64::max);
    a.max(b)
}

#[test]
fn points_on_a_circle_become_one_arc_in_the_right_direction() {
    // A convex cap of radius 2 mm: z = sqrt(R² − x²) − R, cut from the
    // rim to the centre (X decreasing).
    let r = 2.0;
    let pts: Vec<(f64, f64)> = (0..=200)
        .map(|k| {
            let x = 1.0 - k as f64 / 200.0;
            (x, (r * r - x * x).sqrt() - r)
        })
        .collect();
    let stream = lathe_stream(&pts);
    let (out, s) = optimise(&stream, TOL, &[Plane::Zx]);
    assert_eq!(s.arcs, 1, "{out:?}");
    assert_eq!(s.moves_before, stream.len());
    assert_eq!(s.moves_after, out.len());
    assert_eq!(out.len(), 5);
    let Move::Arc { centre, to, .. } = out[3] else {
        panic!("{out:?}")
    };
    assert!(
        (centre.x).abs() < 1e-9 && (centre.z + r).abs() < 1e-9,
        "{centre:?}"
    );
    assert_eq!((to.x, to.z), pts[200]);
    assert!(s.max_deviation <= TOL);
    let d = hausdorff(&pts, &out);
    assert!(d <= TOL, "{d} {out:?}");
    // The arc's middle lies on the cap, not on the other side.
    let mid = along(pts[0], &out[3], 0.5);
    assert!(
        (mid.1 - ((r * r - mid.0 * mid.0).sqrt() - r)).abs() < 1e-9,
        "{mid:?}"
    );
}

#[test]
fn concave_arcs_turn_the_other_way() {
    let r = 3.0;
    let pts: Vec<(f64, f64)> = (0..=1000)
        .map(|k| {
            let x = 1.5 * k as f64 / 1000.0;
            (x, r - (r * r - x * x).sqrt())
        })
        .collect();
    let (out, s) = optimise(&lathe_stream(&pts), TOL, &[Plane::Zx]);
    assert_eq!(s.arcs, 1);
    let arc = out.iter().find(|m| matches!(m, Move::Arc { .. })).unwrap();
    let mid = along(pts[0], arc, 0.5);
    assert!(
        (mid.1 - (r - (r * r - mid.0 * mid.0).sqrt())).abs() < 1e-9,
        "{mid:?}"
    );
    assert!(hausdorff(&pts, &out) <= TOL);
}

#[test]
fn collinear_points_merge_and_corners_stay() {
    // Two straight legs with wobble below the tolerance.
    let mut pts: Vec<(f64, f64)> = (0..=50)
        .map(|k| {
            let x = k as f64 * 0.01;
            (x, 1e-6 * ((k * 7 % 5) as f64 / 4.0 - 0.5))
        })
        .collect();
    pts.extend((1..=50).map(|k| (0.5, -(k as f64) * 0.01)));
    let (out, s) = optimise(&lathe_stream(&pts), TOL, &[]);
    assert_eq!(s.arcs, 0);
    let lines = out
        .iter()
        .filter(|m| matches!(m, Move::Linear { .. }))
        .count();
    assert_eq!(lines, 3, "{out:?}"); // the plunge and one line per leg
    assert!(hausdorff(&pts, &out) <= TOL);
    assert!(s.max_deviation > 0.0 && s.max_deviation <= TOL);
}

#[test]
fn any_profile_stays_within_tolerance_of_the_polyline() {
    // Sampled sines and steps of many sizes, some far coarser than the
    // tolerance, some finer: whatever is fitted, nothing strays.
    for (amp, freq, n) in [
        (0.01, 3.0, 400),
        (1e-6, 40.0, 300),
        (0.2, 1.0, 50),
        (2e-6, 1.0, 999),
    ] {
        let pts: Vec<(f64, f64)> = (0..=n)
            .map(|k| {
                let x = 2.0 - 2.0 * k as f64 / n as f64;
                (x, amp * (freq * x).sin() + 0.01 * x * x)
            })
            .collect();
        let (out, s) = optimise(&lathe_stream(&pts), TOL, &[Plane::Zx]);
        let d = hausdorff(&pts, &out);
        assert!(d <= TOL * 1.001, "amp {amp} freq {freq}: {d}");
        assert!(s.max_deviation <= TOL);
        assert!(s.moves_after <= s.moves_before);
    }
}

#[test]
fn rapids_spindle_and_inverse_time_moves_are_kept() {
    let stream = vec![
        Move::Rapid(Position::xzc(1.0, 1.0, 0.0)),
        Move::Linear {
            to: Position::xzc(0.9, 0.0, 1.0),
            feed: Some(Feed::InverseTime(0.1)),
        },
        Move::Linear {
            to: Position::xzc(0.8, 0.0, 2.0),
            feed: Some(Feed::InverseTime(0.1)),
        },
        Move::Linear {
            to: Position::xzc(0.7, 0.0, 3.0),
            feed: Some(Feed::InverseTime(0.1)),
        },
        Move::SpindleOff,
    ];
    let (out, s) = optimise(&stream, TOL, &[Plane::Zx]);
    assert_eq!(format!("{out:?}"), format!("{stream:?}"));
    assert_eq!(s.arcs + s.merged_lines, 0);
}

/// The largest depth (mm) by which the optimised path, sampled, passes
/// below the polyline through `pts` (X, Z; X increasing), in Z at the
/// same X.
fn deepest_below(pts: &[(f64, f64)], out: &[Move]) -> f64 {
    let polyline = |x: f64| {
        let i = pts.partition_point(|p| p.0 <= x).clamp(1, pts.len() - 1);
        let (a, b) = (pts[i - 1], pts[i]);
        a.1 + (x - a.0) / (b.0 - a.0) * (b.1 - a.1)
    };
    let mut from = pts[0];
    let mut deepest: f64 = 0.0;
    for m in out
        .iter()
        .skip_while(|m| !matches!(m, Move::Linear { .. }))
        .skip(1)
    {
        if !matches!(m, Move::Linear { .. } | Move::Arc { .. }) {
            continue;
        }
        for k in 0..=200 {
            let p = along(from, m, k as f64 / 200.0);
            deepest = deepest.max(polyline(p.0) - p.1);
        }
        from = along(from, m, 1.0);
    }
    deepest
}

#[test]
fn fits_held_above_stay_on_or_above_the_polyline() {
    // A convex arc (centre below) whose points alternate 1 µm above and
    // on it: fitted both ways, arcs pass below the raised points; held
    // above, nothing passes below the polyline.
    let r = 3.0;
    let pts: Vec<(f64, f64)> = (0..=400)
        .map(|k| {
            let x = 1.5 * k as f64 / 400.0;
            let lift = if k % 2 == 1 { 1e-6 } else { 0.0 };
            (x, (r * r - x * x).sqrt() + lift)
        })
        .collect();
    let (both, _) = optimise(&lathe_stream(&pts), TOL, &[Plane::Zx]);
    assert!(deepest_below(&pts, &both) > 0.5e-6);
    let (above, s) = optimise_within(&lathe_stream(&pts), TOL, &[Plane::Zx], true);
    assert!(s.moves_after < s.moves_before, "{s:?}");
    let depth = deepest_below(&pts, &above);
    assert!(depth <= 1e-9, "{depth}");
    assert!(hausdorff(&pts, &above) <= TOL);
    // A concave arc (centre above) likewise.
    let pts: Vec<(f64, f64)> = pts.iter().map(|&(x, z)| (x, -z + 2e-6)).collect();
    let (above, _) = optimise_within(&lathe_stream(&pts), TOL, &[Plane::Zx], true);
    let depth = deepest_below(&pts, &above);
    assert!(depth <= 1e-9, "{depth}");
}
