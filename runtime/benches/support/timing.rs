//! The benches' one clock: the best of N runs timed with `Instant` (the run
//! least disturbed by other load). Every bench of the workspace includes
//! this file with `#[path = …] mod timing;`, so it lives outside any crate's
//! `src/` and in a folder cargo does not take for a bench of its own.
#![allow(dead_code, reason = "each bench uses the helpers it needs")]

use std::time::{Duration, Instant};

/// Best of `runs` timings of `f`.
pub fn best_of(runs: usize, f: impl FnMut()) -> Duration {
    best_run(runs, f).0
}

/// The fastest of `runs` runs of `f`: its time and what it returned.
pub fn best_run<T>(runs: usize, mut f: impl FnMut() -> T) -> (Duration, T) {
    let mut best: Option<(Duration, T)> = None;
    for _ in 0..runs {
        let t = Instant::now();
        let out = f();
        let e = t.elapsed();
        if best.as_ref().is_none_or(|b| e < b.0) {
            best = Some((e, out));
        }
    }
    best.expect("at least one run")
}
