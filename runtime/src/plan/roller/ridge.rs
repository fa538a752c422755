//! The nose centre over a ridge of the section. Where two smooth pieces
//! of an axial section meet in a convex corner (neighbouring dimples of a
//! grid, the deeper cut winning), φ(u) = z(u) + sqrt(ρ² − (u − x)²) can
//! peak at the corner itself, φ′ jumping there from + to −: Newton's
//! method bounces across it and bisection takes some thirty kernel calls
//! to close in. Here the corner is put where the two pieces' second-order
//! Taylor models, one taken at each end of the bracket, meet (the circle
//! is the same on both sides and drops out), and the bracket is closed on
//! that estimate from both sides at once.

use crate::surface::Profile;

/// φ, φ′ and φ″ at one u of the nose window, with the section's own
/// height, slope and curvature there.
#[derive(Clone, Copy, Debug)]
pub struct Probe {
    pub u: f64,
    pub z: f64,
    pub dz: f64,
    pub d2z: f64,
    pub phi: f64,
    pub dphi: f64,
    pub ddphi: f64,
}

/// The section probed at u for a nose centred at x (ρ the nose radius).
/// Outside the window (|u − x| ≥ ρ) φ′ and φ″ are NaN.
pub fn probe(section: &dyn Profile, rho: f64, x: f64, u: f64) -> Probe {
    let p = section.point(u);
    let d = u - x;
    let s2 = rho * rho - d * d;
    let root = if s2 > 0.0 { s2.sqrt() } else { f64::NAN };
    Probe {
        u,
        z: p.z,
        dz: p.dz,
        d2z: p.d2z,
        phi: p.z + root,
        dphi: p.dz - d / root,
        ddphi: p.d2z - rho * rho / (root * root * root),
    }
}

/// How narrow (mm) a bracket around a corner is closed before its higher
/// end is taken: φ there is below the corner's by at most the slope
/// across it times this, under a picometre for any slope below 45°·10³.
pub const CORNER_WIDTH: f64 = 1e-12;

/// A Newton step (mm) this short ends the search at a smooth maximum:
/// the same test as the plain Newton search.
const STEP: f64 = 1e-9;

/// Rounds of two probes each before giving up.
const ROUNDS: usize = 16;

/// The highest φ over [lo.u, hi.u] and its u, given φ′(lo) > 0 > φ′(hi)
/// and φ unimodal there: either a corner, closed in on to `CORNER_WIDTH`
/// and its higher end taken, or a smooth maximum, found where a probe's
/// Newton step is under 1e-9 mm. `None` if neither is reached in
/// `ROUNDS` rounds or a probe is not finite: the caller then searches
/// the window the slow way.
pub fn corner_max(
    section: &dyn Profile,
    rho: f64,
    x: f64,
    mut lo: Probe,
    mut hi: Probe,
) -> Option<(f64, f64)> {
    let mut previous: Option<f64> = None;
    let mut last_width = f64::INFINITY;
    for _ in 0..ROUNDS {
        let width = hi.u - lo.u;
        // A round that did not take the bracket below 0.7 of its width is
        // followed by a halving.
        let slow = width > 0.7 * last_width;
        last_width = width;
        if width <= CORNER_WIDTH {
            let top = if lo.phi >= hi.phi { lo } else { hi };
            return Some((top.phi, top.u));
        }
        let inside = |t: &f64| *t > lo.u && *t < hi.u;
        let probes = match meeting(&lo, &hi).filter(inside) {
            Some(t) => {
                // The estimate moved by |t − previous|: its own error is
                // taken to be no larger (the estimates converge faster
                // than linearly), so probes that far either side straddle
                // the corner.
                let spread = previous.map_or(width / 8.0, |p| (t - p).abs());
                let delta = spread.max(0.25 * CORNER_WIDTH);
                previous = Some(t);
                [Some(t - delta), Some(t + delta)]
            }
            None => {
                // No corner between the ends: Newton from the end nearer
                // the maximum (from an end of the window it crawls: the
                // circle's curvature there is unbounded), else halve.
                let near = if lo.dphi < -hi.dphi { lo } else { hi };
                let t = Some(near.u - near.dphi / near.ddphi)
                    .filter(|t| !slow && near.ddphi < 0.0 && inside(t))
                    .unwrap_or(0.5 * (lo.u + hi.u));
                previous = None;
                [Some(t), None]
            }
        };
        for u in probes.into_iter().flatten() {
            if u <= lo.u || u >= hi.u {
                continue;
            }
            let q = probe(section, rho, x, u);
            if !(q.phi.is_finite() && q.dphi.is_finite() && q.ddphi.is_finite()) {
                return None;
            }
            // Near the window's ends the circle's own curvature makes
            // every Newton step short: a smooth maximum has φ′ near 0 too.
            if q.ddphi < 0.0 && (q.dphi / q.ddphi).abs() <= STEP && q.dphi.abs() <= 1e-3 {
                return Some((q.phi, q.u));
            }
            if q.dphi > 0.0 {
                lo = q;
            } else {
                hi = q;
            }
        }
    }
    None
}

/// Where the quadratic models of the section at `lo` and at `hi` give the
/// same height: the linear root of their difference, refined by one
/// Newton step on the quadratic. `None` if the models do not cross, or
/// nearly coincide (both ends on one smooth piece).
fn meeting(lo: &Probe, hi: &Probe) -> Option<f64> {
    let w = hi.u - lo.u;
    // D(v) = z_lo(lo + v) − z_hi(lo + v) = c0 + c1 v + c2 v².
    let c0 = lo.z - hi.z + hi.dz * w - 0.5 * hi.d2z * w * w;
    let c1 = lo.dz - hi.dz + hi.d2z * w;
    let c2 = 0.5 * (lo.d2z - hi.d2z);
    // On one smooth piece the two models nearly agree: their slopes at lo
    // differ by far less than the slopes at the ends do.
    if c1.abs() <= 0.25 * (lo.dz - hi.dz).abs() {
        return None;
    }
    let v = -c0 / c1;
    let d = c0 + v * (c1 + v * c2);
    let slope = c1 + 2.0 * c2 * v;
    let v = if slope != 0.0 { v - d / slope } else { v };
    let t = lo.u + v;
    t.is_finite().then_some(t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::envelope;
    use crate::surface::ProfilePoint;

    /// Two circles of radius r (concave bowls, centres c apart) meeting
    /// in a ridge at 0, the lower winning: z = min of the two.
    struct TwoBowls {
        r: f64,
        c: f64,
    }

    impl Profile for TwoBowls {
        fn point(&self, u: f64) -> ProfilePoint {
            let centre = if u < 0.0 { -self.c } else { self.c };
            let d = u - centre;
            let q = (self.r * self.r - d * d).sqrt();
            ProfilePoint {
                z: self.r - q,
                dz: d / q,
                d2z: self.r * self.r / (q * q * q),
            }
        }
    }

    #[test]
    fn a_nose_on_a_ridge_rests_on_the_corner_or_beside_it() {
        let s = TwoBowls { r: 0.5, c: 0.05 };
        let rho = 0.074;
        let mut on_corner = 0;
        for i in -40..=40 {
            let x = f64::from(i) * 0.0005;
            let lo = probe(&s, rho, x, x - rho + 1e-10);
            let hi = probe(&s, rho, x, x + rho - 1e-10);
            let Some((h, u)) = corner_max(&s, rho, x, lo, hi) else {
                panic!("x {x}: no convergence")
            };
            // The reference: bracketed Newton and bisection over the
            // window, to 1e-9 mm in u.
            let (exact, at) = envelope::piece_max(&s, rho, x, x - rho, x + rho);
            assert!((u - at).abs() <= 2e-9, "x {x}: contact at {u}, not {at}");
            // Never below the reference, and above it only by what the
            // bisection's 1e-9 mm in u leaves on a slope under 1.
            assert!(
                h >= exact - 1e-13 && h <= exact + 2e-9,
                "x {x}: {h} vs {exact}"
            );
            if u.abs() <= CORNER_WIDTH {
                on_corner += 1;
                let top = s.point(0.0).z + (rho * rho - x * x).sqrt();
                assert!((h - top).abs() <= CORNER_WIDTH, "x {x}: {h} vs {top}");
            }
        }
        // The nose rests on the ridge while the bowls' slopes there
        // (± c / sqrt(r² − c²)) outdo the nose's: |x| < ρ c / r = 7.4 µm,
        // 29 of the centres.
        assert_eq!(on_corner, 29);
    }

    #[test]
    fn a_smooth_maximum_is_found_as_newton_finds_it() {
        // One bowl, the nose's contact on its flank (no corner in reach).
        let s = TwoBowls { r: 0.5, c: 0.05 };
        let rho = 0.02;
        let x = 0.08;
        let lo = probe(&s, rho, x, x - rho + 1e-10);
        let hi = probe(&s, rho, x, x + rho - 1e-10);
        let (h, _) = corner_max(&s, rho, x, lo, hi).expect("converges");
        // Over a concave circle of radius r the centre is on the circle
        // of radius r − ρ about the bowl's centre (0.05, 0.5).
        let d = x - 0.05;
        let exact = 0.5 - ((0.5 - rho) * (0.5 - rho) - d * d).sqrt();
        assert!((h - exact).abs() <= 1e-13, "{h} vs {exact}");
    }
}
