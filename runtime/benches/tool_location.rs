//! Tool location speed: the exact nose-centre height (Newton on each smooth
//! piece of the profile, `envelope::centre_height`) against Lei et al.'s
//! binary search over the discretised profile (`envelope::binary_search`)
//! at the same accuracy, on seed 004's profile: convex arcs R = 0.788 mm,
//! width 0.534 mm, 20 µm seams, a 0.5 mm nose — the arcs and the seams
//! the nose rests across.
//!
//! "Same accuracy": the binary search's profile is discretised every 1 µm
//! (the nose dips at most s²/8ρ = 0.25 nm between points) and halved down
//! to 0.5 nm; the bench measures and prints the largest difference from
//! the exact height over all points, which must stay within 1 nm.
//!
//! Run: cargo bench -p lensc-runtime --bench tool_location
//! A plain harness: best of N runs with `Instant`, ratios from one process.

use std::hint::black_box;
use std::time::Duration;

use lensc_runtime::plan::envelope::{binary_search, centre_height, points_near, split_at_corners};
use lensc_runtime::surface::{Profile, ProfilePoint};

#[path = "support/timing.rs"]
mod timing;
use timing::best_of;

#[path = "../src/plan/envelope/lei_arcs.rs"]
mod lei_arcs;

fn main() {
    let profile = lei_arcs::lei();
    let rho = 0.5;
    // The whole profile: ten periods, as the paper turns it.
    let (a, b) = (0.0, 10.0 * 0.554);
    let pieces = split_at_corners(&profile, a, b);
    let spacing = 1e-3;
    let n = ((b - a) / spacing) as usize;
    let points: Vec<(f64, f64)> = (0..=n)
        .map(|i| {
            let u = a + (b - a) * i as f64 / n as f64;
            (u, profile.point(u).z)
        })
        .collect();
    // Tool positions across one full period plus its seams, away from the ends.
    let xs: Vec<f64> = (0..400).map(|i| 2.2 + 1.0 * i as f64 / 400.0).collect();

    {
        struct Counting<'a>(&'a lei_arcs::Arcs, std::cell::Cell<usize>);
        impl Profile for Counting<'_> {
            fn point(&self, u: f64) -> ProfilePoint {
                self.1.set(self.1.get() + 1);
                self.0.point(u)
            }
        }
        let c = Counting(&profile, std::cell::Cell::new(0));
        for &x in &xs {
            centre_height(&c, &pieces, rho, x);
        }
        println!(
            "  profile evaluations per exact point: {:.1}",
            c.1.get() as f64 / xs.len() as f64
        );
    }
    let mut worst: f64 = 0.0;
    for &x in &xs {
        let e = centre_height(&profile, &pieces, rho, x).0;
        let s = binary_search(&points, rho, x, 0.5e-6);
        let w = binary_search(points_near(&points, x, rho), rho, x, 0.5e-6);
        worst = worst.max((e - s).abs()).max((e - w).abs());
    }

    let exact = best_of(15, || {
        for &x in &xs {
            black_box(centre_height(&profile, &pieces, black_box(rho), x));
        }
    });
    let search = best_of(3, || {
        for &x in &xs {
            black_box(binary_search(&points, black_box(rho), x, 0.5e-6));
        }
    });
    let windowed = best_of(5, || {
        for &x in &xs {
            let near = points_near(&points, x, rho);
            black_box(binary_search(near, black_box(rho), x, 0.5e-6));
        }
    });
    let per = |d: Duration| d.as_secs_f64() * 1e6 / xs.len() as f64;
    println!(
        "tool location on seed 004's profile, {} tool positions, nose 0.5 mm",
        xs.len()
    );
    println!(
        "  exact (Newton per piece):        {:>10.2} µs/point",
        per(exact)
    );
    println!(
        "  binary search as published:      {:>10.2} µs/point  (every profile point, 1 µm apart, to 0.5 nm)",
        per(search)
    );
    println!(
        "  binary search within ±ρ:         {:>10.2} µs/point  (only the points the nose can reach)",
        per(windowed)
    );
    println!(
        "  ratio published/exact:           {:>10.1}×",
        search.as_secs_f64() / exact.as_secs_f64()
    );
    println!(
        "  ratio windowed/exact:            {:>10.1}×",
        windowed.as_secs_f64() / exact.as_secs_f64()
    );
    println!(
        "  largest difference:              {:>10.3} nm",
        worst * 1e6
    );
    assert!(worst < 1e-6, "the searches disagree by {} nm", worst * 1e6);
}
