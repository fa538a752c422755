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
//!
//! A measured edge (`machine::edge`) replaces sqrt(ρ² − d²) by its own
//! depth L(d) below the centre; `edged_max` finds that envelope's height
//! from the circle's contact, for every strategy that places a nose by it.

use crate::machine::edge::Nose;
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
mod tests;

/// The nose-centre height over `profile` at `x` with the measured edge of
/// `nose`, from the circle's contact `u0`: the greatest of w(u) = z(u) +
/// L(u − x) (L the edge's depth below its centre at that offset,
/// `Nose::lift`) found by Newton's method from the circle's contact, each
/// step kept only where it raises w; and the contact's u. On a smooth
/// section that is the edge's contact (w′ = 0); at a corner of the
/// profile the circle's contact is the corner, where the edge touches
/// too, and w there is the edge's depth at it. `None` where the edge does
/// not reach `u0` or the profile is undefined there.
pub fn edged_max(profile: &dyn Profile, nose: &Nose, x: f64, u0: f64) -> Option<(f64, f64)> {
    let rho = nose.radius;
    let at = |u: f64| {
        let p = profile.point(u);
        let (l, dl) = nose.lift(u - x)?;
        let w = p.z + l;
        w.is_finite().then_some((w, p.dz + dl, p.d2z))
    };
    // Where the circle touched: its height there with the edge.
    let (mut best_w, mut slope, mut curve) = at(u0)?;
    let mut best_u = u0;
    for _ in 0..6 {
        let off = best_u - x;
        let root = (rho * rho - off * off).max(1e-30).sqrt();
        // w″ with the circle's L″ (the edge's differs by δ″, far below
        // R's): negative where the section is smooth.
        let second = curve - rho * rho / (root * root * root);
        // Not negative (or not a number): a corner, where the circle's
        // contact stands.
        if second.is_nan() || second >= 0.0 {
            break;
        }
        let step = -slope / second;
        let next = best_u + step;
        let Some((w, s, k)) = at(next) else { break };
        if w < best_w {
            break;
        }
        (best_w, best_u, slope, curve) = (w, next, s, k);
        if step.abs() <= 1e-10 {
            break;
        }
    }
    Some((best_w, best_u))
}
