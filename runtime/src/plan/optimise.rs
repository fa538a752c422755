//! Program optimisation on the move stream: runs of straight cutting moves
//! are replaced by fewer straight moves (points collinear within a
//! tolerance dropped) and by circular arcs (G2/G3) in the planes the
//! dialect can arc in. Every replacement is measured, not assumed: the new
//! line or arc stays within the fitting tolerance of the polyline it
//! replaces, both ways (every replaced point and every replaced chord is
//! within it, and the points run monotonically along the new geometry).
//!
//! The deviation budget of a path is stated once, as the strategy's
//! tolerance T, and shared: the planner's chords take `CHORD_SHARE` of it
//! (T/10), fitting `FIT_SHARE` (3T/20) and the controller's corner
//! blending (`G64 P`) `BLEND_SHARE` (T/4); the other half is left to the
//! machine (rounding to its resolution, its own following), so the
//! program as the machine runs it stays within T of the exact tool-centre
//! path. The simulated cut (`simulate.rs`) measures what the program, as
//! printed, leaves.

use crate::moves::{Feed, Move, Plane, Position};
use std::f64::consts::PI;

/// The planner's share of a path's tolerance (its chords' sag).
pub const CHORD_SHARE: f64 = 0.1;
/// The optimiser's share: how far a fitted line or arc may leave the
/// planned polyline.
pub const FIT_SHARE: f64 = 0.15;
/// The controller's share: the blending tolerance the program asks for.
pub const BLEND_SHARE: f64 = 0.25;
/// The chords' share where a path is written as planned, not optimised
/// (fast- and slow-tool-servo spirals): the planner's half of the budget
/// less the blending, so that here too the other half is left to the
/// machine (T/4: with 3T/4, seed 003's contacts were 2.6 nm RMS at 10 nm).
pub const UNOPTIMISED_CHORD_SHARE: f64 = 0.5 - BLEND_SHARE;

/// The smallest arc radius fitted (mm). LinuxCNC refuses arcs under
/// 0.00127 mm (its centre-arc radius tolerance) as zero-radius; a tool
/// centre turning that tightly (round a seam's corner) is left as lines.
pub const MIN_ARC_RADIUS: f64 = 0.01;

/// What optimisation did to a stream.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Summary {
    /// Moves before and after (one program block each).
    pub moves_before: usize,
    pub moves_after: usize,
    /// Arcs written, and straight moves that absorbed collinear points.
    pub arcs: usize,
    pub merged_lines: usize,
    /// The largest distance (mm) between a fitted line or arc and the
    /// polyline it replaced.
    pub max_deviation: f64,
    /// The tolerance the fits were held to (mm).
    pub tolerance: f64,
}

/// How far below the polyline (mm, towards −Z, into the material) a fit
/// held above it may pass: the rounding of its own arithmetic.
pub const ABOVE_SLACK: f64 = 1e-12;

/// Optimises `stream` with fits held to `tolerance` (mm), arcs only in
/// `arc_planes`. Rapids, spindle moves, moves with C, inverse-time moves
/// and feed changes are kept as they are and break runs.
pub fn optimise(stream: &[Move], tolerance: f64, arc_planes: &[Plane]) -> (Vec<Move>, Summary) {
    optimise_within(stream, tolerance, arc_planes, false)
}

/// `optimise`, and with `above` every fitted line or arc also kept on or
/// above the polyline it replaces (+Z, out of the material; within
/// `ABOVE_SLACK`): points placed clear of the material (`chords: clear`)
/// are not fitted back into it. Arcs in a plane without Z are then not
/// fitted.
pub fn optimise_within(
    stream: &[Move],
    tolerance: f64,
    arc_planes: &[Plane],
    above: bool,
) -> (Vec<Move>, Summary) {
    let mut out = Vec::with_capacity(stream.len());
    let mut summary = Summary {
        moves_before: stream.len(),
        tolerance,
        ..Summary::default()
    };
    let mut at = [f64::NAN; 4];
    let mut feed_in_force: Option<Feed> = None;
    let mut i = 0;
    while i < stream.len() {
        // A run: straight moves from a known point, on the same axes, at
        // the feed in force.
        let run_end = run_length(stream, i, &at, feed_in_force);
        if run_end - i >= 2 {
            let start = at;
            let points: Vec<[f64; 3]> = std::iter::once([start[0], start[1], start[2]])
                .chain(stream[i..run_end].iter().map(|m| {
                    let to = target(m).expect("a straight move");
                    [to.x, to.y, to.z]
                }))
                .collect();
            let feed = match stream[i] {
                Move::Linear { feed, .. } => feed.or(feed_in_force),
                _ => None,
            };
            if let Some(f) = feed {
                feed_in_force = Some(f);
            }
            let template = target(&stream[i]).expect("a straight move");
            let first_feed = match stream[i] {
                Move::Linear { feed, .. } => feed,
                _ => None,
            };
            // The turning planner gives every move its feed; keep its habit.
            let rest_feed = if every_move_has_feed(&stream[i..run_end]) {
                feed
            } else {
                None
            };
            fit_run(
                &points,
                template.c,
                (first_feed, rest_feed),
                arc_planes,
                Sides { tolerance, above },
                &mut out,
                &mut summary,
            );
            let last = points[points.len() - 1];
            at = [last[0], last[1], last[2], at[3]];
            i = run_end;
            continue;
        }
        let m = stream[i];
        if let Move::Linear { feed: Some(f), .. } | Move::Arc { feed: Some(f), .. } = m {
            feed_in_force = Some(f);
        }
        if let Some(to) = target(&m) {
            for (a, v) in at.iter_mut().zip(to.axes()) {
                if !v.is_nan() {
                    *a = v;
                }
            }
        }
        out.push(m);
        i += 1;
    }
    summary.moves_after = out.len();
    (out, summary)
}

/// Whether the moves of a run carry their feed on every move or only on
/// the first.
fn every_move_has_feed(run: &[Move]) -> bool {
    run.iter()
        .skip(1)
        .all(|m| matches!(m, Move::Linear { feed: Some(_), .. }))
}

fn target(m: &Move) -> Option<Position> {
    match *m {
        Move::Rapid(to) | Move::Linear { to, .. } | Move::Arc { to, .. } => Some(to),
        _ => None,
    }
}

/// The end (exclusive) of the run of straight moves starting at `i`.
fn run_length(stream: &[Move], i: usize, at: &[f64; 4], feed_in_force: Option<Feed>) -> usize {
    let Move::Linear { to, feed } = stream[i] else {
        return i;
    };
    if !to.c.is_nan() || matches!(feed.or(feed_in_force), None | Some(Feed::InverseTime(_))) {
        return i;
    }
    let present = [!to.x.is_nan(), !to.y.is_nan(), !to.z.is_nan()];
    // The run's start must be known on every axis it moves.
    if (0..3).any(|k| present[k] && at[k].is_nan()) || present.iter().filter(|p| **p).count() < 2 {
        return i;
    }
    let run_feed = feed.or(feed_in_force);
    let mut j = i + 1;
    while j < stream.len() {
        let Move::Linear { to, feed } = stream[j] else {
            break;
        };
        let same_axes = [!to.x.is_nan(), !to.y.is_nan(), !to.z.is_nan()] == present;
        if !same_axes || !to.c.is_nan() || feed.is_some_and(|f| Some(f) != run_feed) {
            break;
        }
        j += 1;
    }
    j
}

/// The tolerance a fit is held to, and whether it must also stay on or
/// above the polyline it replaces.
#[derive(Clone, Copy, Debug)]
struct Sides {
    tolerance: f64,
    above: bool,
}

/// Fits lines and arcs to the polyline `points` (X, Y, Z; NaN on axes the
/// run does not move; C held at `c`) and appends the moves that replace
/// it, the first with `feeds.0`, the others with `feeds.1`.
fn fit_run(
    points: &[[f64; 3]],
    c: f64,
    feeds: (Option<Feed>, Option<Feed>),
    arc_planes: &[Plane],
    sides: Sides,
    out: &mut Vec<Move>,
    summary: &mut Summary,
) {
    let tol = sides.tolerance;
    let above = sides.above;
    // The plane of the run: the axis off it does not change.
    let plane = [Plane::Zx, Plane::Xy, Plane::Yz].into_iter().find(|p| {
        let (a, b) = p.axes();
        let off = 3 - a - b;
        arc_planes.contains(p)
            && points
                .iter()
                .all(|q| !q[a].is_nan() && !q[b].is_nan() && same(q[off], points[0][off]))
    });
    let position = |q: [f64; 3]| Position {
        x: q[0],
        y: q[1],
        z: q[2],
        c,
    };
    let n = points.len() - 1;
    let mut i = 0;
    while i < n {
        let feed = if i == 0 { feeds.0 } else { feeds.1 };
        let line_to = longest(i, n, |j| {
            line_fits(&points[i..=j], tol) && (!above || line_above(&points[i..=j]))
        });
        let arc = plane.and_then(|p| {
            let j = longest(i, n, |j| {
                j >= i + 2 && arc_fit(&points[i..=j], p, tol, above).is_some()
            });
            (j >= i + 2 && j > line_to)
                .then(|| arc_fit(&points[i..=j], p, tol, above).map(|fit| (j, p, fit)))
                .flatten()
        });
        match arc {
            Some((j, plane, fit)) => {
                out.push(Move::Arc {
                    to: position(points[j]),
                    centre: position(fit.centre),
                    plane,
                    ccw: fit.ccw,
                    feed,
                });
                summary.arcs += 1;
                summary.max_deviation = summary.max_deviation.max(fit.deviation);
                i = j;
            }
            None => {
                let j = line_to;
                out.push(Move::Linear {
                    to: position(points[j]),
                    feed,
                });
                if j > i + 1 {
                    summary.merged_lines += 1;
                    let d = line_deviation(&points[i..=j]).unwrap_or(0.0);
                    summary.max_deviation = summary.max_deviation.max(d);
                }
                i = j;
            }
        }
    }
}

fn same(a: f64, b: f64) -> bool {
    (a.is_nan() && b.is_nan()) || (a - b).abs() <= 1e-12
}

/// The largest `j` in (i, n] for which `fits(j)` holds, searched by
/// doubling the span and then bisecting (`fits(i + 1)` is taken to hold).
fn longest(i: usize, n: usize, fits: impl Fn(usize) -> bool) -> usize {
    let mut good = i + 1;
    let mut step = 1;
    let mut bad = None;
    while good < n {
        let j = (i + 2 * step).min(n);
        if fits(j) {
            good = j;
            step *= 2;
        } else {
            bad = Some(j);
            break;
        }
    }
    let Some(mut bad) = bad else { return good };
    while bad - good > 1 {
        let mid = (good + bad) / 2;
        if fits(mid) {
            good = mid;
        } else {
            bad = mid;
        }
    }
    good
}

fn sub(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    let d = |k: usize| {
        let v = a[k] - b[k];
        if v.is_nan() { 0.0 } else { v }
    };
    [d(0), d(1), d(2)]
}

fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The largest distance of the polyline's inner points from the straight
/// line between its ends, or None if they do not run monotonically along
/// it.
fn line_deviation(pts: &[[f64; 3]]) -> Option<f64> {
    let (a, b) = (&pts[0], &pts[pts.len() - 1]);
    let ab = sub(b, a);
    let len2 = dot(&ab, &ab);
    if len2 == 0.0 {
        return None;
    }
    let mut last_t = 0.0;
    let mut worst: f64 = 0.0;
    for p in &pts[1..pts.len() - 1] {
        let ap = sub(p, a);
        let t = dot(&ap, &ab) / len2;
        if t < last_t || t > 1.0 {
            return None;
        }
        last_t = t;
        let d2 = (dot(&ap, &ap) - t * t * len2).max(0.0);
        worst = worst.max(d2.sqrt());
    }
    Some(worst)
}

fn line_fits(pts: &[[f64; 3]], tol: f64) -> bool {
    pts.len() <= 2 || line_deviation(pts).is_some_and(|d| d <= tol)
}

/// Whether the straight line between the polyline's ends is nowhere below
/// it: no inner point above the line by more than `ABOVE_SLACK` (the
/// polyline is straight between its points, so its points decide).
fn line_above(pts: &[[f64; 3]]) -> bool {
    let (a, b) = (&pts[0], &pts[pts.len() - 1]);
    let ab = sub(b, a);
    let len2 = dot(&ab, &ab);
    if len2 == 0.0 {
        return pts.len() <= 2;
    }
    pts[1..pts.len() - 1].iter().all(|p| {
        let ap = sub(p, a);
        let t = dot(&ap, &ab) / len2;
        // The point's rise above its foot on the line, along Z.
        let rise = if ap[2].is_nan() {
            0.0
        } else {
            ap[2] - t * ab[2]
        };
        rise <= ABOVE_SLACK
    })
}

/// A circle fitted to a run of points.
#[derive(Clone, Copy, Debug)]
struct ArcFit {
    /// Centre, with the off-plane axis copied from the points.
    centre: [f64; 3],
    ccw: bool,
    /// The largest distance between the arc and the polyline.
    deviation: f64,
}

/// The circle through the first, middle and last of `pts` in `plane`, if
/// every point and every chord between them lies within `tol` of it, the
/// points advance monotonically around it and it turns less than half a
/// revolution; with `above`, only if the arc is also nowhere below the
/// polyline (towards −Z, beyond `ABOVE_SLACK`), and never in a plane
/// without Z.
fn arc_fit(pts: &[[f64; 3]], plane: Plane, tol: f64, above: bool) -> Option<ArcFit> {
    let (ia, ib) = plane.axes();
    // Which of the plane's two axes is Z, if either.
    let up = match (ia, ib) {
        (2, _) => Some(0),
        (_, 2) => Some(1),
        _ => None,
    };
    if above && up.is_none() {
        return None;
    }
    let p2 = |q: &[f64; 3]| (q[ia], q[ib]);
    let (a, m, b) = (
        p2(&pts[0]),
        p2(&pts[pts.len() / 2]),
        p2(&pts[pts.len() - 1]),
    );
    // Circumcentre of a, m, b.
    let (bx, by) = (m.0 - a.0, m.1 - a.1);
    let (cx, cy) = (b.0 - a.0, b.1 - a.1);
    let d = 2.0 * (bx * cy - by * cx);
    let scale = (bx * bx + by * by).max(cx * cx + cy * cy);
    if d.abs() <= 1e-12 * scale {
        return None;
    }
    let ux = (cy * (bx * bx + by * by) - by * (cx * cx + cy * cy)) / d;
    let uy = (bx * (cx * cx + cy * cy) - cx * (bx * bx + by * by)) / d;
    let centre = (a.0 + ux, a.1 + uy);
    let r = (ux * ux + uy * uy).sqrt();
    if !r.is_finite() || !(MIN_ARC_RADIUS..=1e4).contains(&r) {
        return None;
    }
    let ccw = d > 0.0;
    let angle = |p: (f64, f64)| (p.1 - centre.1).atan2(p.0 - centre.0);
    let a0 = angle(a);
    // Angle travelled from the start in the arc's direction, in [0, 2π).
    let swept = |p: (f64, f64)| {
        let mut t = angle(p) - a0;
        if !ccw {
            t = -t;
        }
        t.rem_euclid(2.0 * PI)
    };
    let total = swept(b);
    if total >= PI - 1e-9 {
        return None;
    }
    let dist = |p: (f64, f64)| ((p.0 - centre.0).powi(2) + (p.1 - centre.1).powi(2)).sqrt();
    // With `above`: whether leaving the circle outwards is going up, at
    // the arc's middle (the arc turns less than half a revolution, and
    // one that stands upright there is not fitted).
    let outward_up = if above {
        let rise = match up {
            Some(0) => m.0 - centre.0,
            _ => m.1 - centre.1,
        };
        if rise == 0.0 {
            return None;
        }
        rise > 0.0
    } else {
        true
    };
    let mut last = 0.0;
    let mut worst: f64 = 0.0;
    for w in pts.windows(2) {
        let (p, q) = (p2(&w[0]), p2(&w[1]));
        let t = swept(q);
        if t < last || t > total + 1e-12 {
            return None;
        }
        last = t;
        // Distance from the centre along the chord p→q is convex: its
        // extremes are the ends and the foot of the perpendicular.
        let (dx, dy) = (q.0 - p.0, q.1 - p.1);
        let len2 = dx * dx + dy * dy;
        let mut dev = (dist(p) - r).abs().max((dist(q) - r).abs());
        // The chord's nearest approach to the centre, its radial offset.
        let mut nearest = (dist(p) - r).min(dist(q) - r);
        if len2 > 0.0 {
            let s = (((centre.0 - p.0) * dx + (centre.1 - p.1) * dy) / len2).clamp(0.0, 1.0);
            let foot = dist((p.0 + s * dx, p.1 + s * dy)) - r;
            dev = dev.max(foot.abs());
            nearest = nearest.min(foot);
        }
        if above {
            // The polyline above the arc: outside it where outward is up
            // (its points decide, the disc being convex), inside it where
            // outward is down (its chords' nearest approach decides).
            let below_by = if outward_up {
                (dist(p) - r).max(dist(q) - r)
            } else {
                -nearest
            };
            if below_by > ABOVE_SLACK {
                return None;
            }
        }
        worst = worst.max(dev);
        if worst > tol {
            return None;
        }
    }
    let mut c3 = pts[0];
    c3[ia] = centre.0;
    c3[ib] = centre.1;
    Some(ArcFit {
        centre: c3,
        ccw,
        deviation: worst,
    })
}

#[cfg(test)]
mod tests;
