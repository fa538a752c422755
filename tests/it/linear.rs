//! Linear time on inputs the limits allow (issue #33): each input is
//! checked at n and at 4n in the same run, and fails only if the time
//! grows far faster than linearly (over 2.5 times the linear 4×, so 10×;
//! a quadratic step gives 16×). The smaller size is timed after a warm-up
//! run, each size the best of three, so a busy machine slows both alike;
//! no absolute time is asserted.

use std::time::{Duration, Instant};

use lensc_lang::loader::RealFs;

/// The best of three timings of `f`.
fn best(mut f: impl FnMut()) -> Duration {
    (0..3)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed()
        })
        .min()
        .expect("three runs")
}

/// Times `run` on `make(n)` and `make(4n)`; fails if the ratio is over
/// 10 (2.5 times the linear 4).
fn linear(what: &str, n: usize, make: impl Fn(usize) -> String, run: impl Fn(&str)) {
    let (small, large) = (make(n), make(4 * n));
    run(&small); // warm-up
    let a = best(|| run(&small));
    let b = best(|| run(&large));
    let ratio = b.as_secs_f64() / a.as_secs_f64().max(1e-6);
    eprintln!("{what}: n = {n}: {a:?}, 4n: {b:?}, ratio {ratio:.2} (linear 4)");
    assert!(
        ratio < 10.0,
        "{what}: 4n took {ratio:.1} times as long as n ({a:?} → {b:?}); linear is 4"
    );
}

fn check(text: &str) {
    let c = lensc_lang::check_text(&RealFs, "linear.lens", text.as_bytes());
    assert!(!c.has_errors(), "{:?}", c.diags().first());
}

/// A block of n entries: its duplicate detection was a scan of the
/// entries before each one.
#[test]
fn a_block_of_n_entries() {
    linear(
        "block",
        5_000,
        |n| {
            let mut s = String::from("let b = {\n");
            for i in 0..n {
                s.push_str(&format!("    p{i}: {i} mm\n"));
            }
            s.push_str("}\n");
            s
        },
        check,
    );
}

/// A sum of n terms on one line, refused for its depth (E0002) and
/// rendered for people: the report is a window on the line, not the line.
#[test]
fn a_long_sum() {
    linear(
        "sum",
        20_000,
        |n| format!("let total = {}1 um\n", "1 um + ".repeat(n)),
        |text| {
            let c = lensc_lang::check_text(&RealFs, "sum.lens", text.as_bytes());
            assert!(c.has_errors());
            let mut out = Vec::new();
            lensc::render::human(c.diags(), &c.loaded.sources, false, &mut out).expect("render");
            assert!(out.len() < 4_000, "{}", out.len());
        },
    );
}

/// Human diagnostics on a line of n bytes: the rendering is a window.
#[test]
fn a_diagnostic_on_a_long_line() {
    linear(
        "long line",
        1_000_000,
        |n| format!("let a = 1 mm\nlet b = {}zz + a\n", " ".repeat(n)),
        |text| {
            let c = lensc_lang::check_text(&RealFs, "long.lens", text.as_bytes());
            let mut out = Vec::new();
            lensc::render::human(c.diags(), &c.loaded.sources, false, &mut out).expect("render");
            assert!(out.len() < 4_000, "{}", out.len());
        },
    );
}

/// A chain of n files, each `use`-ing the next: loaded and checked in
/// time linear in n (the import-cycle check looked through the files
/// being loaded at each `use`).
#[test]
fn a_chain_of_used_files() {
    let dir = tempfile::tempdir().expect("tmp");
    let write_chain = |n: usize| {
        let sub = dir.path().join(format!("chain{n}"));
        std::fs::create_dir_all(&sub).expect("mkdir");
        for i in 0..n {
            let next = if i + 1 < n {
                format!("use \"f{}.lens\"\n", i + 1)
            } else {
                String::new()
            };
            std::fs::write(
                sub.join(format!("f{i}.lens")),
                format!("{next}let v{i} = {i} mm\n"),
            )
            .expect("write");
        }
        sub.join("f0.lens").display().to_string()
    };
    // 800 nested loads: a stack as large as the binary's main thread.
    std::thread::scope(|s| {
        std::thread::Builder::new()
            .stack_size(8 << 20)
            .spawn_scoped(s, || {
                linear("use chain", 200, write_chain, |path| {
                    let c = lensc_lang::check_path(&RealFs, std::path::Path::new(path))
                        .expect("checked");
                    assert!(!c.has_errors(), "{:?}", c.diags().first());
                })
            })
            .expect("a thread")
            .join()
            .expect("linear");
    });
}

/// A chain of more files than one check loads (E0189, said once) is
/// refused, by the binary as a user runs it.
#[test]
fn a_chain_past_the_file_limit_is_refused() {
    let dir = tempfile::tempdir().expect("tmp");
    let n = lensc_lang::loader::MAX_FILES + 50;
    for i in 0..n {
        std::fs::write(
            dir.path().join(format!("f{i}.lens")),
            format!("use \"f{}.lens\"\nlet v{i} = {i} mm\n", i + 1),
        )
        .expect("write");
    }
    let out = crate::common::lensc(dir.path(), &["check", "f0.lens"]);
    let err = crate::common::text(&out.stderr);
    let head = &err[..err.len().min(2000)];
    assert_eq!(out.status.code(), Some(1), "{head}");
    assert_eq!(err.matches("[E0189]").count(), 1, "{head}");
}
