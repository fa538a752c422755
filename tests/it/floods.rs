//! Floods of diagnostics: after 100 of one code the rest are counted in one
//! summary line per code (every one with `--all-diagnostics`), and a file
//! of 200,000 unused `let`s checks quickly (the time is printed, not
//! gated on: the bench is `cargo bench -p lensc-build --bench check_throughput`).

use std::time::Instant;

use crate::common::text;

/// A file of `n` unused `let`s in a fresh directory.
fn unused_lets(n: usize) -> (tempfile::TempDir, std::path::PathBuf) {
    let dir = tempfile::tempdir().expect("tmp");
    let path = dir.path().join("lets.lens");
    let mut src = String::with_capacity(n * 20);
    for i in 0..n {
        src.push_str(&format!("let a{i} = 1 mm\n"));
    }
    std::fs::write(&path, src).expect("write");
    (dir, path)
}

fn check(dir: &std::path::Path, args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_lensc"))
        .current_dir(dir)
        .args(args)
        .env("NO_COLOR", "1")
        .output()
        .expect("run lensc")
}

#[test]
fn two_hundred_thousand_warnings_are_summarised_per_code() {
    let (dir, _) = unused_lets(200_000);
    let start = Instant::now();
    let out = check(
        dir.path(),
        &["check", "--message-format", "json", "lets.lens"],
    );
    eprintln!(
        "checking 200,000 unused lets (this build's profile): {:.2} s",
        start.elapsed().as_secs_f64()
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let lines: Vec<serde_json::Value> = text(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).expect("JSON line"))
        .collect();
    assert_eq!(lines.len(), 101);
    assert!(lines.iter().all(|v| v["code"] == "W0001"));
    let summary = &lines[100];
    assert_eq!(summary["suppressed"], 199_900, "{summary}");
    assert!(lines[..100].iter().all(|v| v.get("suppressed").is_none()));

    let out = check(dir.path(), &["check", "lets.lens"]);
    let err = text(&out.stderr);
    assert_eq!(
        err.matches("[W0001]").count(),
        101,
        "100 shown and the summary"
    );
    assert!(
        err.contains("warning[W0001]: 199900 more W0001 diagnostics not shown"),
        "{}",
        &err[err.len().saturating_sub(400)..]
    );
}

#[test]
fn all_diagnostics_prints_every_one() {
    let (dir, _) = unused_lets(1_000);
    let out = check(
        dir.path(),
        &[
            "check",
            "--message-format",
            "json",
            "--all-diagnostics",
            "lets.lens",
        ],
    );
    assert_eq!(out.status.code(), Some(0));
    let stdout = text(&out.stdout);
    assert_eq!(stdout.lines().count(), 1_000);
    assert!(!stdout.contains("suppressed"));
}

#[test]
fn the_limit_is_per_code() {
    // 150 unused lets and 150 missing files: 100 of each shown, two summaries.
    let dir = tempfile::tempdir().expect("tmp");
    let mut src = String::new();
    for i in 0..150 {
        src.push_str(&format!("let a{i} = 1 mm\nuse \"missing{i}.lens\"\n"));
    }
    std::fs::write(dir.path().join("mixed.lens"), src).expect("write");
    let out = check(
        dir.path(),
        &["check", "--message-format", "json", "mixed.lens"],
    );
    assert_eq!(out.status.code(), Some(1));
    let lines: Vec<serde_json::Value> = text(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).expect("JSON line"))
        .collect();
    let summaries: Vec<_> = lines
        .iter()
        .filter(|v| v.get("suppressed").is_some())
        .collect();
    assert_eq!(summaries.len(), 2, "{summaries:?}");
    for code in ["W0001", "E0103"] {
        let shown = lines
            .iter()
            .filter(|v| v["code"] == code && v.get("suppressed").is_none())
            .count();
        assert_eq!(shown, 100, "{code}");
    }
}
