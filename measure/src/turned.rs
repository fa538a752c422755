//! A turned part's set-up errors, read from its form error map: the
//! tool's X offset from the cone it leaves, its centre-height error from
//! the stub at the centre.
//!
//! A tool whose X zero is off by δx (it stands δx further from the
//! spindle axis than programmed) and whose tip is off the centre height
//! by h cuts, at commanded radius x, the design height f(x) at the radius
//! √((x + δx)² + h²). So the part's height at radius r is
//! z(r) = f(√(r² − h²) − δx), and inside the radius the tool never
//! reaches, ρ = √(δx² + h²) when it stops short (δx > 0), |h| otherwise,
//! a stub of uncut material stands. The form error z(r) − f(r) is, to
//! first order, −f′(r)·δx (a cone across the whole part) and
//! −f′(r)·h²/(2r), which on a conic is nearly a piston: the map holds h
//! in the stub's radius, not in the rest of the part.
//!
//! So: the error is averaged in rings about the registered centre; δx and
//! a piston are fitted to the rings outside the stub by Gauss–Newton on
//! f(r − δx) − f(r) (f and f′ from the surface's kernel along +x); the
//! stub is the run of rings from the centre whose error stands above that
//! fit by more than five times its RMS (and 1 nm); h follows from its
//! radius, its edge placed between the points on either side of it (a
//! map's points lie at many radii about a centre that is not a pixel's,
//! so far finer than a ring). h is a magnitude (a map does not tell above
//! from below centre).

use lensc_runtime::surface::ir::SurfaceFn;

/// What the fit found (mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SetUp {
    /// δx: the tool stands this much further from the axis than
    /// programmed (negative: it passes the centre). Correct by −δx.
    pub x_offset: f64,
    /// |h|: the tip's distance from the centre height.
    pub centre_height: f64,
    /// The stub's radius ρ (0: none seen).
    pub stub_radius: f64,
    /// The ring width (the stub's edge is then found between points).
    pub ring: f64,
    /// RMS of the rings outside the stub about the fitted cone (mm).
    pub residual_rms: f64,
    /// Rings used for the cone.
    pub rings: usize,
}

/// Fits δx and |h| to form errors `e` at radii `r` from the centre (mm),
/// in rings `ring` wide. `None` with fewer than four rings.
pub fn fit(f: &dyn SurfaceFn, r: &[f64], e: &[f64], ring: f64) -> Option<SetUp> {
    let rmax = r.iter().cloned().fold(0.0, f64::max);
    // Only the rings that hold points, in order out from the centre: as
    // many as the points at most, however narrow the ring (a map's 1 pm
    // pixels 10 mm out counted 1e10 rings, each allocated, `as usize`
    // unchecked: an abort). A ring's index saturates, NaN to 0.
    let mut sums: std::collections::BTreeMap<usize, (f64, f64, usize)> = Default::default();
    for (ri, ei) in r.iter().zip(e) {
        let sum = sums.entry((ri / ring) as usize).or_default();
        sum.0 += ri;
        sum.1 += ei;
        sum.2 += 1;
    }
    // (mean radius, mean error, count) of each ring that holds points
    let rings: Vec<(f64, f64, f64)> = sums
        .values()
        .map(|&(rs, es, cnt)| (rs / cnt as f64, es / cnt as f64, cnt as f64))
        .collect();
    let z = |x: f64| f.eval(x.abs(), 0.0);
    let model = |p: &[f64; 2], rr: f64| p[0] + z(rr - p[1])[0] - z(rr)[0];
    // The cone, outside a stub: first outside a tenth of the part, then
    // outside the stub found.
    let mut inner = 0.1 * rmax;
    let (mut p, mut rms, mut used) = ([0.0f64; 2], f64::NAN, 0);
    for _pass in 0..2 {
        for _ in 0..30 {
            let (mut a, mut g) = ([[0.0f64; 2]; 2], [0.0f64; 2]);
            let (mut ssr, mut wsum) = (0.0, 0.0);
            used = 0;
            for &(rr, ee, w) in rings.iter().filter(|q| q.0 > inner) {
                let j = [1.0, -z(rr - p[1])[1]];
                let res = ee - model(&p, rr);
                for m in 0..2 {
                    g[m] += w * j[m] * res;
                    for n in 0..2 {
                        a[m][n] += w * j[m] * j[n];
                    }
                }
                ssr += w * res * res;
                wsum += w;
                used += 1;
            }
            if used < 4 {
                return None;
            }
            rms = (ssr / wsum).sqrt();
            let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
            if det.abs() <= f64::MIN_POSITIVE {
                return None;
            }
            let d0 = (a[1][1] * g[0] - a[0][1] * g[1]) / det;
            let d1 = (a[0][0] * g[1] - a[1][0] * g[0]) / det;
            p[0] += d0;
            p[1] += d1;
            if d1.abs() < 1e-13 {
                break;
            }
        }
        // The stub: rings from the centre standing above the cone.
        let threshold = (5.0 * rms).max(1e-6);
        let stub = rings
            .iter()
            .take_while(|q| q.1 - model(&p, q.0) > threshold)
            .last()
            .map_or(0.0, |q| q.0);
        let stub = if stub > 0.0 {
            edge(r, e, stub + ring / 2.0, ring, &|rr| {
                model(&p, rr) + threshold
            })
        } else {
            0.0
        };
        inner = (2.0 * stub).max(2.0 * ring);
        if _pass == 1 || stub == 0.0 {
            let h2 = stub * stub - p[1].max(0.0).powi(2);
            return Some(SetUp {
                x_offset: p[1],
                centre_height: h2.max(0.0).sqrt(),
                stub_radius: stub,
                ring,
                residual_rms: rms,
                rings: used,
            });
        }
    }
    None
}

/// The stub's edge to the point, not the ring: among the points within two
/// rings of `rough`, the radius that best splits those standing above
/// `level(r)` (inside) from those that do not (outside), the fewest
/// points on the wrong side, halfway between the two points it falls
/// between. A map's points lie at many radii about a centre that is not
/// a pixel's, so the edge is found far finer than a ring (a pixel).
fn edge(r: &[f64], e: &[f64], rough: f64, ring: f64, level: &dyn Fn(f64) -> f64) -> f64 {
    let (lo, hi) = (rough - 2.0 * ring, rough + 2.0 * ring);
    let mut near: Vec<(f64, bool)> = r
        .iter()
        .zip(e)
        .filter(|(rr, _)| **rr > lo && **rr < hi)
        .map(|(rr, ee)| (*rr, *ee > level(*rr)))
        .collect();
    near.sort_by(|a, b| a.0.total_cmp(&b.0));
    // wrong(b): points outside the split that stand above, plus points
    // inside it that do not; the split b = 0 puts every point outside.
    let above_total = near.iter().filter(|q| q.1).count();
    let (mut best, mut best_wrong) = (0, above_total);
    let (mut inside_low, mut inside_high) = (0, 0);
    for (b, q) in near.iter().enumerate() {
        if q.1 {
            inside_high += 1;
        } else {
            inside_low += 1;
        }
        let wrong = inside_low + (above_total - inside_high);
        if wrong < best_wrong {
            (best, best_wrong) = (b + 1, wrong);
        }
    }
    if best == 0 || best == near.len() {
        return rough;
    }
    (near[best - 1].0 + near[best].0) / 2.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A turned part made with the exact expression (δx = +1 µm, h = 2
    /// µm, a 0.5 µm stub inside the tool's reach) on the test asphere:
    /// δx within 5 %, h within the ring width.
    #[test]
    fn recovers_x_offset_and_centre_height() {
        let f = crate::register::tests::asphere(0.0);
        let (dx, h): (f64, f64) = (1e-3, 2e-3);
        let reach = (dx * dx + h * h).sqrt();
        let (mut r, mut e) = (Vec::new(), Vec::new());
        for k in 1..=20000 {
            // denser near the centre
            let rr = 0.8 * (k as f64 / 20000.0).powi(2);
            let cut = if rr > reach {
                f.eval((rr * rr - h * h).sqrt() - dx, 0.0)[0]
            } else {
                f.eval(0.0, 0.0)[0] + 5e-4
            };
            r.push(rr);
            e.push(cut - f.eval(rr, 0.0)[0] + 3e-5);
        }
        let ring = 2e-5;
        let s = fit(&f, &r, &e, ring).expect("fits");
        assert!((s.x_offset - dx).abs() <= 0.05 * dx, "{s:?}");
        assert!((s.centre_height - h).abs() <= 2.0 * ring, "{s:?}");
    }

    /// A part passed by 1 µm in rings 0.5 µm wide (a coarse pixel): the stub's edge is found from the points, so h is
    /// still within 5 %, where the ring alone resolves it to a ring.
    #[test]
    fn centre_height_is_resolved_finer_than_a_ring() {
        let f = crate::register::tests::asphere(0.0);
        // h = 2.2 µm: its edge in the middle of a 0.5 µm ring.
        let (dx, h): (f64, f64) = (-1e-3, 2.2e-3);
        let (mut r, mut e) = (Vec::new(), Vec::new());
        for k in 1..=20000 {
            let rr = 0.8 * (k as f64 / 20000.0).powi(2);
            let cut = if rr > h {
                f.eval((rr * rr - h * h).sqrt() - dx, 0.0)[0]
            } else {
                f.eval(0.0, 0.0)[0] + 5e-4
            };
            r.push(rr);
            e.push(cut - f.eval(rr, 0.0)[0]);
        }
        let s = fit(&f, &r, &e, 5e-4).expect("fits");
        assert!((s.centre_height - h).abs() <= 0.05 * h, "{s:?}");
        assert!((s.x_offset - dx).abs() <= 0.05 * dx.abs(), "{s:?}");
    }

    /// Rings far narrower than the points' spread are counted by the
    /// points they hold, not allocated out to the farthest (issue #33: a
    /// map's 1 pm pixels 0.8 mm out asked for 8e8 rings in each of three
    /// vectors, 1e-15 mm for 8e14, an abort): the same fit as at a ring the
    /// points' own spacing, where every point is its own ring either way.
    #[test]
    fn rings_narrower_than_any_point_spacing_are_not_allocated() {
        let f = crate::register::tests::asphere(0.0);
        let r: Vec<f64> = (1..=4000).map(|k| 0.8 * k as f64 / 4000.0).collect();
        let e: Vec<f64> = r.iter().map(|&rr| 1e-5 + 1e-3 * rr).collect();
        let fine = fit(&f, &r, &e, 1e-15).expect("fits");
        let own = fit(&f, &r, &e, 1e-7).expect("fits");
        assert_eq!(fine.rings, own.rings);
        assert!(
            (fine.x_offset - own.x_offset).abs() < 1e-12,
            "{fine:?} {own:?}"
        );
    }

    /// A part with no set-up error shows neither.
    #[test]
    fn a_true_part_has_no_setup_error() {
        let f = crate::register::tests::asphere(0.0);
        let r: Vec<f64> = (1..=4000).map(|k| 0.8 * k as f64 / 4000.0).collect();
        let e = vec![1e-5; r.len()];
        let s = fit(&f, &r, &e, 1e-3).expect("fits");
        assert!(s.x_offset.abs() < 1e-9 && s.centre_height == 0.0, "{s:?}");
    }
}
