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

/// The CPU time this process has used so far (s), every thread's, user
/// and system: `/proc/self/stat`'s utime and stime, in clock ticks (100 a
/// second), the 12th and 13th fields after the command's parenthesis.
pub fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let rest = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |k: usize| {
        fields
            .get(k)
            .and_then(|f| f.parse::<f64>().ok())
            .unwrap_or(f64::NAN)
    };
    (ticks(11) + ticks(12)) / 100.0
}

/// The process's peak resident memory so far (MB): `/proc/self/status`'s
/// VmHWM.
pub fn peak_resident_mb() -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<f64>().ok())
        .map_or(f64::NAN, |kb| kb / 1024.0)
}
