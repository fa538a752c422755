//! Counts of points, steps and samples taken from floating point: a span
//! over a spacing, as a whole number, or `None` where it is not one a
//! planner can allocate or loop over. `as usize` alone saturates (NaN to
//! 0, infinity and 1e300 to `usize::MAX`), and an allocation of that many
//! aborts the process; a planner counts here first and refuses the job
//! with the number.

/// The whole steps of `spacing` that cover `span` (⌈span / spacing⌉, at
/// least `least`), or `None` if that is not a number, or more than `most`.
pub fn steps_over(span: f64, spacing: f64, least: usize, most: usize) -> Option<usize> {
    let n = (span / spacing).ceil();
    // NaN fails both comparisons; a negative span is `least` steps.
    if n.is_nan() || n > most as f64 {
        None
    } else {
        Some((n.max(0.0) as usize).max(least))
    }
}

#[cfg(test)]
mod tests {
    use super::steps_over;

    #[test]
    fn counts_whole_steps_and_refuses_what_is_no_count() {
        assert_eq!(steps_over(1.0, 0.25, 1, 10), Some(4));
        assert_eq!(steps_over(1.0, 0.3, 1, 10), Some(4));
        assert_eq!(steps_over(0.0, 0.3, 1, 10), Some(1));
        assert_eq!(steps_over(-5.0, 0.3, 2, 10), Some(2));
        assert_eq!(steps_over(1.0, 0.1, 1, 10), Some(10));
        assert_eq!(steps_over(1.0, 0.09, 1, 10), None);
        assert_eq!(steps_over(1.0, 1e-300, 1, usize::MAX), None);
        assert_eq!(steps_over(f64::INFINITY, 1.0, 1, usize::MAX), None);
        assert_eq!(steps_over(f64::NAN, 1.0, 1, 10), None);
        assert_eq!(steps_over(1.0, 0.0, 1, 10), None);
    }
}
