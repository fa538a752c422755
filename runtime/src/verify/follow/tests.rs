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

/// The per-sample loop as it was before the moves were split by kind
/// (one loop testing every condition per sample): the reference the
/// split loops must match bit for bit.
fn extend_one_loop(sim: &mut FollowingSimulation, points: &[SpiralPoint]) {
    for &p in points {
        let Some(q) = sim.last else {
            sim.state = Some(Vector2::new(p.w, 0.0));
            sim.t0 = p.t;
            sim.next = p.t;
            sim.last = Some(p);
            continue;
        };
        let span = p.t - q.t;
        if span > 0.0 {
            let (xq, yq) = (q.x * q.c.cos(), q.x * q.c.sin());
            let (xp, yp) = (p.x * p.c.cos(), p.x * p.c.sin());
            let chord = (xp - xq).hypot(yp - yq);
            let arc = 0.5 * (p.x + q.x).abs() * (p.c - q.c).abs();
            let step = chord.max(arc).max(1e-12) / span * sim.dt;
            let cm = 0.5 * (p.c + q.c);
            let xm = 0.5 * (p.x + q.x);
            let lenslet = sim.lenslet_at(xm * cm.cos(), xm * cm.sin());
            let (mut pos, mut vel) = (sim.state.unwrap().x, sim.state.unwrap().y);
            let per_second = 1.0 / span;
            let dw = p.w - q.w;
            let mut acc = lenslet.map(|i| (i, 0usize, 0.0f64, 0.0f64, 0.0f64));
            let bin = sim.by_radius.index(q.x.abs());
            let one_bin = q.x * p.x >= 0.0 && sim.by_radius.index(p.x.abs()) == bin;
            let (mut n, mut lo, mut hi) = (0u64, f64::INFINITY, f64::NEG_INFINITY);
            while sim.next < p.t {
                let f = (sim.next - q.t) * per_second;
                let command = q.w + f * dw;
                let error = pos - command;
                let radius = || (q.x + f * (p.x - q.x)).abs();
                if error.abs() > sim.max_error {
                    sim.max_error = error.abs();
                    sim.max_error_at = radius();
                }
                if one_bin {
                    n += 1;
                    lo = lo.min(error);
                    hi = hi.max(error);
                } else {
                    sim.by_radius.add(radius(), error);
                }
                if let Some((_, n, max, sum2, slope2)) = acc.as_mut() {
                    *n += 1;
                    *max = max.max(error.abs());
                    *sum2 += error * error;
                    if let Some(e0) = sim.last_error {
                        let slope = (error - e0) / step;
                        *slope2 += slope * slope;
                    }
                }
                sim.last_error = Some(error);
                let v0 = vel;
                (pos, vel) = (
                    sim.phi[(0, 0)] * pos + sim.phi[(0, 1)] * vel + sim.gamma[0] * command,
                    sim.phi[(1, 0)] * pos + sim.phi[(1, 1)] * vel + sim.gamma[1] * command,
                );
                if (vel - v0).abs() / sim.dt > sim.max_acceleration {
                    sim.max_acceleration = (vel - v0).abs() / sim.dt;
                    sim.max_acceleration_at = radius();
                }
                sim.k += 1;
                sim.next = sim.t0 + sim.k as f64 * sim.dt;
            }
            if n > 0 {
                sim.by_radius.add_many(bin, n, lo, hi);
            }
            if let Some((i, n, max, sum2, slope2)) = acc {
                let a = &mut sim.acc[i];
                a.samples += n;
                a.max = a.max.max(max);
                a.sum2 += sum2;
                a.slope2 += slope2;
            }
            sim.state = Some(Vector2::new(pos, vel));
        }
        sim.last = Some(p);
    }
}

#[test]
fn the_loops_by_kind_of_move_match_one_loop_bit_for_bit() {
    // A spiral crossing the axis over a ring of lenslets, its points at
    // uneven times (moves shorter and longer than a sample, some of no
    // duration), a command wobbling over the lenslets: every kind of
    // move (in one bin of radius or across bins, over a lenslet or
    // not) occurs, and every figure must be the same bits.
    let feats: Vec<(f64, f64, f64)> = (0..12)
        .map(|i| {
            let a = i as f64 * std::f64::consts::PI / 6.0;
            let r = 1.0 + 0.25 * (i % 3) as f64;
            (r * a.cos(), r * a.sin(), 0.3)
        })
        .collect();
    let mut t = 0.0;
    let pts: Vec<SpiralPoint> = (0..40_000)
        .map(|k| {
            let s = k as f64 / 40_000.0;
            // Times from 0.2 to 3 samples apart, some repeated.
            t += if k % 97 == 0 {
                0.0
            } else {
                (0.2 + 2.8 * ((k * 7919) % 101) as f64 / 100.0) / 20e3
            };
            let x = 1.6 - 1.9 * s;
            let c = 40.0 * std::f64::consts::PI * s;
            let (px, py) = (x * c.cos(), x * c.sin());
            let over = feats
                .iter()
                .map(|f| (px - f.0).hypot(py - f.1))
                .fold(f64::INFINITY, f64::min);
            let w = if over < 0.3 {
                0.002 * (over * 40.0).cos()
            } else {
                0.0
            };
            SpiralPoint { x, c, w, t }
        })
        .collect();
    let bins = RadialBins::new(0.0, 1.7, 37);
    let mut by_kind = FollowingSimulation::new(&servo(), 20e3, &feats, bins.clone()).unwrap();
    let mut one_loop = FollowingSimulation::new(&servo(), 20e3, &feats, bins).unwrap();
    for chunk in pts.chunks(1013) {
        by_kind.extend(chunk);
        extend_one_loop(&mut one_loop, chunk);
    }
    let (a, b) = (by_kind.finish(), one_loop.finish());
    assert!(a.samples > 50_000 && a.lenslets.iter().all(|l| l.samples > 0));
    assert!(a.by_radius.bins.iter().filter(|b| b.samples > 0).count() > 30);
    // Debug prints each float's shortest round trip: equal text, equal bits.
    assert_eq!(format!("{a:?}"), format!("{b:?}"));
}

/// The largest following error (mm) of the servo, led or not, along a
/// circle at radius 1 mm where W is a ripple of `amplitude` (mm) at `hz`
/// Hz (from rest), its points 73 µs apart (not on the 50 µs samples, so
/// that periods straddle points), streamed in chunks.
fn ripple_error(led: bool, amplitude: f64, hz: f64) -> f64 {
    let w = |t: f64| amplitude * (1.0 - (2.0 * std::f64::consts::PI * hz * t).cos());
    let every = 73e-6;
    let pts = circle(1.0, 100.0, every, (0.05 / every) as usize, w);
    let sim =
        FollowingSimulation::new(&servo(), 20e3, &[], RadialBins::new(0.0, 2.0, 4)).expect("valid");
    let mut sim = if led { sim.led(&servo()) } else { sim };
    for chunk in pts.chunks(7) {
        sim.extend(chunk);
    }
    sim.finish().max_error
}

#[test]
fn the_led_servo_tracks_its_commands() {
    // Issue #29: driven by the commands themselves the servo lags by its
    // delay, 2ζ/ωn and half a period times the velocity; led by its
    // inverse model it follows the same commands but for their corners,
    // where their velocity steps within a data period (the chords' sag,
    // A·(2πf)²·Δt²/8: 2.4 nm for 1 µm at 300 Hz, 0.3 nm for 5 µm at
    // 50 Hz, 12 nm for 5 µm at 300 Hz).
    for (amplitude, hz, lag_over, led_under) in [
        (1e-3, 300.0, 150e-6, 5e-6),
        (5e-3, 50.0, 100e-6, 1e-6),
        (5e-3, 300.0, 700e-6, 25e-6),
    ] {
        let lagging = ripple_error(false, amplitude, hz);
        let led = ripple_error(true, amplitude, hz);
        eprintln!(
            "{} um at {hz} Hz: as printed {} nm, led {} nm",
            amplitude * 1e3,
            lagging * 1e6,
            led * 1e6
        );
        assert!(lagging > lag_over, "{lagging}");
        assert!(led < led_under, "{led}");
    }
}

/// The largest following error (mm) along `ripple_error`'s ripple of the
/// servo unled, on the commands a program that leads it writes
/// (`machine::lead`), measured from the ripple itself.
fn program_led_ripple_error(amplitude: f64, hz: f64) -> f64 {
    let w = |t: f64| amplitude * (1.0 - (2.0 * std::f64::consts::PI * hz * t).cos());
    let every = 73e-6;
    let pts = circle(1.0, 100.0, every, (0.05 / every) as usize, w);
    let mut sim =
        FollowingSimulation::new(&servo(), 20e3, &[], RadialBins::new(0.0, 2.0, 4)).expect("valid");
    let mut lead = crate::machine::lead::ProgramLead::new(&servo(), 20e3, 1e-6);
    let (mut commands, mut path) = (Vec::new(), Vec::new());
    let aims = |path: &[SpiralPoint]| path.iter().map(|p| p.w).collect::<Vec<_>>();
    for chunk in pts.chunks(7) {
        lead.extend(chunk, &mut commands, &mut path);
        sim.extend_toward(&commands, &aims(&path));
    }
    lead.finish(&mut commands, &mut path);
    sim.extend_toward(&commands, &aims(&path));
    sim.finish().max_error
}

#[test]
fn a_servo_led_by_the_program_tracks_the_path() {
    // Issue #29: a servo with no feed-forward, driven by the commands the
    // program leads it by, follows the path about as closely as a servo
    // its controller leads (the same bounds as
    // `the_led_servo_tracks_its_commands`), where driven by the path
    // itself it lags microns.
    for (amplitude, hz, led_under) in [
        (1e-3, 300.0, 5e-6),
        (5e-3, 50.0, 1e-6),
        (5e-3, 300.0, 25e-6),
    ] {
        let lagging = ripple_error(false, amplitude, hz);
        let by_program = program_led_ripple_error(amplitude, hz);
        eprintln!(
            "{} um at {hz} Hz: as printed {} nm, led by the program {} nm, by the controller {} nm",
            amplitude * 1e3,
            lagging * 1e6,
            by_program * 1e6,
            ripple_error(true, amplitude, hz) * 1e6
        );
        assert!(by_program < led_under, "{by_program}");
        assert!(lagging > 20.0 * by_program, "{lagging} {by_program}");
    }
}

#[test]
fn a_led_held_command_is_followed_exactly() {
    // Nothing to lead: a held command is held, however the points fall
    // (to the rounding of the period's mean, a few femtometres).
    let sim = FollowingSimulation::new(&servo(), 20e3, &[], RadialBins::new(0.0, 10.0, 4))
        .expect("valid")
        .led(&servo());
    let mut sim = sim;
    sim.extend(&circle(5.0, 100.0, 1e-3, 200, |_| 0.25));
    let f = sim.finish();
    assert!(f.samples > 3900);
    assert!(f.max_error < 1e-12, "{}", f.max_error);
}

#[test]
fn errors_in_the_air_are_not_gathered() {
    // A step up to a plateau and back: driven as printed the servo lags
    // the step by microns. Cutting below the plateau, the moves held on it
    // (both ends at or above it) cut air and are not counted; the error
    // entering and leaving it is.
    let dt = 1.0 / 20e3;
    let w = |t: f64| if (0.01..0.02).contains(&t) { 0.01 } else { 0.0 };
    let pts = circle(1.0, 100.0, 4.0 * dt, 1000, w);
    let run = |air: Option<f64>| {
        let sim = FollowingSimulation::new(&servo(), 20e3, &[], RadialBins::new(0.0, 2.0, 4))
            .expect("valid");
        let mut sim = match air {
            Some(level) => sim.cutting_below(level),
            None => sim,
        };
        sim.extend(&pts);
        sim.finish()
    };
    let (all, cut) = (run(None), run(Some(0.01)));
    assert!(all.max_error > 1e-3, "{}", all.max_error);
    // Counted: the moves onto and off the plateau, not the ringing on it.
    assert!(cut.max_error > 1e-3, "{}", cut.max_error);
    let ringing_on_the_plateau = run(Some(0.0)).max_error;
    assert_eq!(ringing_on_the_plateau, 0.0);
    assert_eq!(run(Some(f64::INFINITY)).max_error, all.max_error);
}
