//! Cut simulation of profiles: the surface a lathe or grinder program
//! leaves, from the moves the program actually commands (after
//! optimisation, with every coordinate rounded to the machine's
//! resolution as the writer prints it), compared with the design.
//!
//! The tool is a round nose (or a wheel's section) of radius ρ whose
//! centre follows the moves; the material is on the −Z side, so the cut
//! surface is the lower envelope of the disc swept along every cutting
//! move. The envelope is exact: a disc swept along a straight move is
//! bounded below by its end discs and the move offset by ρ; along an arc,
//! by its end discs and the arc offset by ±ρ along its normal. A nose
//! whose edge was measured (`machine::edge`, ρ(θ) = R + δ(θ)) is swept
//! the same way, each offset by the edge point that touches the move's
//! tangent instead of ρ along its normal (`program_cut_by`).
//!
//! Arcs as the controller cuts them. A printed arc's end is rarely at
//! exactly its start radius from the printed centre (every coordinate is
//! rounded to the resolution). LinuxCNC does not cut a circle at the start
//! radius and jump: posemath's `pmCircleInit` takes the start radius and
//! `spiral` = end radius − start radius, and `pmCirclePoint` puts the
//! point at angle θ of the arc's sweep Θ at radius r₀ + spiral · θ / Θ — a
//! spiral that ends exactly on the printed end point. The simulation cuts
//! every arc so (Fanuc's manuals describe the same linear blend, "spiral
//! interpolation", for radii that differ within parameter 3410; the other
//! controllers are taken to do likewise). `program_cut` takes the moves
//! from the program's text as the reader executes them (`reader::
//! read_moves`); `profile_cut` from the planned move stream, as printed.

use super::figures::ErrorStats;
use crate::machine::edge::Nose;
use crate::moves::{Move, Plane};
use crate::post::format::decimals_for;
use crate::reader::{Executed, Path};
use std::f64::consts::PI;

/// What a profile program cuts, against the design.
#[derive(Clone, Debug, PartialEq)]
pub struct ProfileCut {
    /// Radii (mm) where the cut was sampled, and the error there: the cut
    /// surface's height minus the design's (mm; positive where material is
    /// left, negative where the cut went below the design).
    pub samples: Vec<(f64, f64)>,
    /// Peak to valley (largest minus least) and RMS about the mean of
    /// the error (mm; 0 if no radius was cut).
    pub pv: f64,
    pub rms: f64,
    /// The mean error (mm; piston: a uniform datum shift), NaN if no
    /// radius was cut.
    pub mean: f64,
    /// The error of the largest magnitude (mm, sign kept) and where; NaN
    /// if no radius was cut.
    pub largest_deviation: (f64, f64),
    /// The area (mm²) of the surface of revolution the radii sampled
    /// stand for (each 2π|r| times the spacing), the part of it at radii
    /// the cut does not reach, and the first such radius, if any.
    pub area: f64,
    pub uncut_area: f64,
    pub uncut_at: Option<f64>,
    /// The most material left above the design (mm, ≥ 0) and where.
    pub max_residual: (f64, f64),
    /// The deepest cut below the design (mm, ≥ 0) and where.
    pub max_gouge: (f64, f64),
}

/// One cutting move of the nose centre in the X–Z plane.
#[derive(Clone, Copy, Debug)]
enum Piece {
    Line {
        a: (f64, f64),
        b: (f64, f64),
    },
    /// Centre, radius at the start and at the end (blended linearly in
    /// the angle), and the arc's start angle and signed sweep, angles
    /// measured from +Z towards +X (the G18 sense).
    Arc {
        o: (f64, f64),
        r: f64,
        r_end: f64,
        start: f64,
        sweep: f64,
        a: (f64, f64),
        b: (f64, f64),
    },
}

/// Rounds `v` (mm) as a writer with `resolution` prints it.
pub fn as_printed(v: f64, resolution: f64) -> f64 {
    Printed::new(resolution).round(v)
}

/// `as_printed` for one resolution, its decimals and their scale worked
/// out once: for a stream of millions of coordinates (the same values,
/// bit for bit, as `as_printed`).
#[derive(Clone, Copy, Debug)]
pub struct Printed {
    units: crate::post::format::Decimals,
    /// 10^decimals.
    scale: f64,
}

impl Printed {
    pub fn new(resolution: f64) -> Printed {
        let d = decimals_for(resolution);
        Printed {
            units: crate::post::format::Decimals::new(d),
            scale: 10f64.powi(d as i32),
        }
    }

    /// `v` (mm) as printed.
    #[inline]
    pub fn round(&self, v: f64) -> f64 {
        match self.units.units(v) {
            Some(n) => n as f64 / self.scale,
            None => v,
        }
    }
}

/// The cutting moves of a lathe stream (X, Z; arcs in G18) as printed.
fn pieces(stream: &[Move], resolution: f64) -> Vec<Piece> {
    let printed = Printed::new(resolution);
    let p = |v: f64| printed.round(v);
    let mut at = (f64::NAN, f64::NAN);
    let mut out = Vec::new();
    for m in stream {
        let (to, arc) = match *m {
            Move::Rapid(to) => (to, None),
            Move::Linear { to, .. } => (to, Some(None)),
            Move::Arc {
                to,
                centre,
                plane: Plane::Zx,
                ccw,
                ..
            } => (to, Some(Some((centre, ccw)))),
            _ => continue,
        };
        let next = (
            if to.x.is_nan() { at.0 } else { p(to.x) },
            if to.z.is_nan() { at.1 } else { p(to.z) },
        );
        let known = !(at.0.is_nan() || at.1.is_nan());
        match arc {
            Some(None) if known => out.push(Piece::Line { a: at, b: next }),
            Some(Some((c, ccw))) if known => {
                let o = (p(c.x), p(c.z));
                let angle = |q: (f64, f64)| (q.0 - o.0).atan2(q.1 - o.1);
                let (a0, a1) = (angle(at), angle(next));
                let sweep = if ccw {
                    (a1 - a0).rem_euclid(2.0 * PI)
                } else {
                    -(a0 - a1).rem_euclid(2.0 * PI)
                };
                out.push(Piece::Arc {
                    o,
                    r: (at.0 - o.0).hypot(at.1 - o.1),
                    r_end: (next.0 - o.0).hypot(next.1 - o.1),
                    start: a0,
                    sweep,
                    a: at,
                    b: next,
                });
            }
            _ => {}
        }
        at = next;
    }
    out
}

/// The nose centre's path along the cutting moves of a lathe `stream`, as
/// printed (coordinates rounded to `resolution`): one polyline of (X, Z)
/// (mm) per run of cutting moves, an arc drawn through points at most
/// 1° of its sweep apart. For plots.
pub fn centre_path(stream: &[Move], resolution: f64) -> Vec<Vec<(f64, f64)>> {
    let mut runs: Vec<Vec<(f64, f64)>> = Vec::new();
    for piece in pieces(stream, resolution) {
        let (a, b) = match piece {
            Piece::Line { a, b } | Piece::Arc { a, b, .. } => (a, b),
        };
        let continues = runs.last().and_then(|r| r.last()) == Some(&a);
        if !continues {
            runs.push(vec![a]);
        }
        let run = runs.last_mut().expect("pushed");
        if let Piece::Arc {
            o,
            r,
            r_end,
            start,
            sweep,
            ..
        } = piece
        {
            let steps = (sweep.abs().to_degrees().ceil() as usize).max(1);
            for k in 1..steps {
                let f = k as f64 / steps as f64;
                let (ang, rr) = (start + sweep * f, r + (r_end - r) * f);
                run.push((o.0 + rr * ang.sin(), o.1 + rr * ang.cos()));
            }
        }
        run.push(b);
    }
    runs
}

impl Piece {
    /// The radii the nose swept along the piece reaches (`rho` its
    /// farthest reach from its centre).
    fn reach(&self, rho: f64) -> (f64, f64) {
        match *self {
            Piece::Line { a, b } => (a.0.min(b.0) - rho, a.0.max(b.0) + rho),
            Piece::Arc { o, r, r_end, .. } => {
                let r = r.max(r_end);
                (o.0 - r - rho, o.0 + r + rho)
            }
        }
    }

    /// The lowest point at `x` of the nose swept along the piece, if the
    /// swept region reaches `x`. A measured edge is convex (its deviation
    /// is a small share of R), so the region's lower boundary is the
    /// nose at both ends and the piece moved by the edge point that
    /// touches a line along the piece (`Nose::support_point`).
    fn bottom(&self, nose: &Nose, x: f64) -> Option<f64> {
        let (a, b) = match *self {
            Piece::Line { a, b } | Piece::Arc { a, b, .. } => (a, b),
        };
        let mut low = nose.bottom(a, x);
        let mut see = |z: Option<f64>| {
            if let Some(z) = z {
                low = Some(low.map_or(z, |l: f64| l.min(z)));
            }
        };
        see(nose.bottom(b, x));
        match *self {
            Piece::Line { a, b } => {
                let (dx, dz) = (b.0 - a.0, b.1 - a.1);
                let len = dx.hypot(dz);
                if len > 0.0 && dx != 0.0 {
                    // The normal pointing down (−Z).
                    let (nx, nz) = if dx > 0.0 {
                        (dz / len, -dx / len)
                    } else {
                        (-dz / len, dx / len)
                    };
                    let (sx, sz) = nose.support_point((nx, nz));
                    let (a2, b2) = ((a.0 + sx, a.1 + sz), (b.0 + sx, b.1 + sz));
                    let t = (x - a2.0) / (b2.0 - a2.0);
                    if (0.0..=1.0).contains(&t) {
                        see(Some(a2.1 + t * (b2.1 - a2.1)));
                    }
                }
            }
            Piece::Arc {
                o,
                r,
                r_end,
                start,
                sweep,
                ..
            } => {
                for side in [1.0, -1.0] {
                    see(match nose.edge {
                        None => {
                            spiral_offset_at(o, (r, r_end), (start, sweep), side * nose.radius, x)
                        }
                        Some(_) => edge_offset_at(o, (r, r_end), (start, sweep), side, nose, x),
                    });
                }
            }
        }
        low
    }
}

/// The offset by `off` (mm, + outward) along the normal of the arc about
/// `o` from radius `r0` to `r1` (linear in the angle), from angle `start`
/// through the signed `sweep`: its height where it crosses abscissa `x`,
/// the lowest of the crossings within the sweep. The crossings of the
/// offset circle at the mean radius start Newton's method on the exact
/// offset point p(θ) = c(θ) + off · n(θ), c(θ) = o + r(θ) (sin θ, cos θ),
/// n the unit normal (r u − r′ t) / √(r² + r′²).
fn spiral_offset_at(
    o: (f64, f64),
    (r0, r1): (f64, f64),
    (start, sweep): (f64, f64),
    off: f64,
    x: f64,
) -> Option<f64> {
    let k = if sweep != 0.0 { (r1 - r0) / sweep } else { 0.0 };
    let rr = 0.5 * (r0 + r1) + off;
    if rr <= 0.0 {
        return None;
    }
    let s = (x - o.0) / rr;
    if s.abs() > 1.0 {
        return None;
    }
    // The angle travelled from the start, in the sweep's direction.
    let travelled = |ang: f64| {
        if sweep >= 0.0 {
            (ang - start).rem_euclid(2.0 * PI)
        } else {
            (start - ang).rem_euclid(2.0 * PI)
        }
    };
    let mut low: Option<f64> = None;
    let base = s.asin();
    for guess in [base, PI - base] {
        let t0 = travelled(guess);
        // θ unwrapped from the start, so r(θ) is the blend's.
        let mut theta = start + t0 * sweep.signum();
        let point = |theta: f64| {
            let r = r0 + k * (theta - start);
            let h = r.hypot(k);
            let (sn, cs) = theta.sin_cos();
            let px = o.0 + r * sn + off * (r * sn - k * cs) / h;
            let pz = o.1 + r * cs + off * (r * cs + k * sn) / h;
            let slope = k * sn + r * cs + off * (2.0 * k * sn + r * cs) / h;
            (px, pz, slope)
        };
        if k != 0.0 {
            for _ in 0..8 {
                let (px, _, slope) = point(theta);
                let step = (px - x) / slope;
                if !step.is_finite() || step.abs() > 1e-3 {
                    break;
                }
                theta -= step;
                if step.abs() < 1e-15 {
                    break;
                }
            }
        }
        let t = (theta - start) * sweep.signum();
        if !(-1e-12..=sweep.abs() + 1e-12).contains(&t) {
            continue;
        }
        let (px, pz, _) = point(theta);
        if (px - x).abs() > 1e-9 {
            continue;
        }
        low = Some(low.map_or(pz, |l| l.min(pz)));
    }
    low
}

/// The envelope of a measured nose swept along the arc of
/// `spiral_offset_at` on its outer (`side` +1) or inner (−1) side: the
/// arc's point moved by the edge point that touches the arc's tangent,
/// e(θ) = c(θ) + s(±n(θ)), at abscissa `x`; the lowest of its crossings
/// within the sweep. Newton on θ (its slope by central differences) from
/// the crossings of the offset circle at the mean radius.
fn edge_offset_at(
    o: (f64, f64),
    (r0, r1): (f64, f64),
    (start, sweep): (f64, f64),
    side: f64,
    nose: &Nose,
    x: f64,
) -> Option<f64> {
    let k = if sweep != 0.0 { (r1 - r0) / sweep } else { 0.0 };
    let rr = 0.5 * (r0 + r1) + side * nose.radius;
    if rr <= 0.0 {
        return None;
    }
    let s = (x - o.0) / rr;
    if s.abs() > 1.0 + 1e-3 {
        return None;
    }
    let travelled = |ang: f64| {
        if sweep >= 0.0 {
            (ang - start).rem_euclid(2.0 * PI)
        } else {
            (start - ang).rem_euclid(2.0 * PI)
        }
    };
    let point = |theta: f64| {
        let r = r0 + k * (theta - start);
        let h = r.hypot(k);
        let (sn, cs) = theta.sin_cos();
        let n = (side * (r * sn - k * cs) / h, side * (r * cs + k * sn) / h);
        let (ex, ez) = nose.support_point(n);
        (o.0 + r * sn + ex, o.1 + r * cs + ez)
    };
    let mut low: Option<f64> = None;
    let base = s.clamp(-1.0, 1.0).asin();
    for guess in [base, PI - base] {
        let mut theta = start + travelled(guess) * sweep.signum();
        for _ in 0..20 {
            let d = 1e-7;
            let slope = (point(theta + d).0 - point(theta - d).0) / (2.0 * d);
            let step = (point(theta).0 - x) / slope;
            if !step.is_finite() || step.abs() > 0.1 {
                break;
            }
            theta -= step;
            if step.abs() < 1e-14 {
                break;
            }
        }
        let t = (theta - start) * sweep.signum();
        if !(-1e-12..=sweep.abs() + 1e-12).contains(&t) {
            continue;
        }
        let (px, pz) = point(theta);
        if (px - x).abs() > 1e-9 {
            continue;
        }
        low = Some(low.map_or(pz, |l| l.min(pz)));
    }
    low
}

/// Simulates the cut of a lathe `stream` (nose radius `rho`, coordinates
/// rounded to `resolution`) on `samples` radii evenly over `from..=to`
/// and compares it with `design` (the profile's height at a radius).
/// Radii the cut does not reach are left out.
pub fn profile_cut(
    stream: &[Move],
    rho: f64,
    resolution: f64,
    design: &dyn Fn(f64) -> f64,
    range: (f64, f64),
    samples: usize,
) -> ProfileCut {
    cut_of(
        &pieces(stream, resolution),
        &Nose::circle(rho),
        design,
        range,
        samples,
    )
}

/// Simulates the cut of a lathe program from the moves its controller
/// makes (`reader::read_moves`: X, Z in machine coordinates, arcs in
/// G18 blended from their start radius to their end radius), as
/// `profile_cut` does: the error of the program as written.
pub fn program_cut(
    moves: &[Executed],
    rho: f64,
    design: &dyn Fn(f64) -> f64,
    range: (f64, f64),
    samples: usize,
) -> ProfileCut {
    program_cut_by(moves, &Nose::circle(rho), design, range, samples)
}

/// `program_cut` by a `nose` whose edge may be measured (the real tool's
/// edge, swept as it is).
pub fn program_cut_by(
    moves: &[Executed],
    nose: &Nose,
    design: &dyn Fn(f64) -> f64,
    range: (f64, f64),
    samples: usize,
) -> ProfileCut {
    cut_of(&executed_pieces(moves), nose, design, range, samples)
}

/// `profile_cut` by a `nose` whose edge may be measured.
pub fn profile_cut_by(
    stream: &[Move],
    nose: &Nose,
    resolution: f64,
    design: &dyn Fn(f64) -> f64,
    range: (f64, f64),
    samples: usize,
) -> ProfileCut {
    cut_of(&pieces(stream, resolution), nose, design, range, samples)
}

/// The cutting moves among the executed `moves`: feed moves with X and Z
/// known at both ends, arcs in the ZX plane (G18).
fn executed_pieces(moves: &[Executed]) -> Vec<Piece> {
    let mut out = Vec::new();
    for m in moves {
        let (Some(ax), Some(az), Some(bx), Some(bz)) = (m.from[0], m.from[2], m.to[0], m.to[2])
        else {
            continue;
        };
        let (a, b) = ((ax, az), (bx, bz));
        match m.path {
            Path::Rapid => {}
            Path::Line => out.push(Piece::Line { a, b }),
            Path::Arc {
                plane: Plane::Zx,
                centre: (cz, cx),
                cw,
                turn,
            } => {
                let o = (cx, cz);
                out.push(Piece::Arc {
                    o,
                    r: (a.0 - o.0).hypot(a.1 - o.1),
                    r_end: (b.0 - o.0).hypot(b.1 - o.1),
                    start: (a.0 - o.0).atan2(a.1 - o.1),
                    sweep: if cw { -turn } else { turn },
                    a,
                    b,
                });
            }
            Path::Arc { .. } => {}
        }
    }
    out
}

/// The cut of `pieces` (see `profile_cut`).
fn cut_of(
    pieces: &[Piece],
    nose: &Nose,
    design: &dyn Fn(f64) -> f64,
    (from, to): (f64, f64),
    samples: usize,
) -> ProfileCut {
    let n = samples.max(2);
    // Each piece listed in the bins of radii its swept disc can reach.
    let bins = 1024usize;
    let width = (to - from) / bins as f64;
    let bin = |x: f64| (((x - from) / width).floor().max(0.0) as usize).min(bins - 1);
    let mut in_bin: Vec<Vec<usize>> = vec![Vec::new(); bins];
    for (i, p) in pieces.iter().enumerate() {
        let (lo, hi) = p.reach(nose.reach());
        if hi < from || lo > to || !(lo.is_finite() && hi.is_finite()) {
            continue;
        }
        for b in &mut in_bin[bin(lo)..=bin(hi)] {
            b.push(i);
        }
    }
    let mut out = Vec::with_capacity(n);
    let step = (to - from).abs() / (n - 1) as f64;
    let (mut area, mut uncut_area, mut uncut_at) = (0.0, 0.0, None);
    for k in 0..n {
        let x = from + (to - from) * k as f64 / (n - 1) as f64;
        let cut = in_bin[bin(x)]
            .iter()
            .filter_map(|&i| pieces[i].bottom(nose, x))
            .fold(f64::INFINITY, f64::min);
        let ring = 2.0 * PI * x.abs() * step;
        area += ring;
        if cut.is_finite() {
            out.push((x, cut - design(x)));
        } else {
            uncut_area += ring;
            uncut_at.get_or_insert(x);
        }
    }
    let mut stats = ErrorStats::<f64>::new();
    for &(x, e) in &out {
        stats.add(e, x);
    }
    let f = stats.figures();
    let (pv, rms, mean) = f.map_or((0.0, 0.0, f64::NAN), |f| (f.pv, f.rms, f.mean));
    let nowhere = (0.0, f64::NAN);
    ProfileCut {
        pv,
        rms,
        mean,
        largest_deviation: f.map_or((f64::NAN, f64::NAN), |f| f.largest_deviation),
        area,
        uncut_area,
        uncut_at,
        max_residual: f.map_or(nowhere, |f| f.max_residual),
        max_gouge: f.map_or(nowhere, |f| f.max_gouge),
        samples: out,
    }
}

#[cfg(test)]
mod tests;
