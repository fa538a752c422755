//! The full finish toolpath of seed 003's 10 × 10 lens array (Hashimoto &
//! Yan 2025: 2 µm/rev, constant surface speed 5 m/min capped at 1000 rpm,
//! settling offset, 10 nm chord tolerance; about 12,400 revolutions), as
//! `examples/hashimoto2025_lens_array.lens` states it: the planner's points
//! streamed to a sink that only counts them (program text excluded), timed
//! with all threads and with one (the ratio shows the parallel speed-up in
//! the same run), with the process's peak resident memory.
//!
//! Goal (issue #4): under 5 s on the 2-core machine, under 200 MB.
//!
//! Run: cargo bench -p lensc --bench fts_toolpath

#[path = "../../../runtime/benches/support/timing.rs"]
mod timing;

use std::time::Instant;

fn main() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let path = root.join("examples/hashimoto2025_lens_array.lens");
    let c = lensc_build::driver::check_path(&lensc_lang::loader::RealFs, &path).expect("example");
    assert!(!c.has_errors(), "the example checks");
    let job = &c.checked.jobs[0];
    let t = Instant::now();
    let limits = lensc_build::job::Limits::default();
    let Ok((lensc_build::strategy::JobSpec::Spiral(spec), _)) =
        lensc_build::pipeline::lower(job, None, &limits)
    else {
        panic!("lowers to a spiral")
    };
    let prepared = lensc_build::strategy::spiral::Prepared::of(&spec);
    let prepare = t.elapsed();
    let planner = prepared.planner();
    let run = || {
        let mut points = 0usize;
        let t = Instant::now();
        let s = planner
            .plan(&spec.fast_axis, |p| points += p.len())
            .expect("plans");
        (t.elapsed(), s, points)
    };
    let (all, s, points) = run();
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool");
    let (single, s1, _) = one.install(run);
    assert_eq!(
        s.fingerprint, s1.fingerprint,
        "thread count changed the path"
    );
    println!(
        "seed 003 finish toolpath: {} revolutions, {} points, h_offset from the example",
        s.revolutions, points
    );
    println!(
        "  prepare (lowering, JIT, analysis): {:>8.3} s",
        prepare.as_secs_f64()
    );
    println!(
        "  plan, {} threads:                 {:>8.3} s",
        rayon::current_num_threads(),
        all.as_secs_f64()
    );
    println!(
        "  plan, 1 thread:                   {:>8.3} s",
        single.as_secs_f64()
    );
    println!(
        "  speed-up:                         {:>8.2}×",
        single.as_secs_f64() / all.as_secs_f64()
    );
    println!(
        "  peak resident memory:             {:>8.1} MB",
        timing::peak_resident_mb()
    );
}
