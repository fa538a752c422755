//! Tests of Forbes Q-polynomials.

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
        let q3 = (2.0f64 / 2545.0).sqrt() * (207.0 - 4.0 * x * (315.0 - x * (577.0 - 320.0 * x)));
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
