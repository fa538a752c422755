//! Tests of the servo model: responses, limits and following error.

use super::*;

/// mm/s per m/min.
const M_PER_MIN: f64 = 1000.0 / 60.0;

/// The paper's servo from its frequency-response plot. Fixtures:
/// resonance 1367 Hz and resonant peak +1.0 dB, Hashimoto & Yan 2025
/// §3.4 ("the resonant frequency ω_r was 1367 Hz, and the resonant peak
/// M_p was +1.0 dB", Fig. 13).
fn paper_servo() -> SecondOrderServo {
    SecondOrderServo::from_resonance(1367.0, 1.0).unwrap()
}

#[test]
fn settling_offset_of_seed_003_lenslet_is_3_7_um() {
    // §3.5: "For a surface speed of 5 m/min applied to a 20 mm radius
    // dimple with a 1.7 mm diameter, the offset amount was determined to
    // be 3.7 μm ... considering the minimum settling time of 0.001 s".
    let h = settling_offset(20.0, 1.7, 5.0 * M_PER_MIN, 0.001).unwrap();
    let microns = h * 1e3;
    assert_eq!(
        (microns * 10.0).round(),
        37.0,
        "h_offset = {microns:.6} µm ({h:e} mm)"
    );
    // The difference-of-roots form of eq. 6 gives the same value.
    let naive = (20f64.powi(2) - 0.85f64.powi(2)).sqrt()
        - (20f64.powi(2) - (0.85 + 5.0 * M_PER_MIN * 0.001).powi(2)).sqrt();
    assert!((h - naive).abs() < 1e-12, "{h} vs {naive}");
}

#[test]
fn settling_offset_rejects_bad_geometry() {
    // Aperture edge plus travel past the sphere's equator.
    assert_eq!(settling_offset(1.0, 1.8, 200.0, 0.001), None);
    assert_eq!(settling_offset(1.0, 2.2, 0.0, 0.001), None);
    assert_eq!(settling_offset(0.0, 1.7, 83.3, 0.001), None);
    assert_eq!(settling_offset(-20.0, 1.7, 83.3, 0.001), None);
    assert_eq!(settling_offset(20.0, 0.0, 83.3, 0.001), None);
    assert_eq!(settling_offset(20.0, 1.7, -83.3, 0.001), None);
    assert_eq!(settling_offset(20.0, 1.7, 83.3, -0.001), None);
    assert_eq!(settling_offset(20.0, 1.7, f64::NAN, 0.001), None);
    assert_eq!(settling_offset(f64::INFINITY, 1.7, 83.3, 0.001), None);
    // No travel while settling: no offset.
    assert_eq!(settling_offset(20.0, 1.7, 0.0, 0.001), Some(0.0));
    assert_eq!(settling_offset(1.0, 2.0, 0.0, 0.0), Some(0.0));
}

#[test]
fn paper_resonance_gives_paper_damping_and_natural_frequency() {
    // §3.4: "damping ratios of 0.523 and 0.855 were derived ... the
    // damping ratio of this system can be approximated as 0.523 ... the
    // natural frequency ω_n can also be approximated as 2029 Hz".
    let servo = paper_servo();
    assert!(
        (servo.damping - 0.523).abs() < 5e-4,
        "ζ = {}",
        servo.damping
    );
    // fn = 2029.90 Hz; the paper's 2029 is truncated, within 1 Hz.
    assert!(
        (servo.natural_frequency_hz - 2029.0).abs() < 1.0,
        "fn = {} Hz",
        servo.natural_frequency_hz
    );
    // The rejected root of eq. 3: ζ² = (1 + √(1 − 1/Mp²))/2 = 0.8525,
    // which the paper prints as 0.855.
    let peak = 10f64.powf(1.0 / 20.0);
    let other = ((1.0 + (1.0 - 1.0 / (peak * peak)).sqrt()) / 2.0).sqrt();
    assert!((other - 0.8525).abs() < 5e-4, "other root ζ = {other}");
}

#[test]
fn paper_overshoot_is_14_6_percent_not_16_4() {
    // Paper §3.4 / Fig. 15: "overshoot amount of 16.4%". NOT reproducible:
    // the step response of eq. 2 with ζ = 0.5227 (from 1367 Hz, +1.0 dB)
    // overshoots e^(−πζ/√(1−ζ²)) = 14.57 %, and with the paper's rounded
    // ζ = 0.523, 14.55 %. 16.4 % would need ζ = 0.499. The paper's own
    // measured overshoot in the linear (< 1 µm step) range, "between 14%
    // and 15%" (§3.4, Fig. 14d), agrees with the computed 14.6 %.
    let overshoot = paper_servo().overshoot();
    assert_eq!((overshoot * 1000.0).round(), 146.0, "overshoot {overshoot}");
    assert!((0.14..0.15).contains(&overshoot));
    // Fixture: ζ = 0.523, fn = 2029 Hz as printed in §3.4.
    let rounded = SecondOrderServo::from_natural(2029.0, 0.523).unwrap();
    assert_eq!((rounded.overshoot() * 1000.0).round(), 145.0);
}

#[test]
fn paper_settling_time_at_0_2_percent_is_1_ms() {
    // Paper §3.4: "settling time of 0.001 s when the determination range
    // was set at 0.2% of the step input". Reproduced to the paper's one
    // significant digit: 0.948 ms (exact) with fn = 2029.9 Hz, ζ = 0.5227.
    let servo = paper_servo();
    let settling = servo.settling_time(0.002).unwrap();
    assert_eq!(
        (settling * 1e3).round(),
        1.0,
        "0.2 % settling time {settling} s"
    );
    // 2 % band: entered for good on the recovery from the first undershoot
    // (2.1 % deep), at 0.606 ms; the 0.2 % band after the second overshoot.
    let settling_2 = servo.settling_time(0.02).unwrap();
    assert!(settling_2 < settling, "2 % settling time {settling_2} s");
}

#[test]
fn paper_eq_5_coefficients_take_fn_as_rad_per_s() {
    // Paper eq. 5: G(s) = 4.12e6 / (s² + 2121 s + 4.12e6). Its
    // coefficients are 2029² and 2·0.523·2029, i.e. ωn = 2029 rad/s,
    // whereas the text derives fn = 2029 Hz (ωn = 12 750 rad/s). Taken
    // literally, eq. 5 settles to 0.2 % in 5.96 ms, not 0.001 s; the
    // paper's 0.001 s belongs to the 2029 Hz model.
    let wn = 4.12e6f64.sqrt();
    let literal = SecondOrderServo::from_natural(wn / (2.0 * PI), 2121.0 / (2.0 * wn)).unwrap();
    let settling = literal.settling_time(0.002).unwrap();
    assert_eq!((settling * 1e3).round(), 6.0, "eq. 5 settling {settling} s");
    assert!((literal.damping - 0.523).abs() < 1e-3);
}

#[test]
fn simulated_unit_step_matches_closed_form() {
    // dt = 50 µs: the paper's FTS data acquisition at 20 kHz (§2).
    let servo = paper_servo();
    let dt = 1.0 / 20_000.0;
    let mut commanded = vec![1.0; 400];
    commanded[0] = 0.0;
    let positions = servo.simulate(&commanded, dt).unwrap();
    assert_eq!(positions.len(), commanded.len());
    assert_eq!(positions[0], 0.0);
    for (k, &y) in positions.iter().enumerate().skip(1) {
        let t = (k - 1) as f64 * dt;
        let exact = servo.step_response(t);
        assert!((y - exact).abs() < 1e-12, "k = {k}: {y} vs {exact}");
    }
}

#[test]
fn simulation_is_linear_and_holds_a_steady_command() {
    // Arbitrary fixture: a 3 µm step from 2 µm, paper servo, 20 kHz.
    let servo = paper_servo();
    let dt = 1.0 / 20_000.0;
    let commanded: Vec<f64> = (0..200)
        .map(|k| if k < 10 { 0.002 } else { 0.005 })
        .collect();
    let positions = servo.simulate(&commanded, dt).unwrap();
    for (k, &y) in positions.iter().enumerate() {
        // Command 10 is the first of the new level, held from t = 10·dt.
        let expected = if k < 10 {
            0.002
        } else {
            0.002 + 0.003 * servo.step_response((k - 10) as f64 * dt)
        };
        assert!((y - expected).abs() < 1e-15, "k = {k}: {y} vs {expected}");
    }
    assert_eq!(servo.simulate(&[], dt), Some(Vec::new()));
}

#[test]
fn zero_order_hold_matches_matrix_exponential() {
    // Arbitrary fixture: paper servo, 20 kHz and 1 kHz sampling.
    // Reference: nalgebra's Padé matrix exponential of the augmented
    // matrix [[A, B], [0, 0]] dt, whose top blocks are Φ and Γ.
    let servo = paper_servo();
    let wn = servo.natural_angular_frequency();
    let z = servo.damping;
    for dt in [5e-5, 1e-3] {
        let augmented = nalgebra::Matrix3::new(
            0.0,
            1.0,
            0.0,
            -wn * wn,
            -2.0 * z * wn,
            wn * wn,
            0.0,
            0.0,
            0.0,
        ) * dt;
        let reference = augmented.exp();
        let (phi, gamma) = servo.zero_order_hold(dt);
        for (i, j) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
            let scale = reference[(i, j)].abs().max(1.0);
            assert!(
                (phi[(i, j)] - reference[(i, j)]).abs() < 1e-12 * scale,
                "dt {dt}, Φ[{i},{j}]: {} vs {}",
                phi[(i, j)],
                reference[(i, j)]
            );
        }
        for i in 0..2 {
            let scale = reference[(i, 2)].abs().max(1.0);
            assert!(
                (gamma[i] - reference[(i, 2)]).abs() < 1e-12 * scale,
                "dt {dt}, Γ[{i}]: {} vs {}",
                gamma[i],
                reference[(i, 2)]
            );
        }
    }
}

#[test]
fn step_response_starts_at_rest_and_settles_to_the_command() {
    let servo = paper_servo();
    assert_eq!(servo.step_response(-1.0), 0.0);
    assert_eq!(servo.step_response(0.0), 0.0);
    assert!(servo.step_response(1e-9) < 1e-6);
    assert!((servo.step_response(0.1) - 1.0).abs() < 1e-12);
}

#[test]
fn overshoot_is_the_peak_of_the_step_response() {
    // Arbitrary fixtures: the paper servo and two other dampings.
    for servo in [
        paper_servo(),
        SecondOrderServo::from_natural(500.0, 0.1).unwrap(),
        SecondOrderServo::from_natural(3000.0, 0.9).unwrap(),
    ] {
        let period = 1.0 / servo.natural_frequency_hz;
        let steps = 200_000;
        let peak = (0..=steps)
            .map(|i| servo.step_response(5.0 * period * i as f64 / steps as f64))
            .fold(f64::NEG_INFINITY, f64::max);
        let overshoot = servo.overshoot();
        assert!(
            (peak - 1.0 - overshoot).abs() < 1e-9,
            "ζ {}: grid peak {peak}, overshoot {overshoot}",
            servo.damping
        );
    }
}

#[test]
fn response_stays_in_band_after_settling_time_and_leaves_it_just_before() {
    // Bands: the paper's 0.2 % and the usual 2 %, plus a tight one;
    // servos: the paper's and an arbitrary light and heavy damping.
    for servo in [
        paper_servo(),
        SecondOrderServo::from_natural(500.0, 0.1).unwrap(),
        SecondOrderServo::from_natural(3000.0, 0.9).unwrap(),
    ] {
        for band in [0.002, 0.02, 1e-6] {
            let settling = servo.settling_time(band).unwrap();
            let error = |t: f64| (servo.step_response(t) - 1.0).abs();
            assert!(
                (error(settling) - band).abs() < 1e-9 * band.max(1e-3),
                "ζ {} band {band}: error {} at {settling}",
                servo.damping,
                error(settling)
            );
            assert!(
                error(settling * (1.0 - 1e-9)) > band,
                "ζ {} band {band}: inside before {settling}",
                servo.damping
            );
            let period = 1.0 / servo.natural_frequency_hz;
            for i in 0..=100_000 {
                let t = settling + 20.0 * period * i as f64 / 100_000.0;
                assert!(
                    error(t) <= band * (1.0 + 1e-9),
                    "ζ {} band {band}: error {} at {t} after settling {settling}",
                    servo.damping,
                    error(t)
                );
            }
            // Tighter than the envelope bound e^(−ζωn t)/√(1 − ζ²) = band.
            let envelope = -(band * (1.0 - servo.damping.powi(2)).sqrt()).ln() / servo.decay_rate();
            assert!(settling <= envelope, "{settling} > envelope {envelope}");
        }
    }
}

#[test]
fn from_resonance_inverts_from_natural() {
    // Arbitrary fixtures with ζ < 1/√2 (a resonant peak exists).
    for (natural_frequency_hz, damping) in [(2029.0, 0.523), (100.0, 0.05), (5000.0, 0.7)] {
        let servo = SecondOrderServo::from_natural(natural_frequency_hz, damping).unwrap();
        let fr = servo.resonance_frequency_hz().unwrap();
        let peak = servo.resonant_peak_db().unwrap();
        let back = SecondOrderServo::from_resonance(fr, peak).unwrap();
        assert!(
            (back.natural_frequency_hz - natural_frequency_hz).abs() < 1e-9 * natural_frequency_hz,
            "fn {} vs {natural_frequency_hz}",
            back.natural_frequency_hz
        );
        assert!(
            (back.damping - damping).abs() < 1e-9,
            "ζ {} vs {damping}",
            back.damping
        );
    }
    // And the paper's plot reading round-trips the other way.
    let servo = paper_servo();
    assert!((servo.resonance_frequency_hz().unwrap() - 1367.0).abs() < 1e-9);
    assert!((servo.resonant_peak_db().unwrap() - 1.0).abs() < 1e-12);
}

#[test]
fn invalid_parameters_give_none() {
    for (f, z) in [
        (0.0, 0.5),
        (-1.0, 0.5),
        (f64::NAN, 0.5),
        (f64::INFINITY, 0.5),
        (1000.0, 0.0),
        (1000.0, -0.1),
        (1000.0, 1.0),
        (1000.0, 1.2),
        (1000.0, f64::NAN),
    ] {
        assert_eq!(SecondOrderServo::from_natural(f, z), None, "({f}, {z})");
    }
    for (f, db) in [
        (0.0, 1.0),
        (-1367.0, 1.0),
        (f64::NAN, 1.0),
        (1367.0, 0.0),
        (1367.0, -1.0),
        (1367.0, f64::NAN),
        (1367.0, f64::INFINITY),
        (1367.0, 1e-300),
    ] {
        assert_eq!(SecondOrderServo::from_resonance(f, db), None, "({f}, {db})");
    }
    // No resonant peak at ζ ≥ 1/√2.
    let heavy = SecondOrderServo::from_natural(1000.0, 0.8).unwrap();
    assert_eq!(heavy.resonance_frequency_hz(), None);
    assert_eq!(heavy.resonant_peak_db(), None);

    let servo = paper_servo();
    assert_eq!(servo.settling_time(0.0), None);
    assert_eq!(servo.settling_time(-0.002), None);
    assert_eq!(servo.settling_time(f64::NAN), None);
    assert_eq!(servo.settling_time(1.0), Some(0.0));
    assert_eq!(servo.simulate(&[0.0, 1.0], 0.0), None);
    assert_eq!(servo.simulate(&[0.0, 1.0], -1e-3), None);
    assert_eq!(servo.simulate(&[0.0, 1.0], f64::NAN), None);

    // A hand-built invalid model answers NaN / None, without panicking.
    let bad = SecondOrderServo {
        natural_frequency_hz: -5.0,
        damping: 2.0,
    };
    assert!(bad.step_response(1e-3).is_nan());
    assert!(bad.overshoot().is_nan());
    assert_eq!(bad.settling_time(0.002), None);
    assert_eq!(bad.simulate(&[0.0, 1.0], 1e-4), None);
    assert_eq!(bad.resonance_frequency_hz(), None);
}
