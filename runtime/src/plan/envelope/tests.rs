//! Tests of the nose envelope: exact centre heights against discretised search.

use super::*;
use crate::surface::ProfilePoint;

#[path = "lei_arcs.rs"]
mod lei_arcs;
use lei_arcs::{Arcs, lei};

#[test]
fn corners_are_found_where_the_arcs_meet_the_seams() {
    let a = lei();
    let pieces = split_at_corners(&a, 0.0, 3.0 * 0.554);
    // Three cells: arcs from 0.01 to 0.544, 0.564 to 1.098, 1.118 to 1.652.
    let want = [0.01, 0.544, 0.564, 1.098, 1.118, 1.652];
    assert_eq!(pieces.corners.len(), want.len(), "{:?}", pieces.corners);
    for (c, w) in pieces.corners.iter().zip(want) {
        assert!((c.at - w).abs() < 1e-12, "corner {} vs {w}", c.at);
        assert!(c.is_concave());
    }
}

#[test]
fn on_an_arc_the_centre_is_on_the_concentric_circle() {
    let a = lei();
    let pieces = split_at_corners(&a, 0.0, 0.554);
    let rho = 0.1;
    let rim = (0.788f64 * 0.788 - 0.267 * 0.267).sqrt();
    for x in [0.2, 0.277, 0.35] {
        let (h, _) = centre_height(&a, &pieces, rho, x);
        let want = ((0.788f64 + rho).powi(2) - (x - 0.277).powi(2)).sqrt() - rim;
        assert!((h - want).abs() < 1e-13, "{h} vs {want}");
    }
}

#[test]
fn in_a_seam_the_nose_rests_on_both_arcs() {
    // Centred over the seam at x = 0.554, the 0.5 mm nose touches both
    // arc edges (symmetric): its centre is where circles of radius
    // R + ρ about both arc centres meet.
    let a = lei();
    let pieces = split_at_corners(&a, 0.0, 2.0 * 0.554);
    let rho = 0.5;
    let (h, _) = centre_height(&a, &pieces, rho, 0.554);
    let rim = (0.788f64 * 0.788 - 0.267 * 0.267).sqrt();
    let half = 0.277;
    let want = ((0.788f64 + rho).powi(2) - half * half).sqrt() - rim;
    assert!((h - want).abs() < 1e-12, "{h} vs {want}");
    // The seam is left uncut: the nose bottom there is well above z = 0.
    let cut = cut_height(&a, &pieces, rho, 0.554);
    assert!(cut > 0.01, "cut {cut}");
    assert!((cut - (want - rho)).abs() < 1e-9, "{cut} vs {}", want - rho);
}

#[test]
fn the_envelope_never_gouges() {
    let a = lei();
    // Two splits: their corners fall on different sides of the exact ones.
    for pieces in [
        split_at_corners(&a, 0.0, 2.0 * 0.554),
        split_at_corners(&a, -0.5, 5.54),
    ] {
        never_gouges(&a, &pieces);
    }
}

fn never_gouges(a: &Arcs, pieces: &Pieces) {
    let rho = 0.5;
    for i in 0..200 {
        let x = 0.3 + 0.5 * i as f64 / 200.0;
        let (h, _) = centre_height(a, pieces, rho, x);
        for j in 0..2000 {
            let u = x - rho + 2.0 * rho * j as f64 / 2000.0;
            if !(0.0..=1.108).contains(&u) {
                continue;
            }
            let z = a.point(u).z;
            let d = ((u - x).powi(2) + (z - h).powi(2)).sqrt();
            assert!(d >= rho - 1e-12, "gouge at x {x}, u {u}: {d}");
        }
    }
}

#[test]
fn the_envelope_is_symmetric_about_a_seam() {
    // Corners located a hair to either side must not matter: every seam
    // of the symmetric profile is cut the same from both sides.
    let a = lei();
    let pieces = split_at_corners(&a, -0.5, 5.54);
    let rho = 0.5;
    for d in [0.0, 0.003, 0.005, 0.01, 0.05, 0.2] {
        let (l, _) = centre_height(&a, &pieces, rho, 0.554 - d);
        let (r, _) = centre_height(&a, &pieces, rho, 0.554 + d);
        assert!((l - r).abs() < 1e-12, "at ±{d}: {l} vs {r}");
    }
    let (l, r) = (
        cut_height(&a, &pieces, rho, 0.544),
        cut_height(&a, &pieces, rho, 0.564),
    );
    assert!((l - r).abs() < 1e-12, "{l} vs {r}");
}

#[test]
fn reference_searches_agree_with_the_exact_height() {
    let a = lei();
    let pieces = split_at_corners(&a, 0.0, 2.0 * 0.554);
    let rho = 0.5;
    let n = 20_000;
    let pts: Vec<(f64, f64)> = (0..=n)
        .map(|i| {
            let u = 1.108 * i as f64 / n as f64;
            (u, a.point(u).z)
        })
        .collect();
    for x in [0.2, 0.5, 0.554, 0.7] {
        let (exact, _) = centre_height(&a, &pieces, rho, x);
        let b = binary_search(points_near(&pts, x, rho), rho, x, 1e-9);
        assert_eq!(
            b,
            binary_search(&pts, rho, x, 1e-9),
            "windowing changes nothing"
        );
        // Discretised at 55 nm, the points sit on the arcs, so the
        // searches can only sit lower, by at most the chordal gap.
        assert!(
            b <= exact + 1e-9 && exact - b < 1e-6,
            "binary {b} vs {exact}"
        );
        let s = sequential_search(&pts, rho, x, exact + 0.01, 1e-5);
        assert!(
            s <= exact + 1e-9 && exact - s < 1e-5 + 1e-6,
            "sequential {s} vs {exact}"
        );
    }
}

/// A bracket below the heights' floating-point spacing cannot be halved:
/// the binary search stops where the midpoint is one of its ends, at a
/// height that clears, instead of halving for ever (issue #33: a
/// `search_step` of 1e-15 mm hung a build).
#[test]
fn the_binary_search_stops_where_floating_point_cannot_halve() {
    let a = lei();
    let pieces = split_at_corners(&a, 0.0, 2.0 * 0.554);
    let rho = 0.5;
    let n = 2_000;
    let pts: Vec<(f64, f64)> = (0..=n)
        .map(|i| {
            let u = 1.108 * i as f64 / n as f64;
            (u, a.point(u).z)
        })
        .collect();
    for x in [0.2, 0.554] {
        let (exact, _) = centre_height(&a, &pieces, rho, x);
        let b = binary_search(points_near(&pts, x, rho), rho, x, 1e-300);
        assert!(
            b <= exact + 1e-9 && exact - b < 1e-4,
            "binary {b} vs {exact}"
        );
    }
}
