//! The emission bench's stream through the writer alone, for profiling
//! (callgrind, perf) and for comparing two builds run alternately: the
//! moves (default 1,000,000) written `rounds` times (default 5), then
//! once more to hash the text. Prints the best wall time and the mean CPU
//! time a line over the timed runs, the text's length and its hash (two
//! builds that print the same hash wrote the same bytes). Run:
//!     cargo run --release -p lensc-runtime --example emission_probe -- 1000000 15

use lensc_runtime::moves::{Feed, Move, Position, Start};
use lensc_runtime::post::{Dialect, ProgramWriter, Setup};
use std::hash::{Hash, Hasher};
use std::time::Instant;

#[path = "../benches/support/timing.rs"]
mod timing;

fn main() {
    let arg = |k: usize, default: usize| {
        std::env::args()
            .nth(k)
            .and_then(|a| a.parse().ok())
            .unwrap_or(default)
    };
    let (moves, rounds) = (arg(1, 1_000_000), arg(2, 5).max(1));
    // The bench's spiral: X, Z and C on every move, inverse time.
    let stream: Vec<Move> = (0..moves)
        .map(|i| {
            let c = i as f64 * 0.0021;
            let x = 24.0 - 0.002 * c / std::f64::consts::TAU;
            let z = 0.4997 + 0.018 * (7.0 * c).sin().powi(2);
            Move::Linear {
                to: Position::xzc(x, z, c),
                feed: Some(Feed::InverseTime(0.00058 + 1e-7 * (i % 13) as f64)),
            }
        })
        .collect();
    // One run: the text's chunks handed to `take`.
    let run = |take: &mut dyn FnMut(String)| {
        let mut w = ProgramWriter::new(
            &Dialect::linuxcnc(),
            Setup::Lathe,
            "probe",
            &[],
            "XZC",
            1e-6,
            1e-5,
        )
        .expect("a LinuxCNC lathe program");
        w.call_tool(&Start::default()).expect("tool 1");
        for chunk in stream.chunks(4096) {
            w.write_all(chunk).expect("printable");
            take(w.take_text().expect("checked"));
        }
    };
    let mut best = f64::MAX;
    let cpu_before = timing::cpu_seconds();
    for _ in 0..rounds {
        let t = Instant::now();
        run(&mut |text| drop(std::hint::black_box(text)));
        best = best.min(t.elapsed().as_secs_f64());
    }
    let cpu = timing::cpu_seconds() - cpu_before;
    let mut hasher = std::collections::hash_map::DefaultHasher::new();
    let mut bytes = 0;
    run(&mut |text| {
        bytes += text.len();
        text.hash(&mut hasher);
    });
    println!(
        "{:.1} ns/line best wall, {:.1} CPU ns/line, {bytes} bytes, hash {:016x}",
        best * 1e9 / moves as f64,
        cpu * 1e9 / (moves * rounds) as f64,
        hasher.finish()
    );
}
