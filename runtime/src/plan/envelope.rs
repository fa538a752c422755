//! Exact, gouge-free tool location over a profile with corners (seams):
//! the nose-centre height at each x is the highest point of the nose
//! circles touching the profile, found piece by piece with Newton's method
//! on the exact derivatives; and the reference methods of Lei et al. 2021
//! (seed 004), sequential and binary search over a discretised profile.
//!
//! For a nose of radius ρ whose centre is at x, the lowest centre height
//! that clears the profile z(u) is
//!   z_c(x) = max over |u − x| ≤ ρ of  φ(u) = z(u) + sqrt(ρ² − (u − x)²).
//! On a smooth piece where ρ is below the concave radius of curvature, φ is
//! concave, so its maximum is either an end of the piece or the single root
//! of φ′(u) = z′(u) − (u − x)/sqrt(ρ² − (u − x)²) (the normal-offset
//! contact). A profile's corners split it into such pieces.

use crate::surface::Profile;

/// A profile split at its corners into smooth pieces.
#[derive(Clone, Debug, PartialEq)]
pub struct Pieces {
    /// Piece boundaries, ascending: piece i is [bounds[i], bounds[i + 1]].
    pub bounds: Vec<f64>,
    /// Interior boundaries that are corners.
    pub corners: Vec<Corner>,
    /// An upper bound of z on each piece (the scan's highest point plus
    /// the most a slope-limited curve can rise between scan points).
    pub z_bound: Vec<f64>,
}

/// A point where the profile's slope jumps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Corner {
    pub at: f64,
    /// z′ just before and just after the corner.
    pub slope_left: f64,
    pub slope_right: f64,
}

impl Corner {
    /// A concave corner (a groove or seam): no round nose can reach it.
    pub fn is_concave(&self) -> bool {
        self.slope_right > self.slope_left
    }
    /// The angle (rad) the profile turns through at the corner.
    pub fn angle(&self) -> f64 {
        self.slope_right.atan() - self.slope_left.atan()
    }
}

/// Number of scan intervals used to look for corners.
const SCAN: usize = 8192;

/// Finds the corners of `profile` on [a, b] (a < b): wherever the slope
/// changes between neighbouring scan points by more than the curvature
/// there explains, the corner is located by bisection to 1e-13 mm.
pub fn split_at_corners(profile: &dyn Profile, a: f64, b: f64) -> Pieces {
    let h = (b - a) / SCAN as f64;
    let mut bounds = vec![a];
    let mut corners = Vec::new();
    let mut z_bound = Vec::new();
    let mut top = f64::NEG_INFINITY;
    let mut u0 = a;
    for i in 1..=SCAN {
        let u1 = if i == SCAN { b } else { a + h * i as f64 };
        let (p0, p1) = (profile.point(u0), profile.point(u1));
        top = top.max(p0.z.max(p1.z) + 0.5 * h * p0.dz.abs().max(p1.dz.abs()));
        if unexplained_slope_change(profile, u0, u1) {
            let at = locate_corner(profile, u0, u1);
            let (l, r) = (profile.point(at - 1e-9), profile.point(at + 1e-9));
            if at > a && at < b {
                z_bound.push(top);
                top = f64::NEG_INFINITY;
                bounds.push(at);
                corners.push(Corner {
                    at,
                    slope_left: l.dz,
                    slope_right: r.dz,
                });
            }
        }
        u0 = u1;
    }
    bounds.push(b);
    z_bound.push(top);
    Pieces {
        bounds,
        corners,
        z_bound,
    }
}

/// Whether z′ changes over [u0, u1] by more than the trapezoid rule on z″
/// predicts (a smooth profile's error here is ~h³ z‴/12, far below this).
fn unexplained_slope_change(profile: &dyn Profile, u0: f64, u1: f64) -> bool {
    let (p0, p1) = (profile.point(u0), profile.point(u1));
    let change = p1.dz - p0.dz;
    let predicted = 0.5 * (p0.d2z + p1.d2z) * (u1 - u0);
    let z_change = p1.z - p0.z;
    let z_predicted = 0.5 * (p0.dz + p1.dz) * (u1 - u0);
    (change - predicted).abs() > 1e-7 + 1e-3 * change.abs()
        || (z_change - z_predicted).abs() > 1e-9 + 1e-3 * z_change.abs()
}

/// Bisection towards the half that still holds the unexplained change.
fn locate_corner(profile: &dyn Profile, mut u0: f64, mut u1: f64) -> f64 {
    while u1 - u0 > 1e-13 {
        let m = 0.5 * (u0 + u1);
        if m <= u0 || m >= u1 {
            break;
        }
        if unexplained_slope_change(profile, u0, m) {
            u1 = m;
        } else {
            u0 = m;
        }
    }
    0.5 * (u0 + u1)
}

/// The exact lowest nose-centre height at `x` that clears the profile on
/// [pieces.bounds[0], last bound], and the contact point u.
pub fn centre_height(profile: &dyn Profile, pieces: &Pieces, rho: f64, x: f64) -> (f64, f64) {
    let (lo, hi) = (x - rho, x + rho);
    // The pieces within reach, each with the highest the nose could be
    // lifted by it; searched from the highest bound down, stopping once no
    // piece left can beat the best height found.
    let first = pieces.bounds.partition_point(|&b| b < lo).saturating_sub(1);
    let mut candidates: Vec<(f64, f64, f64)> = Vec::with_capacity(8);
    for (w, &z_top) in pieces.bounds[first..]
        .windows(2)
        .zip(&pieces.z_bound[first..])
    {
        if w[0] > hi {
            break;
        }
        let (a, b) = (w[0].max(lo), w[1].min(hi));
        if a > b {
            continue;
        }
        let near = if x < a {
            a - x
        } else if x > b {
            x - b
        } else {
            0.0
        };
        candidates.push((z_top + (rho * rho - near * near).max(0.0).sqrt(), a, b));
    }
    candidates.sort_by(|p, q| q.0.total_cmp(&p.0));
    let mut best = (f64::NEG_INFINITY, x);
    for (bound, a, b) in candidates {
        if bound <= best.0 {
            break;
        }
        let (h, u) = piece_max(profile, rho, x, a, b);
        if h > best.0 {
            best = (h, u);
        }
    }
    best
}

/// φ and φ′ at u for a nose centred at x.
fn phi(profile: &dyn Profile, rho: f64, x: f64, u: f64) -> (f64, f64, f64) {
    let p = profile.point(u);
    let d = u - x;
    let s = (rho * rho - d * d).max(0.0).sqrt();
    let dphi = if s > 0.0 {
        p.dz - d / s
    } else if d > 0.0 {
        f64::NEG_INFINITY
    } else {
        f64::INFINITY
    };
    (p.z + s, dphi, p.d2z - rho * rho / (s * s * s))
}

/// The highest φ(u) = z(u) + sqrt(ρ² − (u − x)²) over [a, b] and its u,
/// where φ is unimodal there (a smooth piece with ρ below its concave
/// radius, or one with convex corners only): an end, or the root of φ′ by
/// Newton's method kept inside a shrinking bracket.
pub fn piece_max(profile: &dyn Profile, rho: f64, x: f64, a: f64, b: f64) -> (f64, f64) {
    // A corner is located to 1e-13 mm, possibly just across it: the ends
    // are read 1e-10 mm inside the piece, on the piece's own side.
    let inset = (1e-10f64).min(0.25 * (b - a));
    let (a, b) = (a + inset, b - inset);
    let (fa, da, _) = phi(profile, rho, x, a);
    if da <= 0.0 {
        return (fa, a);
    }
    let (fb, db, _) = phi(profile, rho, x, b);
    if db >= 0.0 {
        return (fb, b);
    }
    // φ′(a) > 0 > φ′(b): bracketed root. Start where the normal at x
    // would put the contact (u = x + ρ z′/sqrt(1 + z′²), to first order).
    let (mut lo, mut hi) = (a, b);
    let mut u = {
        let s = profile.point(x.clamp(a, b)).dz;
        (x + rho * s / (1.0 + s * s).sqrt()).clamp(a, b)
    };
    let mut f = f64::NAN;
    for _ in 0..100 {
        let (fu, d, dd) = phi(profile, rho, x, u);
        f = fu;
        if d > 0.0 {
            lo = u;
        } else {
            hi = u;
        }
        let mut next = u - d / dd;
        let inside = next > lo && next < hi;
        if !inside {
            next = 0.5 * (lo + hi);
        }
        // A step of 1e-9 mm in u moves φ by ~φ″·1e-18: the height at u is
        // exact to far below a picometre; stop without another evaluation.
        if (next - u).abs() <= 1e-9 || hi - lo <= 1e-14 {
            break;
        }
        u = next;
    }
    (f, u)
}

/// The surface the nose leaves at u after passing every centre x in
/// [u − ρ, u + ρ] at its exact height: the lowest of the nose's lower arcs,
/// found on a scan refined by golden-section search.
pub fn cut_height(profile: &dyn Profile, pieces: &Pieces, rho: f64, u: f64) -> f64 {
    let (a, b) = (
        pieces.bounds[0].max(u - rho),
        pieces.bounds[pieces.bounds.len() - 1].min(u + rho),
    );
    let arc = |x: f64| {
        let (h, _) = centre_height(profile, pieces, rho, x);
        let d = u - x;
        h - (rho * rho - d * d).max(0.0).sqrt()
    };
    const N: usize = 256;
    let mut best = (f64::INFINITY, u);
    for i in 0..=N {
        let x = a + (b - a) * i as f64 / N as f64;
        let v = arc(x);
        if v < best.0 {
            best = (v, x);
        }
    }
    let step = (b - a) / N as f64;
    let (mut lo, mut hi) = ((best.1 - step).max(a), (best.1 + step).min(b));
    let g = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..80 {
        let (m1, m2) = (hi - g * (hi - lo), lo + g * (hi - lo));
        if arc(m1) < arc(m2) {
            hi = m2;
        } else {
            lo = m1;
        }
    }
    best.0.min(arc(0.5 * (lo + hi)))
}

/// Lei et al.'s sequential search: the nose centre descends from `start`
/// above the profile in steps of `step` until it comes within ρ of one of
/// the discretised profile points; the height where it stops.
pub fn sequential_search(points: &[(f64, f64)], rho: f64, x: f64, start: f64, step: f64) -> f64 {
    let window = points_near(points, x, rho);
    let mut h = start;
    // Bounded: the descent never passes the lowest point of the window.
    let floor = window.iter().map(|p| p.1).fold(f64::INFINITY, f64::min) - rho;
    while h > floor && min_distance(window, x, h) > rho {
        h -= step;
    }
    h
}

/// Lei et al.'s binary search: the lowest nose-centre height at x whose
/// nose clears every one of `points` (the discretised profile, sorted by
/// u: the whole profile as in the paper, or `points_near` x), bracketed
/// between a height that gouges and one that clears and halved until the
/// bracket is below `tolerance`.
pub fn binary_search(points: &[(f64, f64)], rho: f64, x: f64, tolerance: f64) -> f64 {
    let window = points;
    let high = window.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max);
    // The point nearest below the centre puts it at least ρ above itself;
    // at `high + ρ` the nose clears every point.
    let below = window
        .iter()
        .min_by(|a, b| (a.0 - x).abs().total_cmp(&(b.0 - x).abs()))
        .map_or(high, |p| p.1);
    let (mut gouges, mut clears) = (below + rho - tolerance, high + rho);
    while clears - gouges > tolerance {
        let m = 0.5 * (gouges + clears);
        if min_distance(window, x, m) < rho {
            gouges = m;
        } else {
            clears = m;
        }
    }
    clears
}

/// The discretised points within ρ of x in u (points sorted by u): the
/// only ones a nose centred at x can touch.
pub fn points_near(points: &[(f64, f64)], x: f64, rho: f64) -> &[(f64, f64)] {
    let start = points.partition_point(|p| p.0 < x - rho);
    let end = points.partition_point(|p| p.0 <= x + rho);
    &points[start..end]
}

fn min_distance(points: &[(f64, f64)], x: f64, h: f64) -> f64 {
    points
        .iter()
        .map(|&(u, z)| ((u - x) * (u - x) + (z - h) * (z - h)).sqrt())
        .fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::ProfilePoint;

    /// Convex circular arcs of radius R, width w, separated by flat seams
    /// of width s at z = 0 (Lei et al. 2021's cylinder array profile).
    struct Arcs {
        r: f64,
        w: f64,
        s: f64,
    }

    impl Profile for Arcs {
        fn point(&self, u: f64) -> ProfilePoint {
            let p = self.w + self.s;
            let c = (u / p).floor() * p + 0.5 * p;
            let d = u - c;
            if d.abs() > 0.5 * self.w {
                return ProfilePoint {
                    z: 0.0,
                    dz: 0.0,
                    d2z: 0.0,
                };
            }
            let rim = (self.r * self.r - 0.25 * self.w * self.w).sqrt();
            let q = (self.r * self.r - d * d).sqrt();
            ProfilePoint {
                z: q - rim,
                dz: -d / q,
                d2z: -self.r * self.r / (q * q * q),
            }
        }
    }

    fn lei() -> Arcs {
        Arcs {
            r: 0.788,
            w: 0.534,
            s: 0.02,
        }
    }

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
}
