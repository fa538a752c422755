//! Tests of the number printer: fixed decimals, rounding and the shortest form.

use super::*;

fn f(v: f64, d: u32) -> String {
    let mut s = String::new();
    assert!(push_fixed(&mut s, v, d));
    s
}

#[test]
fn prints_canonical_fixed_point() {
    assert_eq!(f(1.6, 4), "1.6");
    assert_eq!(f(0.0, 4), "0.");
    assert_eq!(f(-0.0, 4), "0.");
    assert_eq!(f(-0.00001, 4), "0.");
    assert_eq!(f(-0.25, 4), "-0.25");
    assert_eq!(f(12.000_05, 4), "12.0001");
    assert_eq!(f(0.000_123_4, 6), "0.000123");
    assert_eq!(f(3.0, 0), "3.");
    assert_eq!(f(1e-9, 6), "0.");
}

#[test]
fn refuses_non_finite() {
    let mut s = String::new();
    assert!(!push_fixed(&mut s, f64::NAN, 4));
    assert!(!push_fixed(&mut s, f64::INFINITY, 4));
    assert!(!push_fixed(&mut s, 1e300, 4));
    assert!(s.is_empty());
}

#[test]
fn decimals_follow_resolution() {
    assert_eq!(decimals_for(1e-4), 4);
    assert_eq!(decimals_for(1e-6), 6);
    assert_eq!(decimals_for(1e-3), 3);
    assert_eq!(decimals_for(5e-5), 5);
}

/// `{:.N}` of the rounded value (`n` units), trimmed as the writer
/// trims: trailing zeros off, the point kept. Exact for |n| < 2^52:
/// the nearest double to n/10^N is within a hair of it.
fn std_fixed(n: i64, d: u32) -> String {
    let s = format!("{:.*}", d as usize, n as f64 / 10f64.powi(d as i32));
    if d == 0 {
        s + "."
    } else {
        s.trim_end_matches('0').to_string()
    }
}

/// The same from integer arithmetic alone, for any `i64` and up to
/// 18 decimals.
fn int_fixed(n: i64, d: u32) -> String {
    let p = 10u64.pow(d);
    let mag = n.unsigned_abs();
    let frac = format!("{:0w$}", mag % p, w = d as usize);
    let sign = if n < 0 { "-" } else { "" };
    format!(
        "{sign}{}.{}",
        mag / p,
        if d == 0 {
            ""
        } else {
            frac.trim_end_matches('0')
        }
    )
}

fn printed(n: i64, d: u32) -> String {
    String::from_utf8(print_units(n, d).as_bytes().to_vec()).expect("ASCII")
}

/// What the printer must keep to: `std_fixed`, the integer reference,
/// the final check's rules, the digit count.
fn check_printed(n: i64, d: u32) -> Result<(), proptest::test_runner::TestCaseError> {
    let p = print_units(n, d);
    let s = printed(n, d);
    if n.unsigned_abs() < 1 << 52 {
        proptest::prop_assert_eq!(&s, &std_fixed(n, d), "{} units at {} decimals", n, d);
    }
    proptest::prop_assert_eq!(&s, &int_fixed(n, d));
    proptest::prop_assert!(
        crate::post::writer::check_number(p.as_bytes()).is_ok(),
        "{}",
        s
    );
    proptest::prop_assert_eq!(p.digits, s.bytes().filter(u8::is_ascii_digit).count());
    Ok(())
}

#[test]
fn carries_signs_and_the_short_printers_edges() {
    // 0.9999995 rounds up through every digit.
    assert_eq!(f(0.999_999_5, 6), "1.");
    assert_eq!(f(-9.999_999_5, 6), "-10.");
    assert_eq!(f(99_999_999.999_999_5, 6), "100000000.");
    assert_eq!(f(-0.000_000_4, 6), "0.");
    assert_eq!(f(-0.000_000_6, 6), "-0.000001");
    // Where the eight-digit printer hands over to the general one.
    for n in [
        99_999_999_999_999_999,
        100_000_000_000_000_000,
        9_999_999_999_999_999,
        99_999_999 * 100 + 99,
        100_000_000 * 100,
        -99_999_999 * 100,
        -100_000_000 * 100,
        123_456_789,
        1,
        -1,
        0,
        i64::MAX,
        i64::MIN,
    ] {
        for d in 0..=18 {
            check_printed(n, d).unwrap_or_else(|e| panic!("{e}"));
        }
    }
}

/// Values at and around the half unit, where rounding turns.
fn near_half() -> impl proptest::strategy::Strategy<Value = (f64, u32)> {
    use proptest::prelude::*;
    (-10_000_000_000i64..10_000_000_000, 0u32..=9, -2i32..=2).prop_map(|(k, d, nudge)| {
        let v = (k as f64 + 0.5) / 10f64.powi(d as i32);
        let mut b = v.to_bits() as i64 + nudge as i64;
        if v == 0.0 {
            b = 0;
        }
        (f64::from_bits(b as u64), d)
    })
}

/// Values one half unit below a power of ten: carries through every digit.
fn near_carry() -> impl proptest::strategy::Strategy<Value = (f64, u32)> {
    use proptest::prelude::*;
    (0i32..=10, 0u32..=9, any::<bool>()).prop_map(|(j, d, neg)| {
        let v = 10f64.powi(j) - 0.5 / 10f64.powi(d as i32);
        (if neg { -v } else { v }, d)
    })
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(20_000))]

    /// Every value the writer is handed: rounded as `f64::round` rounds
    /// it, printed as `{:.N}` prints the rounded value.
    #[test]
    fn prints_what_std_prints_of_the_rounded_value(
        (v, d) in proptest::prop_oneof![
            (-1e9f64..1e9, 0u32..=9),
            (-1.0f64..1.0, 0u32..=9),
            (-1e-6f64..1e-6, 0u32..=9),
            near_half(),
            near_carry(),
            (proptest::num::f64::ANY, 0u32..=9),
        ]
    ) {
        let scaled = (v * 10f64.powi(d as i32)).round();
        let expected = (scaled.is_finite() && scaled.abs() < 1e18).then_some(scaled as i64);
        proptest::prop_assert_eq!(fixed_units(v, d), expected, "{} at {} decimals", v, d);
        if let Some(n) = expected {
            check_printed(n, d)?;
            let mut s = String::new();
            proptest::prop_assert!(push_fixed(&mut s, v, d));
            proptest::prop_assert_eq!(s, printed(n, d));
        }
    }

    /// Any unit count at any number of decimals the formatter takes.
    #[test]
    fn prints_any_unit_count(
        n in proptest::prop_oneof![
            proptest::num::i64::ANY,
            -1_000_000_000_000i64..1_000_000_000_000,
            -1_000_000i64..1_000_000,
        ],
        d in 0u32..=18,
    ) {
        check_printed(n, d)?;
    }
}

/// The digits of `v` (below 10^8) by division, one a byte, the first in
/// the lowest byte.
fn digits_by_division(mut v: u32) -> u64 {
    let mut word = 0u64;
    for i in (0..8).rev() {
        word |= u64::from(v % 10) << (8 * i);
        v /= 10;
    }
    word
}

#[test]
fn eight_digits_are_the_decimal_digits() {
    let edges = (0..10_000).chain((0..10_000).map(|k| 99_999_999 - k));
    for v in edges.chain((0..100_000_000).step_by(997)) {
        assert_eq!(eight_digits(v), digits_by_division(v), "{v}");
    }
}

#[test]
fn sixteen_digits_are_eight_and_eight() {
    // Every value below 10^8, as the integer part and as the decimals
    // (each paired with a different other half).
    for v in 0..100_000_000u32 {
        let other = 99_999_999 - v;
        assert_eq!(
            sixteen_digits(v, other),
            (eight_digits(v), eight_digits(other)),
            "{v}"
        );
    }
}

/// The rounding's shortcut (add the largest double below one half, with
/// the value's sign, and truncate) is `f64::round`, half away from zero,
/// at every tie k + 1/2 and the doubles on either side of it, in every
/// binade up to 2^53 and past it, both signs, and at whole numbers and
/// their neighbours.
#[test]
fn round_half_away_is_f64_round() {
    let reference = |x: f64| x.round() as i64;
    let mut checked = 0;
    for e in 0..=60 {
        let base = 2f64.powi(e);
        for k in [0.0, 1.0, 2.0, 3.0, 7.0, 1e3] {
            for frac in [0.0, 0.25, 0.5, 0.75] {
                let v = base + k + frac;
                for x in [v, v.next_up(), v.next_down()] {
                    for x in [x, -x] {
                        if x.abs() < 1e18 {
                            assert_eq!(round_half_away(x), reference(x), "{x:e}");
                            checked += 1;
                        }
                    }
                }
            }
        }
    }
    // Below one: zero, one half and its neighbours, the smallest values.
    for x in [
        0.0,
        -0.0,
        0.5,
        0.5f64.next_up(),
        0.5f64.next_down(),
        BELOW_HALF,
        f64::MIN_POSITIVE,
        5e-324,
        1.5,
        2.5,
        1e18f64.next_down(),
    ] {
        for x in [x, -x] {
            assert_eq!(round_half_away(x), reference(x), "{x:e}");
            checked += 1;
        }
    }
    assert!(checked > 4000);
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(20_000))]

    /// The same at random doubles below 1e18 and at random ties and
    /// their neighbours.
    #[test]
    fn round_half_away_is_f64_round_anywhere(
        x in proptest::prop_oneof![
            // Any finite double, taken below 1e18 by the remainder
            // (exact, and the double itself when it is below already).
            proptest::strategy::Strategy::prop_map(proptest::num::f64::ANY, |x| {
                if x.is_finite() { x % 1e18 } else { 0.5 }
            }),
            proptest::strategy::Strategy::prop_map(
                (-1_000_000_000_000i64..1_000_000_000_000, -1i32..=1),
                |(k, step)| {
                    let tie = k as f64 + 0.5;
                    match step {
                        -1 => tie.next_down(),
                        1 => tie.next_up(),
                        _ => tie,
                    }
                },
            ),
        ]
    ) {
        proptest::prop_assert_eq!(round_half_away(x), x.round() as i64, "{:e}", x);
    }
}
