//! What every surface evaluator (a `SurfaceFn` backend) promises beside
//! the reference interpreter, and the check that holds it: the same six
//! outputs at every point to `TOLERANCE` relative (NaN where the
//! interpreter has NaN), whatever `out` held before. The suite that holds
//! each backend to it case by case, instantiated once for the interpreter
//! and once for the JIT, is `suite` (tests only); tests of surfaces built
//! from `.lens` text call `against_reference` too.

use super::ir::{Interpreter, SurfaceFn};

#[cfg(test)]
pub(crate) mod suite;
#[cfg(test)]
pub(crate) use suite::{Backend, surface_fn_test, surface_fn_tests};

/// How far a backend may stray from the reference interpreter, relative to
/// the larger of 1 and the two values (they may round in other orders).
pub const TOLERANCE: f64 = 1e-13;

/// Whether two outputs agree: equal (±∞ and ±0 too), both NaN, or within
/// `TOLERANCE`.
pub fn agree(a: f64, b: f64) -> bool {
    a == b
        || (a.is_nan() && b.is_nan())
        || (a - b).abs() <= TOLERANCE * 1f64.max(a.abs()).max(b.abs())
}

/// Evaluates `f` at the points as one batch, twice (into an `out` of NaN
/// and one of a number, so an output it forgets to write shows), and
/// `reference` once; returns the reference's outputs, or a message naming
/// the first output where `f` disagrees with it or with itself.
pub fn against_reference(
    reference: &Interpreter,
    f: &dyn SurfaceFn,
    xs: &[f64],
    ys: &[f64],
) -> Result<Vec<f64>, String> {
    let n = xs.len();
    let mut want = vec![0.0; 6 * n];
    reference.eval_batch(xs, ys, &mut want);
    let mut got = vec![f64::from_bits(0x7ff4_dead_beef_0001); 6 * n];
    let mut again = vec![-12345.678; 6 * n];
    f.eval_batch(xs, ys, &mut got);
    f.eval_batch(xs, ys, &mut again);
    for i in 0..6 * n {
        let (k, p) = (i % 6, i / 6);
        if !agree(want[i], got[i]) {
            return Err(format!(
                "output {k} at point {p} ({}, {}): reference {:e}, backend {:e}",
                xs[p], ys[p], want[i], got[i]
            ));
        }
        if !agree(want[i], again[i]) {
            return Err(format!(
                "output {k} at point {p} ({}, {}) depends on what `out` held before",
                xs[p], ys[p]
            ));
        }
    }
    Ok(want)
}
