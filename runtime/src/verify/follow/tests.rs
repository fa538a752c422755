//! Tests of the following-error estimate.

use super::*;

fn servo() -> SecondOrderServo {
    SecondOrderServo::from_resonance(1367.0, 1.0).expect("seed 003's servo")
}

/// Points every `dt` on a circle of radius `r` at `rpm`, W given by
/// `w(t)`.
fn circle(r: f64, rpm: f64, dt: f64, n: usize, w: impl Fn(f64) -> f64) -> Vec<SpiralPoint> {
    let omega = rpm * 2.0 * std::f64::consts::PI / 60.0;
    (0..n)
        .map(|k| {
            let t = k as f64 * dt;
            SpiralPoint {
                x: r,
                c: omega * t,
                w: w(t),
                t,
            }
        })
        .collect()
}

#[test]
fn a_held_command_is_followed_exactly() {
    let mut sim = FollowingSimulation::new(&servo(), 20e3, &[], RadialBins::new(0.0, 10.0, 4))
        .expect("valid");
    sim.extend(&circle(5.0, 100.0, 1e-3, 200, |_| 0.25));
    let f = sim.finish();
    assert!(f.samples > 3900);
    assert!(f.max_error < 1e-15, "{}", f.max_error);
}

#[test]
fn streaming_matches_the_batch_servo_response() {
    // Points exactly on the servo's samples, the radius falling from 5
    // to 3 mm: the streamed errors are the batch simulation's response
    // minus the command, sample for sample, however the points are
    // split into chunks; each radial bin holds the least and largest
    // of the errors at its radii.
    let dt = 1.0 / 20e3;
    let w = |t: f64| 0.002 * (2.0 * std::f64::consts::PI * 300.0 * t).sin();
    let mut pts = circle(5.0, 100.0, dt, 2000, w);
    for (k, p) in pts.iter_mut().enumerate() {
        p.x = 5.0 - 2.0 * k as f64 / 2000.0;
    }
    let bins = RadialBins::new(2.55, 5.55, 30);
    let mut sim = FollowingSimulation::new(&servo(), 20e3, &[], bins.clone()).expect("valid");
    for chunk in pts.chunks(37) {
        sim.extend(chunk);
    }
    let f = sim.finish();
    let commands: Vec<f64> = pts.iter().map(|p| p.w).collect();
    let batch = servo().simulate(&commands, dt).expect("valid");
    let mut want = bins;
    for k in 0..pts.len() - 1 {
        want.add(pts[k].x, batch[k] - commands[k]);
    }
    assert_eq!(f.samples, pts.len() - 1);
    let used = want.bins.iter().filter(|b| b.samples > 0).count();
    assert_eq!(used, 21, "radii 3.001 to 5 mm: bins 4 to 24");
    for (k, (got, want)) in f.by_radius.bins.iter().zip(&want.bins).enumerate() {
        assert_eq!(got.samples, want.samples, "bin {k}");
        if want.samples > 0 {
            assert!(
                (got.min - want.min).abs() < 1e-15,
                "bin {k}: {got:?} {want:?}"
            );
            assert!(
                (got.max - want.max).abs() < 1e-15,
                "bin {k}: {got:?} {want:?}"
            );
        }
    }
    let peak = f
        .by_radius
        .bins
        .iter()
        .map(|b| b.max.max(-b.min))
        .fold(0.0, f64::max);
    assert_eq!(peak, f.max_error, "the bins keep the largest error");
    // 300 Hz on a 1367 Hz servo: a real, visible lag.
    assert!(f.max_error > 1e-5, "{}", f.max_error);
}

#[test]
fn radial_bins_cover_their_range_and_clamp_beyond_it() {
    let mut b = RadialBins::new(1.0, 3.0, 4);
    assert_eq!(b.index(1.0), 0);
    assert_eq!(b.index(1.49), 0);
    assert_eq!(b.index(1.5), 1);
    assert_eq!(b.index(2.99), 3);
    assert_eq!(b.index(3.0), 3);
    assert_eq!(b.index(-7.0), 0);
    assert_eq!(b.index(f64::NAN), 0);
    assert_eq!(b.span(1), (1.5, 2.0));
    b.add(2.2, 4e-6);
    b.add(2.3, -1e-6);
    assert_eq!(
        b.bins[2],
        ErrorBin {
            samples: 2,
            min: -1e-6,
            max: 4e-6
        }
    );
    assert_eq!(b.bins[0].samples, 0);
    let empty = RadialBins::new(2.0, 2.0, 0);
    assert_eq!(empty.bins.len(), 1);
    assert!(empty.to > empty.from);
}

#[test]
fn errors_are_gathered_by_the_lenslet_under_the_tool() {
    // Two lenslets on the circle's path, at c = 0 and c = π; the
    // command wobbles fast only where the tool is over the second.
    let r = 5.0;
    let feats = [(r, 0.0, 0.5), (-r, 0.0, 0.5)];
    let omega = 100.0 * 2.0 * std::f64::consts::PI / 60.0;
    let w = |t: f64| {
        let c = (omega * t).rem_euclid(2.0 * std::f64::consts::PI);
        if (c - std::f64::consts::PI).abs() < 0.09 {
            0.001 * (2.0 * std::f64::consts::PI * 2000.0 * t).sin()
        } else {
            0.0
        }
    };
    let mut sim = FollowingSimulation::new(&servo(), 20e3, &feats, RadialBins::new(4.0, 6.0, 10))
        .expect("valid");
    sim.extend(&circle(r, 100.0, 1e-5, 60_000, w));
    let f = sim.finish();
    let (a, b) = (&f.lenslets[0], &f.lenslets[1]);
    // Each lenslet spans 2 asin(0.5/(2·5)) ≈ 0.1 rad of the turn.
    assert!(
        a.samples > 100 && b.samples > 100,
        "{} {}",
        a.samples,
        b.samples
    );
    assert!(a.max_error < 1e-12, "{}", a.max_error);
    assert!(b.max_error > 1e-5 && b.waviness > 0.0);
    assert!((b.radius - r).abs() < 1e-12);
    let binned: u64 = f.by_radius.bins.iter().map(|b| b.samples).sum();
    assert_eq!(binned as usize, f.samples);
    assert_eq!(f.by_radius.bins[5].samples, binned, "all at r = 5 mm");
}
