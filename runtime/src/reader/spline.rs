//! LinuxCNC's splines in the XY plane, as its interpreter makes them
//! (LinuxCNC documentation 2.9, chapter 11, sections 11.5.7 "G5 Cubic
//! Spline" and 11.5.8 "G5.1 Quadratic Spline", pp. 869–870): G5 a cubic
//! Bézier from the current point with its first control point at I J from
//! the start (or, left out after another G5, the previous block's P Q
//! mirrored) and its second at P Q from the end; G5.1 a quadratic Bézier
//! with its control point at I J from the start. Where `rs274` 2.9 runs
//! what the manual calls an error (a first G5 without I J, a G5.1 with I
//! and J zero) the reader follows `rs274` (`State::spline`, in `motion`). The reader hands a
//! spline over as straight moves sampled within [`SPLINE_TOLERANCE`] of
//! the curve, so the read-back simulation cuts what the controller cuts
//! to well under any machine's resolution.

/// The largest distance (mm) between a spline and the straight moves it
/// is handed over as: 1 nm.
pub const SPLINE_TOLERANCE: f64 = 1e-6;

/// The most straight moves one spline is sampled into.
const MOST_PIECES: usize = 100_000;

/// Which spline.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Spline {
    /// G5.
    Cubic,
    /// G5.1.
    Quadratic,
}

/// A Bézier curve of 3 or 4 control points as points whose chords stay
/// within [`SPLINE_TOLERANCE`] of it: a chord of a piece of parameter
/// length h is within h² max|B''| / 8 of the curve, and |B''| is largest at
/// an end (it is linear in the parameter for a cubic, constant for a
/// quadratic).
pub(crate) fn bezier(c: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let n = c.len() - 1;
    let second = |a: (f64, f64), b: (f64, f64), d: (f64, f64)| {
        let k = (n * (n - 1)) as f64;
        (k * (a.0 - 2.0 * b.0 + d.0)).hypot(k * (a.1 - 2.0 * b.1 + d.1))
    };
    let most = second(c[0], c[1], c[2]).max(second(c[n - 2], c[n - 1], c[n]));
    let pieces = ((most / (8.0 * SPLINE_TOLERANCE)).sqrt().ceil() as usize).clamp(1, MOST_PIECES);
    (0..=pieces)
        .map(|k| {
            let t = k as f64 / pieces as f64;
            // de Casteljau: exact at both ends.
            let mut p = c.to_vec();
            for r in 1..=n {
                for i in 0..=n - r {
                    p[i] = (
                        p[i].0 + t * (p[i + 1].0 - p[i].0),
                        p[i].1 + t * (p[i + 1].1 - p[i].1),
                    );
                }
            }
            p[0]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sampled points lie on the curve, and every chord's middle is
    /// within the tolerance of the curve's point there (checked against a
    /// dense sampling).
    #[test]
    fn a_bezier_is_sampled_within_the_tolerance() {
        let c = [(0.0, 0.0), (0.0, 3.0), (1.0, -2.0), (1.0, 1.0)];
        let pts = bezier(&c);
        assert_eq!(pts[0], c[0]);
        assert!((pts[pts.len() - 1].0 - 1.0).abs() < 1e-15);
        let curve = |t: f64| {
            let u = 1.0 - t;
            let b = [u * u * u, 3.0 * u * u * t, 3.0 * u * t * t, t * t * t];
            (
                (0..4).map(|i| b[i] * c[i].0).sum::<f64>(),
                (0..4).map(|i| b[i] * c[i].1).sum::<f64>(),
            )
        };
        let n = pts.len() - 1;
        let mut worst: f64 = 0.0;
        for k in 0..n {
            for m in 1..8 {
                let t = (k as f64 + m as f64 / 8.0) / n as f64;
                let f = m as f64 / 8.0;
                let chord = (
                    pts[k].0 + f * (pts[k + 1].0 - pts[k].0),
                    pts[k].1 + f * (pts[k + 1].1 - pts[k].1),
                );
                let on = curve(t);
                worst = worst.max((chord.0 - on.0).hypot(chord.1 - on.1));
            }
        }
        assert!(worst <= SPLINE_TOLERANCE, "{worst:e}");
        assert!(
            worst > SPLINE_TOLERANCE / 10.0,
            "not oversampled: {worst:e}, {n} pieces"
        );
    }
}
