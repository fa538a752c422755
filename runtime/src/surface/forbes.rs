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
mod tests {
    use super::*;

    #[test]
    fn first_polynomials_match_the_published_forms() {
        let q = qbfs_chebyshev(3);
        for x in [0.0, 0.3, 0.77, 1.0] {
            let close = |a: f64, b: f64| (a - b).abs() <= 1e-13 * b.abs().max(1.0);
            assert!(close(eval_chebyshev(&q[0], x), 1.0));
            assert!(close(
                eval_chebyshev(&q[1], x),
                (13.0 - 16.0 * x) / 19f64.sqrt()
            ));
            let q2 = (2.0f64 / 95.0).sqrt() * (29.0 - 4.0 * x * (25.0 - 19.0 * x));
            assert!(
                close(eval_chebyshev(&q[2], x), q2),
                "{} vs {q2}",
                eval_chebyshev(&q[2], x)
            );
            let q3 =
                (2.0f64 / 2545.0).sqrt() * (207.0 - 4.0 * x * (315.0 - x * (577.0 - 320.0 * x)));
            assert!(
                close(eval_chebyshev(&q[3], x), q3),
                "{} vs {q3}",
                eval_chebyshev(&q[3], x)
            );
        }
    }

    #[test]
    fn qcon_polynomials_match_the_published_forms() {
        // Forbes 2007, eq. (A.1)-(A.2): Q_0 = 1, Q_1 = −(5 − 6x),
        // Q_2 = 15 − 14x(3 − 2x), Q_3 = −{35 − 12x[14 − x(21 − 10x)]}.
        let q = qcon_chebyshev(3);
        for x in [0.0, 0.3, 0.77, 1.0] {
            let want = [
                1.0,
                -(5.0 - 6.0 * x),
                15.0 - 14.0 * x * (3.0 - 2.0 * x),
                -(35.0 - 12.0 * x * (14.0 - x * (21.0 - 10.0 * x))),
            ];
            for (m, w) in want.iter().enumerate() {
                let got = eval_chebyshev(&q[m], x);
                assert!(
                    (got - w).abs() <= 1e-13 * w.abs().max(1.0),
                    "Q{m}({x}) = {got} vs {w}"
                );
            }
        }
    }

    #[test]
    fn qcon_polynomials_are_orthogonal_with_their_weight() {
        // ∫₀¹ Q_m Q_n x⁴ dx = δ_mn / (2m + 5) (Jacobi (0, 4) on 2x − 1).
        let q = qcon_chebyshev(MAX_ORDER);
        let n = 40_000;
        for a in [0, 3, 11, 20] {
            for b in [0, 3, 11, 20] {
                let mut sum = 0.0;
                // The midpoint rule on 40 000 cells: error ~h² f''/24,
                // below 1e-8 here.
                for i in 0..n {
                    let x = (i as f64 + 0.5) / n as f64;
                    sum += eval_chebyshev(&q[a], x) * eval_chebyshev(&q[b], x) * x.powi(4);
                }
                sum /= n as f64;
                let want = if a == b {
                    1.0 / (2 * a + 5) as f64
                } else {
                    0.0
                };
                assert!((sum - want).abs() < 1e-6, "<{a},{b}> = {sum}, want {want}");
            }
        }
    }

    #[test]
    fn slopes_are_orthonormal_to_the_highest_order() {
        // Independent quadrature: u = sin θ turns the weight into dθ, and the
        // midpoint rule on θ ∈ (0, π/2) is spectrally accurate here.
        let q = qbfs_chebyshev(MAX_ORDER);
        let n = 3000;
        let slope = |c: &[f64], u: f64| -> f64 {
            basis_slopes(c.len() - 1, u)
                .iter()
                .zip(c)
                .map(|(a, b)| a * b)
                .sum()
        };
        let mut g = vec![vec![0.0; q.len()]; q.len()];
        for i in 0..n {
            let u = (std::f64::consts::FRAC_PI_2 * (i as f64 + 0.5) / n as f64).sin();
            let s: Vec<f64> = q.iter().map(|c| slope(c, u)).collect();
            for (row, sa) in g.iter_mut().zip(&s) {
                for (cell, sb) in row.iter_mut().zip(&s) {
                    *cell += sa * sb;
                }
            }
        }
        let unit = g[0][0];
        for (a, row) in g.iter().enumerate() {
            for (b, cell) in row.iter().enumerate() {
                let want = if a == b { 1.0 } else { 0.0 };
                assert!(
                    (cell / unit - want).abs() < 1e-11,
                    "<{a},{b}> = {}",
                    cell / unit
                );
            }
        }
    }
}
