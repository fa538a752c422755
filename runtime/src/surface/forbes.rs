//! Forbes Q-bfs polynomials (G. W. Forbes, "Shape specification for
//! axially symmetric optical surfaces", Opt. Express 15, 5218 (2007)).
//!
//! The departure from the best-fit sphere is
//!   u²(1 − u²) / sqrt(1 − c² ρ²) · Σ a_m Q_m(u²),  u = ρ / ρ_max,
//! and the Q_m are defined by what makes their coefficients meaningful:
//! the slopes of the basis functions S_m(u) = u²(1 − u²) Q_m(u²) are
//! orthonormal, ∫₀¹ S_m′ S_n′ du / sqrt(1 − u²) = δ_mn (scaled so that
//! Q_0 = 1), with Q_m(0) > 0. They are built here from that definition:
//! Gram–Schmidt over Chebyshev polynomials T_k(2x − 1) (well conditioned,
//! unlike monomials), the integrals done exactly by Gauss–Chebyshev
//! quadrature. Tests compare Q_1 … Q_3 with the closed forms published
//! with them and check orthonormality with an independent quadrature.
//!
//! Q-con (same paper) adds u⁴ Σ a_m Q_m^con(u²) to a conic, with
//! Q_m^con(x) = P_m^(0,4)(2x − 1), the Jacobi polynomials; they are
//! converted here to the same Chebyshev basis so one Clenshaw sum serves
//! both.

/// Highest order a surface may use.
pub const MAX_ORDER: usize = 20;

/// Gauss–Chebyshev nodes on (0, 1) (the integrands are even in u): exact
/// for the polynomials of degree ≤ 4·MAX_ORDER + 6 that appear here.
const NODES: usize = 2 * MAX_ORDER + 8;

/// T_0 … T_n at t, and their derivatives.
fn chebyshev(n: usize, t: f64) -> (Vec<f64>, Vec<f64>) {
    let mut v = vec![1.0, t];
    let mut d = vec![0.0, 1.0];
    for k in 1..n {
        v.push(2.0 * t * v[k] - v[k - 1]);
        d.push(2.0 * v[k] + 2.0 * t * d[k] - d[k - 1]);
    }
    v.truncate(n + 1);
    d.truncate(n + 1);
    (v, d)
}

/// S′ of S(u) = u²(1 − u²) T_k(2u² − 1), for k = 0 … n.
fn basis_slopes(n: usize, u: f64) -> Vec<f64> {
    let x = u * u;
    let (t, dt) = chebyshev(n, 2.0 * x - 1.0);
    (0..=n)
        .map(|k| (2.0 * u - 4.0 * u * u * u) * t[k] + (x - x * x) * dt[k] * 4.0 * u)
        .collect()
}

/// Row m: Q_m = Σ_k c[m][k] T_k(2x − 1), for m = 0 … max.
pub fn qbfs_chebyshev(max: usize) -> Vec<Vec<f64>> {
    let n = max.min(MAX_ORDER);
    // Slopes of every basis function at every node, weight folded in.
    let w = std::f64::consts::PI / (2 * NODES) as f64;
    let at: Vec<Vec<f64>> = (0..NODES)
        .map(|i| {
            let u = (std::f64::consts::PI * (i as f64 + 0.5) / (2 * NODES) as f64).cos();
            basis_slopes(n, u)
        })
        .collect();
    let values = |c: &[f64]| -> Vec<f64> {
        at.iter()
            .map(|s| s.iter().zip(c).map(|(a, b)| a * b).sum())
            .collect()
    };
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>() * w;
    let unit = {
        let mut c = vec![0.0; n + 1];
        c[0] = 1.0;
        let v = values(&c);
        dot(&v, &v)
    };
    let mut qs: Vec<(Vec<f64>, Vec<f64>)> = Vec::new();
    for m in 0..=n {
        let mut c = vec![0.0; n + 1];
        c[m] = 1.0;
        for _ in 0..2 {
            let v = values(&c);
            for (qc, qv) in &qs {
                let proj = dot(&v, qv) / unit;
                for (ci, qi) in c.iter_mut().zip(qc) {
                    *ci -= proj * qi;
                }
            }
        }
        let v = values(&c);
        let norm = (dot(&v, &v) / unit).sqrt();
        // Q_m(0) > 0: T_k(−1) = (−1)^k.
        let at_zero: f64 = c
            .iter()
            .enumerate()
            .map(|(k, ck)| if k % 2 == 0 { *ck } else { -ck })
            .sum();
        let s = if at_zero < 0.0 { -1.0 } else { 1.0 } / norm;
        c.iter_mut().for_each(|ci| *ci *= s);
        let v = values(&c);
        qs.push((c, v));
    }
    qs.into_iter().map(|(c, _)| c).collect()
}

/// P_n^(0,4)(t) by the Jacobi three-term recurrence (α = 0, β = 4):
/// 2n(n+4)(2n+2) P_n = (2n+3)[(2n+4)(2n+2) t − 16] P_{n−1}
///                     − 2(n−1)(n+3)(2n+4) P_{n−2}.
pub fn jacobi_0_4(n: usize, t: f64) -> f64 {
    let (mut p0, mut p1) = (1.0, 3.0 * t - 2.0);
    if n == 0 {
        return p0;
    }
    for k in 2..=n {
        let k = k as f64;
        let a = (2.0 * k + 3.0) * ((2.0 * k + 4.0) * (2.0 * k + 2.0) * t - 16.0);
        let b = 2.0 * (k - 1.0) * (k + 3.0) * (2.0 * k + 4.0);
        let p = (a * p1 - b * p0) / (2.0 * k * (k + 4.0) * (2.0 * k + 2.0));
        p0 = p1;
        p1 = p;
    }
    p1
}

/// Row m: Q_m^con = Σ_k c[m][k] T_k(2x − 1), for m = 0 … max: the values at
/// max + 1 Chebyshev nodes transformed back, exact for these degrees.
pub fn qcon_chebyshev(max: usize) -> Vec<Vec<f64>> {
    let n = max.min(MAX_ORDER) + 1;
    let theta = |j: usize| std::f64::consts::PI * (j as f64 + 0.5) / n as f64;
    (0..n)
        .map(|m| {
            (0..n)
                .map(|k| {
                    let sum: f64 = (0..n)
                        .map(|j| jacobi_0_4(m, theta(j).cos()) * (k as f64 * theta(j)).cos())
                        .sum();
                    let scale = if k == 0 { 1.0 } else { 2.0 };
                    scale * sum / n as f64
                })
                .collect()
        })
        .collect()
}

/// Σ_k c_k T_k(2x − 1), for tests and checks outside the IR.
pub fn eval_chebyshev(c: &[f64], x: f64) -> f64 {
    let (t, _) = chebyshev(c.len().max(2) - 1, 2.0 * x - 1.0);
    c.iter().zip(&t).map(|(a, b)| a * b).sum()
}

#[cfg(test)]
mod tests;
