//! Form-error figures as an optician reads them, gathered in a form that
//! merges: the error is the cut minus the design (positive where material
//! is left); PV is its largest minus its least value over the evaluated
//! area, RMS is taken about its mean (so RMS ≤ PV/2 always holds, never
//! RMS > PV), and the mean (piston) and the largest deviation from the
//! design in either direction are given beside them, each with where it
//! is, so a part cut uniformly deep shows in the mean and the largest
//! deviation rather than vanishing from PV and RMS.
//!
//! [`ErrorStats`] keeps the count, the running mean and the sum of
//! squared deviations about it (Welford), and the least and largest
//! errors with their locations; two of them over disjoint sets merge
//! (Chan, Golub and LeVeque's pairwise update) into the figures of the
//! union, so a simulation cut into tiles can total its tiles.

/// The running statistics of a set of errors (mm) at locations `P` (a
/// radius, or an (x, y) point).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorStats<P> {
    /// Errors counted.
    pub count: u64,
    /// Their mean (mm); 0 while none is counted.
    mean: f64,
    /// The sum of their squared deviations from the mean (mm²).
    m2: f64,
    /// The least error and where; +∞ while none is counted.
    pub min: (f64, P),
    /// The largest error and where; −∞ while none is counted.
    pub max: (f64, P),
}

impl<P: Copy + Default> Default for ErrorStats<P> {
    fn default() -> Self {
        ErrorStats::new()
    }
}

impl<P: Copy + Default> ErrorStats<P> {
    /// No error counted yet.
    pub fn new() -> ErrorStats<P> {
        ErrorStats {
            count: 0,
            mean: 0.0,
            m2: 0.0,
            min: (f64::INFINITY, P::default()),
            max: (f64::NEG_INFINITY, P::default()),
        }
    }

    /// Counts the error `e` (mm) at `at`; a NaN is not counted.
    pub fn add(&mut self, e: f64, at: P) {
        if e.is_nan() {
            return;
        }
        self.count += 1;
        let d = e - self.mean;
        self.mean += d / self.count as f64;
        self.m2 += d * (e - self.mean);
        if e < self.min.0 {
            self.min = (e, at);
        }
        if e > self.max.0 {
            self.max = (e, at);
        }
    }

    /// Adds the errors `other` counted (a disjoint set: another tile):
    /// the result is the statistics of both sets together. On equal
    /// extremes the location already held is kept.
    pub fn merge(&mut self, other: &ErrorStats<P>) {
        if other.count == 0 {
            return;
        }
        if self.count == 0 {
            *self = *other;
            return;
        }
        let (na, nb) = (self.count as f64, other.count as f64);
        let n = na + nb;
        let d = other.mean - self.mean;
        self.mean += d * nb / n;
        self.m2 += other.m2 + d * d * na * nb / n;
        self.count += other.count;
        if other.min.0 < self.min.0 {
            self.min = other.min;
        }
        if other.max.0 > self.max.0 {
            self.max = other.max;
        }
    }

    /// The figures of the errors counted, if any.
    pub fn figures(&self) -> Option<ErrorFigures<P>> {
        (self.count > 0).then(|| {
            let largest = if self.max.0.abs() >= self.min.0.abs() {
                self.max
            } else {
                self.min
            };
            ErrorFigures {
                count: self.count as usize,
                pv: self.max.0 - self.min.0,
                rms: (self.m2.max(0.0) / self.count as f64).sqrt(),
                mean: self.mean,
                largest_deviation: largest,
                max_residual: (self.max.0.max(0.0), self.max.1),
                max_gouge: ((-self.min.0).max(0.0), self.min.1),
            }
        })
    }
}

/// The figures of a set of form errors (mm): cut minus design, positive
/// where material is left.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorFigures<P> {
    /// Errors counted.
    pub count: usize,
    /// Peak to valley: the largest error minus the least.
    pub pv: f64,
    /// Root mean square about the mean (the standard deviation).
    pub rms: f64,
    /// The mean error (piston): a uniform datum shift.
    pub mean: f64,
    /// The error of the largest magnitude, its sign kept, and where.
    pub largest_deviation: (f64, P),
    /// The most material left above the design (≥ 0) and where.
    pub max_residual: (f64, P),
    /// The deepest cut below the design (≥ 0) and where.
    pub max_gouge: (f64, P),
}

#[cfg(test)]
mod tests {
    use super::*;

    fn of(errors: &[f64]) -> ErrorStats<f64> {
        let mut s = ErrorStats::new();
        for (i, &e) in errors.iter().enumerate() {
            s.add(e, i as f64);
        }
        s
    }

    /// A part cut uniformly 44 nm deep: no form error (PV and RMS 0), the
    /// whole shift in the mean and the largest deviation.
    #[test]
    fn a_uniform_datum_shift_shows_in_the_mean_not_the_form() {
        let f = of(&[-44e-6; 1000]).figures().unwrap();
        assert!(f.pv.abs() < 1e-18 && f.rms < 1e-15, "{f:?}");
        assert!((f.mean + 44e-6).abs() < 1e-15, "{f:?}");
        assert!((f.largest_deviation.0 + 44e-6).abs() < 1e-18, "{f:?}");
        assert!((f.max_gouge.0 - 44e-6).abs() < 1e-18 && f.max_residual.0 == 0.0);
    }

    /// A tilt: errors evenly from −a to +a. PV 2a, mean 0, RMS about the
    /// mean a/√3 (the uniform distribution's, in the limit), RMS ≤ PV.
    #[test]
    fn a_tilt_has_the_figures_of_a_ramp() {
        let n = 100_001;
        let a = 5e-6;
        let ramp: Vec<f64> = (0..n)
            .map(|i| -a + 2.0 * a * i as f64 / (n - 1) as f64)
            .collect();
        let f = of(&ramp).figures().unwrap();
        assert!((f.pv - 2.0 * a).abs() < 1e-18, "{f:?}");
        assert!(f.mean.abs() < 1e-16, "{f:?}");
        assert!((f.rms - a / 3f64.sqrt()).abs() < 1e-4 * a, "{f:?}");
        assert!(f.rms <= f.pv);
        // The largest deviation is the first of the two equal ends.
        assert_eq!(f.largest_deviation, (a, (n - 1) as f64));
        assert_eq!(f.max_gouge, (a, 0.0));
    }

    /// Splitting a set into tiles and merging their statistics gives the
    /// statistics of the whole, extremes and their places included.
    #[test]
    fn tiles_merge_into_the_whole() {
        let errors: Vec<f64> = (0..1000)
            .map(|i| 1e-6 * ((i as f64 * 0.37).sin() + 3.0))
            .collect();
        let whole = of(&errors);
        for cut in [0, 1, 333, 999, 1000] {
            let (a, b) = errors.split_at(cut);
            let mut left = of(a);
            let mut right = ErrorStats::new();
            for (i, &e) in b.iter().enumerate() {
                right.add(e, (cut + i) as f64);
            }
            left.merge(&right);
            let (w, m) = (whole.figures().unwrap(), left.figures().unwrap());
            assert_eq!(m.count, w.count);
            assert_eq!(
                (m.pv, m.max_residual, m.max_gouge),
                (w.pv, w.max_residual, w.max_gouge)
            );
            assert!((m.mean - w.mean).abs() < 1e-18, "{m:?} {w:?}");
            assert!((m.rms - w.rms).abs() < 1e-15, "{m:?} {w:?}");
        }
    }

    #[test]
    fn nothing_counted_has_no_figures() {
        let mut s: ErrorStats<f64> = ErrorStats::new();
        s.add(f64::NAN, 0.0);
        assert!(s.figures().is_none());
        s.merge(&ErrorStats::new());
        assert!(s.figures().is_none());
    }
}
