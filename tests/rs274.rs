//! Programs against a real interpreter: LinuxCNC's standalone `rs274`
//! (Debian package linuxcnc-uspace; `.ci/run` installs it). Every LinuxCNC
//! program an example builds must pass `rs274 -g`, and the canonical moves
//! it prints must lie on the tool-centre curve computed here independently
//! of lensc's runtime.

mod common;

use std::path::Path;
use std::process::Command;

use common::{buildable_examples, lensc, root, text};

fn rs274() -> Command {
    assert!(
        Command::new("rs274").arg("-h").output().is_ok(),
        "rs274 is not installed: apt-get install linuxcnc-uspace (.ci/run does this)"
    );
    let mut c = Command::new("rs274");
    c.arg("-g");
    c
}

/// rs274 instances running at the same time crash each other with SIGBUS
/// (seen with 10 in parallel: they share interpreter state outside the
/// process), so the tests run it one at a time.
static RS274: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Runs rs274 on a program; returns the canonical commands it printed.
fn interpret(program: &Path) -> String {
    let _one_at_a_time = RS274.lock().unwrap_or_else(|e| e.into_inner());
    let out = rs274().arg(program).output().expect("run rs274");
    let stdout = text(&out.stdout);
    assert_eq!(
        out.status.code(),
        Some(0),
        "rs274 rejected {} ({:?}):\n{}\n{}",
        program.display(),
        out.status,
        stdout,
        text(&out.stderr)
    );
    stdout
}

/// (x, z) of every STRAIGHT_FEED in rs274's canonical output.
fn feeds(canon: &str) -> Vec<(f64, f64)> {
    feed_axes(canon).iter().map(|v| (v[0], v[2])).collect()
}

/// All six axes (x, y, z, a, b, c) of every STRAIGHT_FEED in rs274's
/// canonical output.
fn feed_axes(canon: &str) -> Vec<Vec<f64>> {
    canon
        .lines()
        .filter_map(|l| l.split_once("STRAIGHT_FEED(").map(|(_, rest)| rest))
        .map(|args| {
            args.trim_end_matches(')')
                .split(',')
                .map(|s| s.trim().parse().expect("number"))
                .collect()
        })
        .collect()
}

/// The Kim 2008 convex conic of examples/kim2008_convex_asphere.lens and the
/// centre of a 2 mm nose touching it at radius r, written out afresh.
fn kim_centre(r: f64) -> (f64, f64) {
    let (c, k, rho) = (1.0 / 22.405, 43.098, 2.0);
    let root = (1.0 - (1.0 + k) * c * c * r * r).sqrt();
    let z = -(c * r * r / (1.0 + root)); // convex: material on −Z
    let dz = -(c * r / root);
    let n = (1.0 + dz * dz).sqrt();
    (r - rho * dz / n, z + rho / n)
}

/// Height of the tool-centre curve at machine X = x (bisection on r; the
/// curve's x grows with r on a convex part).
fn kim_centre_z_at(x: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, 1.6);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if kim_centre(mid).0 < x {
            lo = mid
        } else {
            hi = mid
        }
    }
    kim_centre(0.5 * (lo + hi)).1
}

#[test]
fn every_example_program_passes_rs274() {
    let dir = tempfile::tempdir().expect("tmp");
    for ex in buildable_examples() {
        let out = lensc(
            &root(),
            &[
                "build",
                ex.to_str().expect("utf8"),
                "--out",
                dir.path().to_str().expect("utf8"),
            ],
        );
        assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    }
    let mut n = 0;
    for entry in std::fs::read_dir(dir.path()).expect("out") {
        let p = entry.expect("entry").path();
        // rs274 takes about 15 µs a line: the fast-tool-servo example's six
        // million are left to `fts_program_passes_rs274`, on a smaller array.
        let big = std::fs::metadata(&p).is_ok_and(|m| m.len() > 8 << 20);
        if p.extension().is_some_and(|e| e == "ngc") && !big {
            let canon = interpret(&p);
            assert!(!feeds(&canon).is_empty(), "{} cuts nothing", p.display());
            // Blending is on and held to the tolerance the program states.
            let program = std::fs::read_to_string(&p).expect("program");
            let stated: f64 = program
                .lines()
                .find_map(|l| l.split_once("G64 P"))
                .and_then(|(_, rest)| rest.split_whitespace().next())
                .and_then(|v| v.parse().ok())
                .unwrap_or_else(|| panic!("{}: no G64 P", p.display()));
            let mode = canon
                .lines()
                .find_map(|l| l.split_once("SET_MOTION_CONTROL_MODE(CANON_CONTINUOUS, "))
                .map(|(_, v)| v.trim_end_matches(')').parse::<f64>().expect("number"))
                .unwrap_or_else(|| panic!("{}: not in continuous mode", p.display()));
            assert!(
                (mode - stated).abs() < 1e-6,
                "{}: {mode} vs {stated}",
                p.display()
            );
            assert!(stated > 0.0 && stated <= 1e-4, "{}: P{stated}", p.display());
            n += 1;
        }
    }
    assert!(n >= 1);
}

#[test]
fn canonical_moves_lie_on_the_offset_curve() {
    let dir = tempfile::tempdir().expect("tmp");
    let out = lensc(
        &root(),
        &[
            "build",
            "examples/kim2008_convex_asphere.lens",
            "--out",
            dir.path().to_str().expect("utf8"),
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let program = dir.path().join("kim_convex.ngc");
    let moves = feeds(&interpret(&program));
    // The first feed is the plunge from the retract height to the start.
    let cut = &moves[1..];
    assert!(cut.len() > 20, "{} cutting moves", cut.len());
    // rs274 prints 4 decimals: each coordinate is within 0.5e-4 mm.
    for &(x, z) in cut {
        let want = kim_centre_z_at(x);
        assert!(
            (z - want).abs() <= 0.6e-4,
            "rs274 move X{x} Z{z}: curve at {want}"
        );
    }
    // The cut sweeps the whole aperture, from the edge to the axis.
    assert!(
        (moves[0].0 - kim_centre(1.6).0).abs() < 1e-4,
        "starts at X{}",
        moves[0].0
    );
    assert!(cut.last().expect("last").0.abs() < 1e-4);
}

#[test]
fn program_points_and_chords_are_within_tolerance() {
    // The program itself carries 5 decimals (10 nm resolution): check its
    // points at that precision, and the middle of every chord against the
    // 10 nm chord tolerance plus rounding.
    let dir = tempfile::tempdir().expect("tmp");
    let out = lensc(
        &root(),
        &[
            "build",
            "examples/kim2008_convex_asphere.lens",
            "--out",
            dir.path().to_str().expect("utf8"),
        ],
    );
    assert_eq!(out.status.code(), Some(0));
    let program = std::fs::read_to_string(dir.path().join("kim_convex.ngc")).expect("program");
    let (mut x, mut z) = (f64::NAN, f64::NAN);
    let mut pts = Vec::new();
    for line in program.lines().filter(|l| !l.starts_with('(')) {
        for w in line.split_whitespace() {
            if let Some(v) = w.strip_prefix('X') {
                x = v.parse().expect("X")
            }
            if let Some(v) = w.strip_prefix('Z') {
                z = v.parse().expect("Z")
            }
        }
        if line.contains("G1") {
            pts.push((x, z));
        }
    }
    let cut = &pts[1..];
    let rounding = 0.5e-5 * 2.0;
    for &(x, z) in cut {
        assert!(
            (z - kim_centre_z_at(x)).abs() <= rounding,
            "point X{x} Z{z}"
        );
    }
    for w in cut.windows(2) {
        let (mx, mz) = (0.5 * (w[0].0 + w[1].0), 0.5 * (w[0].1 + w[1].1));
        let dev = (mz - kim_centre_z_at(mx)).abs();
        assert!(dev <= 10e-6 + rounding, "chord {w:?} strays {dev} mm");
    }
}

#[test]
fn fts_program_passes_rs274() {
    // A fast-tool-servo spiral over four of seed 003's lenslets: rs274 reads
    // every move; X falls along the spiral while C rises; the nose-centre
    // heights it reports span what the build report says the fast axis does.
    let dir = tempfile::tempdir().expect("tmp");
    let out = lensc(
        &root(),
        &[
            "build",
            "tests/jobs/fts_small_array.lens",
            "--out",
            dir.path().to_str().expect("utf8"),
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let canon = interpret(&dir.path().join("corner_fts.ngc"));
    let moves = feed_axes(&canon);
    let report: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("corner_fts.report.json")).expect("report"),
    )
    .expect("json");
    let points = report["toolpath"]["cut_points"].as_u64().expect("points") as usize;
    // The plunge, then one move per point after the first.
    assert_eq!(moves.len(), points, "one feed move per point");
    let cut = &moves[1..];
    assert!(
        cut.windows(2)
            .all(|w| w[1][0] <= w[0][0] && w[1][5] > w[0][5])
    );
    let (lo, hi) = cut
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), m| {
            (a.min(m[2]), b.max(m[2]))
        });
    let fa = &report["toolpath"]["fast_axis"];
    // rs274 prints 4 decimals.
    assert!(
        (lo - fa["w_min_mm"].as_f64().expect("min")).abs() < 6e-5,
        "{lo}"
    );
    assert!(
        (hi - fa["w_max_mm"].as_f64().expect("max")).abs() < 6e-5,
        "{hi}"
    );
}

#[test]
fn roller_program_passes_rs274() {
    // Seed 002's pattern on a coarse helix: rs274 reads every move; Z
    // advances by the pitch per turn of C within each pass.
    let dir = tempfile::tempdir().expect("tmp");
    let out = lensc(
        &root(),
        &[
            "build",
            "tests/jobs/roller_small.lens",
            "--out",
            dir.path().to_str().expect("utf8"),
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let canon = interpret(&dir.path().join("roller_small.ngc"));
    let moves = feed_axes(&canon);
    // Rough: 5 turns of 180 points + the end; finish: 20 turns of 360 + 1.
    assert_eq!(moves.len(), 5 * 180 + 1 + 20 * 360 + 1);
    let finish = &moves[5 * 180 + 1..];
    for w in finish[1..].windows(2) {
        let (dz, dc) = (w[1][2] - w[0][2], w[1][5] - w[0][5]);
        assert!((dz - 0.05 * dc / 360.0).abs() < 2e-4, "dz {dz} for dc {dc}");
    }
}
