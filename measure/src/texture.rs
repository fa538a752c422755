//! Texture after form removal, as ISO 25178-2 defines its height and
//! hybrid parameters, on the residual map (measured minus the registered
//! design: the F-operator is the design itself, fitted by `register`).
//! What is left is split by a Gaussian filter (ISO 16610-61, weighting
//! s(x) = exp(−π (x / (α λc))²) / (α λc), α = √(ln 2 / π)) of nesting
//! index λc: the filtered surface is the waviness (and the form error the
//! registration leaves), the rest is the texture (the S-L surface). The
//! filter is applied as a Gaussian regression of the first order (a
//! weighted straight line through the valid points under the window, read
//! at its centre, along x then along y): in the interior of a full map
//! the plain Gaussian mean, and at the map's edges and the mask's holes a
//! ramp is followed instead of pulled (ISO 16610-21's end effect).
//!
//! - Sa: arithmetical mean height, mean |z|;
//! - Sq: root mean square height;
//! - Sz: maximum height, Sp + Sv (highest peak plus deepest valley);
//! - Sdq: root mean square gradient, central differences where both
//!   neighbours are valid.
//!
//! z is taken about its mean over the valid points.

use crate::map::HeightMap;

/// α of the Gaussian filter (ISO 16610-61).
pub const ALPHA: f64 = 0.469_718_639_349_826_4; // √(ln 2 / π)

/// The texture figures (mm, Sdq dimensionless).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Texture {
    pub sa: f64,
    pub sq: f64,
    pub sz: f64,
    pub sdq: f64,
    /// Points that entered the figures.
    pub points: usize,
}

/// The residual's texture: high-pass Gaussian of nesting index `lambda_c`
/// (mm), then the parameters. `None` without two valid neighbours anywhere.
pub fn texture(residual: &HeightMap, lambda_c: f64) -> Option<Texture> {
    let waviness = gaussian(residual, lambda_c);
    let mut t = residual.clone();
    for ((z, v), w) in t.z.iter_mut().zip(&t.valid).zip(&waviness) {
        if *v {
            *z -= w;
        }
    }
    parameters(&t)
}

/// ISO 25178-2 Sa, Sq, Sz and Sdq of a map as it is (mean removed).
pub fn parameters(m: &HeightMap) -> Option<Texture> {
    let n = m.valid_count();
    if n < 2 {
        return None;
    }
    let mean =
        m.z.iter()
            .zip(&m.valid)
            .filter(|(_, v)| **v)
            .map(|(z, _)| z)
            .sum::<f64>()
            / n as f64;
    let (mut sa, mut sq, mut hi, mut lo) = (0.0, 0.0, f64::NEG_INFINITY, f64::INFINITY);
    for (z, v) in m.z.iter().zip(&m.valid) {
        if *v {
            let h = z - mean;
            sa += h.abs();
            sq += h * h;
            hi = hi.max(h);
            lo = lo.min(h);
        }
    }
    let (mut g2, mut ng) = (0.0, 0usize);
    let at = |i: usize, j: usize| j * m.nx + i;
    for j in 1..m.ny.saturating_sub(1) {
        for i in 1..m.nx.saturating_sub(1) {
            let (l, r, d, u) = (at(i - 1, j), at(i + 1, j), at(i, j - 1), at(i, j + 1));
            if m.valid[l] && m.valid[r] && m.valid[d] && m.valid[u] {
                let gx = (m.z[r] - m.z[l]) / (2.0 * m.dx);
                let gy = (m.z[u] - m.z[d]) / (2.0 * m.dy);
                g2 += gx * gx + gy * gy;
                ng += 1;
            }
        }
    }
    Some(Texture {
        sa: sa / n as f64,
        sq: (sq / n as f64).sqrt(),
        sz: hi - lo,
        sdq: if ng > 0 { (g2 / ng as f64).sqrt() } else { 0.0 },
        points: n,
    })
}

/// The Gaussian-filtered surface (separable; normalised over valid points).
pub fn gaussian(m: &HeightMap, lambda_c: f64) -> Vec<f64> {
    let kernel = |d: f64, n: usize| -> Vec<f64> {
        // Truncated where the weight is below 1e-6 of its peak (|x| ≤ 1.3 λc),
        // and at the map's own `n` points along it: an offset of n or more
        // meets no point, so the cut changes nothing (a cutoff of 1 m over
        // 1 nm pixels counted 1.3e12, `as usize` unchecked: an abort on
        // its allocation).
        let half = lensc_runtime::plan::count::steps_over(1.3 * lambda_c, d, 1, n.max(1))
            .unwrap_or(n.max(1));
        (0..=2 * half)
            .map(|k| {
                let x = (k as f64 - half as f64) * d / (ALPHA * lambda_c);
                (-std::f64::consts::PI * x * x).exp()
            })
            .collect()
    };
    let (kx, ky) = (kernel(m.dx, m.nx), kernel(m.dy, m.ny));
    let (z1, ok1) = regression_pass(m, &m.z, &m.valid, &kx, true);
    let (z2, _) = regression_pass(m, &z1, &ok1, &ky, false);
    z2
}

/// One pass along x or y: at each point, the weighted straight line
/// through the valid points of the window, read at the point (in the
/// interior, with every point valid, the Gaussian mean itself).
fn regression_pass(
    m: &HeightMap,
    src: &[f64],
    ok: &[bool],
    k: &[f64],
    along_x: bool,
) -> (Vec<f64>, Vec<bool>) {
    let half = (k.len() / 2) as isize;
    let mut out = vec![0.0; src.len()];
    let mut has = vec![false; src.len()];
    for j in 0..m.ny {
        for i in 0..m.nx {
            let (mut s0, mut s1, mut s2, mut t0, mut t1) = (0.0, 0.0, 0.0, 0.0, 0.0);
            for (t, w) in k.iter().enumerate() {
                let o = t as isize - half;
                let (ii, jj) = if along_x {
                    (i as isize + o, j as isize)
                } else {
                    (i as isize, j as isize + o)
                };
                if ii >= 0 && jj >= 0 && (ii as usize) < m.nx && (jj as usize) < m.ny {
                    let q = jj as usize * m.nx + ii as usize;
                    if ok[q] {
                        let of = o as f64;
                        s0 += w;
                        s1 += w * of;
                        s2 += w * of * of;
                        t0 += w * src[q];
                        t1 += w * of * src[q];
                    }
                }
            }
            let det = s0 * s2 - s1 * s1;
            let at = j * m.nx + i;
            if det > 1e-12 * s0 * s0 {
                out[at] = (s2 * t0 - s1 * t1) / det;
                has[at] = true;
            } else if s0 > 0.0 {
                out[at] = t0 / s0;
                has[at] = true;
            }
        }
    }
    (out, has)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sine of amplitude a along x, 20 µm long (λc / 12.5), over a
    /// waviness four times higher and 5 mm long (λc · 20, a ramp and a bend
    /// across the 1 mm map) that the filter must take out:
    /// Sa = 2a/π, Sq = a/√2, Sz = 2a, Sdq = a·2π/λ/√2.
    #[test]
    fn a_sine_under_waviness_gives_the_closed_forms() {
        let (a, lambda, lc) = (5e-6, 0.02, 0.25);
        let (n, d) = (1000, 0.001);
        let mut z = Vec::new();
        for _j in 0..20 {
            for i in 0..n {
                let x = i as f64 * d;
                z.push(
                    a * (std::f64::consts::TAU * x / lambda).sin()
                        + 2e-5 * (std::f64::consts::TAU * x / (20.0 * lc)).sin(),
                );
            }
        }
        let m = HeightMap::from_heights(n, 20, (d, d), z);
        let t = texture(&m, lc).expect("figures");
        let k = std::f64::consts::TAU / lambda;
        for (name, got, want) in [
            ("Sa", t.sa, 2.0 * a / std::f64::consts::PI),
            ("Sq", t.sq, a / 2f64.sqrt()),
            ("Sz", t.sz, 2.0 * a),
            ("Sdq", t.sdq, a * k / 2f64.sqrt()),
        ] {
            // Sz, an extreme, takes the end effect at the map's two ends
            // (the first-order regression over a part window of the short
            // sine): 10 %; the means 3 %.
            let tol = if name == "Sz" { 0.10 } else { 0.03 };
            assert!(
                (got - want).abs() <= tol * want,
                "{name}: {got:e}, closed form {want:e}"
            );
        }
        // Without the filter the waviness dominates.
        assert!(parameters(&m).unwrap().sq > 1.3 * a / 2f64.sqrt());
    }

    /// A cutoff far longer than the map, over fine pixels, is cut at the
    /// map's own length (issue #33: a 1 m cutoff over 1 nm pixels counted
    /// a kernel of 2.6e9 weights, 21 GB allocated for 40 pixels): the
    /// regression of a tilted plane is the plane itself, whatever the
    /// kernel, so its roughness is nothing.
    #[test]
    fn a_cutoff_longer_than_the_map_is_cut_at_the_map() {
        let (nx, ny, d) = (40, 30, 1e-6);
        let z: Vec<f64> = (0..ny)
            .flat_map(|j| (0..nx).map(move |i| 1e-6 * i as f64 - 2e-6 * j as f64))
            .collect();
        let m = HeightMap::from_heights(nx, ny, (d, d), z.clone());
        let w = gaussian(&m, 1000.0);
        for (got, want) in w.iter().zip(&z) {
            assert!((got - want).abs() < 1e-12, "{got:e} vs {want:e}");
        }
    }

    #[test]
    fn invalid_points_do_not_enter() {
        let mut m = HeightMap::from_heights(
            3,
            3,
            (1.0, 1.0),
            vec![0.0, 1.0, 0.0, 1.0, f64::NAN, 1.0, 0.0, 1.0, 0.0],
        );
        let t = parameters(&m).unwrap();
        assert_eq!(t.points, 8);
        m.z[4] = 1e9; // not read: the point is invalid
        assert_eq!(parameters(&m).unwrap(), t);
    }
}
