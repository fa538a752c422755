//! Programs against a real interpreter: LinuxCNC's standalone `rs274`
//! (Debian package linuxcnc-uspace; `.ci/run` installs it). Every LinuxCNC
//! program an example builds must pass `rs274 -g`, and the canonical moves
//! it prints must lie on the tool-centre curve computed here independently
//! of lensc's runtime.

use std::path::Path;
use std::process::Command;

use crate::common::{Written, built, built_examples, lensc, root, text};

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
pub(crate) static RS274: std::sync::Mutex<()> = std::sync::Mutex::new(());

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

/// X and Z of the end of every STRAIGHT_FEED and ARC_FEED in rs274's
/// canonical output of a G18 program, and for each arc also the middle of
/// the arc (ARC_FEED gives Z and X of the end, Z and X of the centre and
/// the turns, positive counter-clockwise from Z towards X).
fn cut_points_xz(canon: &str) -> Vec<(f64, f64)> {
    let mut out: Vec<(f64, f64)> = Vec::new();
    let args = |rest: &str| -> Vec<f64> {
        rest.trim_end_matches(')')
            .split(',')
            .map(|s| s.trim().parse().expect("number"))
            .collect()
    };
    for l in canon.lines() {
        if let Some((_, rest)) = l.split_once("STRAIGHT_FEED(") {
            let v = args(rest);
            out.push((v[0], v[2]));
        } else if let Some((_, rest)) = l.split_once("ARC_FEED(") {
            let v = args(rest);
            let (end_z, end_x, cz, cx, turn) = (v[0], v[1], v[2], v[3], v[4]);
            let &(x0, z0) = out.last().expect("an arc after a feed");
            let a0 = (x0 - cx).atan2(z0 - cz);
            let a1 = (end_x - cx).atan2(end_z - cz);
            let tau = std::f64::consts::TAU;
            let sweep = if turn > 0.0 {
                (a1 - a0).rem_euclid(tau)
            } else {
                -(a0 - a1).rem_euclid(tau)
            };
            let r = (x0 - cx).hypot(z0 - cz);
            let a = a0 + 0.5 * sweep;
            out.push((cx + r * a.sin(), cz + r * a.cos()));
            out.push((end_x, end_z));
        }
    }
    out
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

/// The seed 001 convex lens's turning program, from the one build of the
/// examples.
fn kim_convex_program() -> String {
    match &built("examples/kim2008_convex_asphere.lens").files["kim_convex.ngc"] {
        Written::Whole(bytes) => text(bytes),
        Written::Abridged(_) => unreachable!("a program of kilobytes"),
    }
}

/// Where the program's control point lies from the nose centre (X, Z),
/// as its header states it: the program moves the imaginary tip, the
/// curve below is the centre's.
fn kim_control_offset() -> (f64, f64) {
    let o = lensc_runtime::reader::header_control_offset(&kim_convex_program())
        .expect("the header states the control point");
    (o[0], o[2])
}

#[test]
fn every_example_program_passes_rs274() {
    let dir = tempfile::tempdir().expect("tmp");
    let mut n = 0;
    for (name, file) in built_examples().iter().flat_map(|b| &b.files) {
        // rs274 takes about 15 µs a line: the programs of millions of
        // points, not kept whole, are left to `fts_program_passes_rs274` and
        // `roller_program_passes_rs274`, on smaller jobs.
        let Written::Whole(bytes) = file else {
            continue;
        };
        let p = dir.path().join(name);
        if p.extension().is_some_and(|e| e == "ngc") {
            std::fs::write(&p, bytes).expect("write program");
            let canon = interpret(&p);
            assert!(!feeds(&canon).is_empty(), "{} cuts nothing", p.display());
            // Blending is on and held to the tolerance the program states.
            let program = text(bytes);
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
    let program = dir.path().join("kim_convex.ngc");
    std::fs::write(&program, kim_convex_program()).expect("write program");
    let canon = interpret(&program);
    assert!(canon.contains("ARC_FEED("), "no arcs");
    // As the nose centre's: the control point's offset taken off.
    let (ox, oz) = kim_control_offset();
    let moves: Vec<(f64, f64)> = cut_points_xz(&canon)
        .into_iter()
        .map(|(x, z)| (x - ox, z - oz))
        .collect();
    // The first feed is the plunge from the retract height to the start.
    let cut = &moves[1..];
    assert!(cut.len() >= 10, "{} cutting moves", cut.len());
    // rs274 prints 4 decimals: each coordinate is within 0.5e-4 mm; the
    // middles of arcs as rs274 turns them lie on the curve too.
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
fn program_path_stays_within_the_path_tolerance() {
    // The program carries 5 decimals (10 nm resolution). Every programmed
    // point, and every point along every line and arc between them (arcs
    // read back from their G2/G3 words and I K centres), must lie within
    // the strategy's 10 nm path tolerance of the exact wheel-centre curve,
    // plus rounding.
    let program = kim_convex_program();
    let (ox, oz) = kim_control_offset();
    let (mut x, mut z) = (f64::NAN, f64::NAN);
    let mut motion = "";
    // (start, end, arc centre and direction if an arc) of each cutting move.
    let mut cuts = Vec::new();
    for line in program.lines().filter(|l| !l.starts_with('(')) {
        let (x0, z0) = (x, z);
        let (mut i, mut k) = (0.0, 0.0);
        for w in line.split_whitespace() {
            match w {
                "G0" | "G1" | "G2" | "G3" => motion = w,
                _ => {}
            }
            let num = |v: &str| v.parse::<f64>().expect("number");
            if let Some(v) = w.strip_prefix('X') {
                x = num(v)
            } else if let Some(v) = w.strip_prefix('Z') {
                z = num(v)
            } else if let Some(v) = w.strip_prefix('I') {
                i = num(v)
            } else if let Some(v) = w.strip_prefix('K') {
                k = num(v)
            }
        }
        if (x, z) == (x0, z0) || motion == "G0" || x0.is_nan() {
            continue;
        }
        let arc = match motion {
            "G2" => Some(((x0 + i, z0 + k), false)),
            "G3" => Some(((x0 + i, z0 + k), true)),
            _ => None,
        };
        // As the nose centre's: the control point's offset taken off
        // (arc centres too; I and K are from the start, so unchanged).
        let c = |(px, pz): (f64, f64)| (px - ox, pz - oz);
        cuts.push((c((x0, z0)), c((x, z)), arc.map(|(p, ccw)| (c(p), ccw))));
    }
    let arcs = cuts.iter().filter(|c| c.2.is_some()).count();
    assert!(arcs > 0, "no arcs fitted");
    // The first cuts are the approach straight down to the start (through
    // the air, then the last clearance at the feed): X does not move.
    let start = cuts
        .iter()
        .position(|c| c.0.0 != c.1.0)
        .unwrap_or(cuts.len());
    let rounding = 0.5e-5 * 2.0;
    let mut worst: f64 = 0.0;
    for &((x0, z0), (x1, z1), arc) in &cuts[start..] {
        for step in 0..=32 {
            let t = step as f64 / 32.0;
            let (px, pz) = match arc {
                None => (x0 + t * (x1 - x0), z0 + t * (z1 - z0)),
                Some(((cx, cz), ccw)) => {
                    // G18: counter-clockwise from Z towards X.
                    let a0 = (x0 - cx).atan2(z0 - cz);
                    let a1 = (x1 - cx).atan2(z1 - cz);
                    let tau = 2.0 * std::f64::consts::PI;
                    let sweep = if ccw {
                        (a1 - a0).rem_euclid(tau)
                    } else {
                        -(a0 - a1).rem_euclid(tau)
                    };
                    let r0 = ((x0 - cx).powi(2) + (z0 - cz).powi(2)).sqrt();
                    let r1 = ((x1 - cx).powi(2) + (z1 - cz).powi(2)).sqrt();
                    let (a, r) = (a0 + t * sweep, r0 + t * (r1 - r0));
                    (cx + r * a.sin(), cz + r * a.cos())
                }
            };
            worst = worst.max((pz - kim_centre_z_at(px)).abs());
        }
    }
    assert!(worst <= 10e-6 + rounding, "the path strays {worst} mm");
}

#[test]
fn fts_program_passes_rs274() {
    // A fast-tool-servo spiral over four of seed 003's lenslets: rs274 reads
    // every move; X falls along the spiral while C rises; the nose-centre
    // heights it reports are the servo's command, as its table holds it.
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
    // The machine gives its servo an axis of its own, W (the tool tip at
    // Z + W). The standalone interpreter enables X Y Z A B C only (its
    // canon, `saicanon.cc`, answers a fixed axis mask): "Bad character
    // 'w' used". A lathe program in G18 writes no Y, so the servo's words
    // are given to it as Y, every other word as written, and the tip read
    // as Z + Y.
    let program = std::fs::read_to_string(dir.path().join("corner_fts.ngc")).expect("program");
    let servo_words = program
        .lines()
        .filter(|l| !l.starts_with('('))
        .filter(|l| l.split_whitespace().any(|w| w.starts_with('W')))
        .count();
    assert!(servo_words > 1000, "the servo written on W: {servo_words}");
    assert!(
        !program
            .lines()
            .any(|l| !l.starts_with('(') && l.contains('Y'))
    );
    let as_y: String = program
        .lines()
        .map(|l| {
            if l.starts_with('(') {
                l.to_string()
            } else {
                l.replace(" W", " Y")
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    let translated = dir.path().join("corner_fts_y.ngc");
    std::fs::write(&translated, as_y + "\n").expect("write");
    let canon = interpret(&translated);
    // The slide at 0 from the plunge on, while the servo cuts; the tip
    // (put in Z's place for what follows) is Z + W.
    let moves: Vec<Vec<f64>> = feed_axes(&canon)
        .into_iter()
        .map(|mut m| {
            assert_eq!(m[2], 0.0, "the slide holds still: {m:?}");
            m[2] += m[1];
            m
        })
        .collect();
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
    // The servo is led by the program (`feed_forward: none`): what it is
    // sent is the led command, which the servo table of the same job in
    // the table-writing dialect holds too, row for row (rs274 prints 4
    // decimals).
    let table_dir = tempfile::tempdir().expect("tmp");
    let out = lensc(
        &root(),
        &[
            "build",
            "tests/jobs/fts_small_array.lens",
            "--dialect",
            "ultra_precision_lathe_gcode",
            "--out",
            table_dir.path().to_str().expect("utf8"),
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let table = std::fs::read_to_string(table_dir.path().join("corner_fts.fts")).expect("table");
    let rows: Vec<f64> = table
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| l.split(' ').nth(2).expect("W").parse().expect("number"))
        .collect();
    assert_eq!(rows.len(), points, "one row per point");
    let (table_lo, table_hi) = rows
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &w| {
            (a.min(w), b.max(w))
        });
    assert!((lo - table_lo).abs() < 6e-5, "{lo} {table_lo}");
    assert!((hi - table_hi).abs() < 6e-5, "{hi} {table_hi}");
    // And the command spans the path the report gives.
    let fa = &report["toolpath"]["fast_axis"];
    assert!(lo <= fa["w_min_mm"].as_f64().expect("min") + 6e-5, "{lo}");
    assert!(hi >= fa["w_max_mm"].as_f64().expect("max") - 6e-5, "{hi}");
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
