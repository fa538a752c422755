//! Cut simulation of profiles: the surface a lathe or grinder program
//! leaves, from the moves the program actually commands (after
//! optimisation, with every coordinate rounded to the machine's
//! resolution as the writer prints it), compared with the design.
//!
//! The tool is a round nose (or a wheel's section) of radius ρ whose
//! centre follows the moves; the material is on the −Z side, so the cut
//! surface is the lower envelope of the disc swept along every cutting
//! move. The envelope is exact: a disc swept along a straight move is
//! bounded below by its end discs and the move offset by ρ; along an arc
//! of radius R, by its end discs and the arcs of radius R ± ρ.

use super::figures::ErrorStats;
use crate::moves::{Move, Plane};
use crate::post::format::{decimals_for, fixed_units};
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
    /// Centre, radius, and the arc's start angle and signed sweep, angles
    /// measured from +Z towards +X (the G18 sense).
    Arc {
        o: (f64, f64),
        r: f64,
        start: f64,
        sweep: f64,
        a: (f64, f64),
        b: (f64, f64),
    },
}

/// Rounds `v` (mm) as a writer with `resolution` prints it.
pub fn as_printed(v: f64, resolution: f64) -> f64 {
    let d = decimals_for(resolution);
    match fixed_units(v, d) {
        Some(n) => n as f64 / 10f64.powi(d as i32),
        None => v,
    }
}

/// The cutting moves of a lathe stream (X, Z; arcs in G18) as printed.
fn pieces(stream: &[Move], resolution: f64) -> Vec<Piece> {
    let p = |v: f64| as_printed(v, resolution);
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
                let r = (at.0 - o.0).hypot(at.1 - o.1);
                out.push(Piece::Arc {
                    o,
                    r,
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
            o, r, start, sweep, ..
        } = piece
        {
            let steps = (sweep.abs().to_degrees().ceil() as usize).max(1);
            for k in 1..steps {
                let ang = start + sweep * k as f64 / steps as f64;
                run.push((o.0 + r * ang.sin(), o.1 + r * ang.cos()));
            }
        }
        run.push(b);
    }
    runs
}

/// The lowest point at abscissa `x` of a disc of radius `rho` centred at
/// `c`, if the disc reaches `x`.
fn disc_bottom(c: (f64, f64), rho: f64, x: f64) -> Option<f64> {
    let dx = x - c.0;
    (dx.abs() <= rho).then(|| c.1 - (rho * rho - dx * dx).sqrt())
}

impl Piece {
    /// The radii the disc swept along the piece reaches.
    fn reach(&self, rho: f64) -> (f64, f64) {
        match *self {
            Piece::Line { a, b } => (a.0.min(b.0) - rho, a.0.max(b.0) + rho),
            Piece::Arc { o, r, .. } => (o.0 - r - rho, o.0 + r + rho),
        }
    }

    /// The lowest point at `x` of the disc of radius `rho` swept along the
    /// piece, if the swept region reaches `x`.
    fn bottom(&self, rho: f64, x: f64) -> Option<f64> {
        let (a, b) = match *self {
            Piece::Line { a, b } | Piece::Arc { a, b, .. } => (a, b),
        };
        let mut low = disc_bottom(a, rho, x);
        let mut see = |z: Option<f64>| {
            if let Some(z) = z {
                low = Some(low.map_or(z, |l: f64| l.min(z)));
            }
        };
        see(disc_bottom(b, rho, x));
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
                    let (a2, b2) = (
                        (a.0 + rho * nx, a.1 + rho * nz),
                        (b.0 + rho * nx, b.1 + rho * nz),
                    );
                    let t = (x - a2.0) / (b2.0 - a2.0);
                    if (0.0..=1.0).contains(&t) {
                        see(Some(a2.1 + t * (b2.1 - a2.1)));
                    }
                }
            }
            Piece::Arc {
                o, r, start, sweep, ..
            } => {
                for rr in [r + rho, r - rho] {
                    if rr <= 0.0 {
                        continue;
                    }
                    let s = (x - o.0) / rr;
                    if s.abs() > 1.0 {
                        continue;
                    }
                    let base = s.asin();
                    for ang in [base, PI - base] {
                        // Within the arc's sweep from its start?
                        let mut t = ang - start;
                        if sweep >= 0.0 {
                            t = t.rem_euclid(2.0 * PI);
                            if t > sweep {
                                continue;
                            }
                        } else {
                            t = (-t).rem_euclid(2.0 * PI);
                            if t > -sweep {
                                continue;
                            }
                        }
                        see(Some(o.1 + rr * ang.cos()));
                    }
                }
            }
        }
        low
    }
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
    (from, to): (f64, f64),
    samples: usize,
) -> ProfileCut {
    let pieces = pieces(stream, resolution);
    let n = samples.max(2);
    // Each piece listed in the bins of radii its swept disc can reach.
    let bins = 1024usize;
    let width = (to - from) / bins as f64;
    let bin = |x: f64| (((x - from) / width).floor().max(0.0) as usize).min(bins - 1);
    let mut in_bin: Vec<Vec<usize>> = vec![Vec::new(); bins];
    for (i, p) in pieces.iter().enumerate() {
        let (lo, hi) = p.reach(rho);
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
            .filter_map(|&i| pieces[i].bottom(rho, x))
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
