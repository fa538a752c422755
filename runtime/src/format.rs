//! The one canonical number formatter every dialect uses: round to a fixed
//! number of decimals as an integer, print it with `itoa`. It never prints
//! an exponent, `-0`, NaN or infinity (those are refused before this point).

/// Decimals needed to express `resolution` (mm), e.g. 0.1 µm → 4.
pub fn decimals_for(resolution: f64) -> u32 {
    let mut d = 0u32;
    while d < 9 && resolution * 10f64.powi(d as i32) < 0.999_999 {
        d += 1;
    }
    d
}

/// Appends `value` rounded to `decimals` places with trailing zeros
/// trimmed but the decimal point kept (`1.`, `0.`, `-0.25`): Fanuc-style
/// controllers read `X1` as one least increment, so the point is never
/// dropped. Returns false (and appends nothing) if the value is not
/// finite or does not fit in 18 digits.
pub fn push_fixed(out: &mut String, value: f64, decimals: u32) -> bool {
    match fixed_units(value, decimals) {
        Some(n) => {
            push_units(out, n, decimals);
            true
        }
        None => false,
    }
}

/// Powers of ten, exactly, for up to 18 decimals.
const POW10: [u64; 19] = {
    let mut t = [1u64; 19];
    let mut i = 1;
    while i < 19 {
        t[i] = t[i - 1] * 10;
        i += 1;
    }
    t
};

/// `value` in units of 10^−decimals, rounded half away from zero (what
/// `push_fixed` prints); `None` if it is not finite or does not fit in 18
/// digits. Two values print the same exactly when their units are equal.
#[inline]
pub fn fixed_units(value: f64, decimals: u32) -> Option<i64> {
    let scaled = value * POW10[decimals.min(18) as usize] as f64;
    // NaN fails the comparison. Rounding cannot cross 1e18: doubles that
    // large are spaced 128 apart, so they are whole numbers already.
    if !(scaled.abs() < 1e18) {
        return None;
    }
    Some(round_half_away(scaled))
}

/// `scaled.round() as i64` for |scaled| < 1e18, without the library call:
/// below 2^52 a double's distance from its truncation is exact, so the
/// comparison with one half is too; above, every double is whole.
#[inline]
fn round_half_away(scaled: f64) -> i64 {
    const WHOLE: f64 = 4_503_599_627_370_496.0; // 2^52
    let t = scaled as i64;
    if scaled.abs() >= WHOLE {
        return t;
    }
    let rest = scaled - t as f64;
    if rest >= 0.5 {
        t + 1
    } else if rest <= -0.5 {
        t - 1
    } else {
        t
    }
}

/// Room for the longest number `print_units` writes: a minus, 19 integer
/// digits (an `i64`'s magnitude) and the point; or a minus, `0.` and 18
/// decimals. A whole number of 8-byte words, so it is copied as such.
pub const PRINTED_ROOM: usize = 24;

/// Two-digit groups "00" to "99", for printing two digits a step.
const PAIRS: &[u8; 200] = b"\
0001020304050607080910111213141516171819\
2021222324252627282930313233343536373839\
4041424344454647484950515253545556575859\
6061626364656667686970717273747576777879\
8081828384858687888990919293949596979899";

/// A number as `push_units` writes it, printed at the start of a buffer
/// on the stack: ASCII digits, one point, perhaps a leading minus (never
/// on a zero: the minus is written only for a negative unit count).
#[derive(Clone, Copy)]
pub struct Printed {
    /// The number, then filler up to the buffer's end.
    pub room: [u8; PRINTED_ROOM],
    /// How many bytes of `room` are the number.
    pub len: usize,
    /// How many of them are digits (what a dialect's digit limit counts).
    pub digits: usize,
}

impl Printed {
    /// The printed bytes.
    #[inline]
    pub fn as_bytes(&self) -> &[u8] {
        &self.room[..self.len]
    }
}

/// Writes `v`'s digits right-aligned to end at `end`, two at a time.
/// Zero writes nothing.
#[inline]
fn digits_before(buf: &mut [u8; PRINTED_ROOM], end: usize, mut v: u64) {
    let mut pos = end;
    while v >= 100 {
        let pair = (v % 100) as usize * 2;
        v /= 100;
        pos -= 2;
        buf[pos..pos + 2].copy_from_slice(&PAIRS[pair..pair + 2]);
    }
    if v >= 10 {
        let pair = v as usize * 2;
        buf[pos - 2..pos].copy_from_slice(&PAIRS[pair..pair + 2]);
    } else if v > 0 {
        buf[pos - 1] = b'0' + v as u8;
    }
}

/// `n` units of 10^−decimals (at most 18) printed as `push_units` writes
/// them: the integer part (at least `0`), the point, the decimals with
/// trailing zeros trimmed.
#[inline]
pub fn print_units(n: i64, decimals: u32) -> Printed {
    let d = decimals.min(18) as usize;
    let (whole, frac) = split_units(n.unsigned_abs(), d);
    if d <= 8 && whole < 100_000_000 {
        print_short(n < 0, whole as u32, frac as u32 * POW10[8 - d] as u32)
    } else {
        print_long(n < 0, whole, frac, d)
    }
}

/// The eight decimal digits of `v` (below 10^8), leading zeros included,
/// one a byte, the first in the lowest byte (as they are stored): split
/// into halves, quarters and digits in every lane at once, dividing by
/// multiplying (exact in these ranges).
#[inline]
fn eight_digits(v: u32) -> u64 {
    let x = (v / 10_000) as u64 | (((v % 10_000) as u64) << 32);
    // Each 32-bit lane (below 10^4): /100 as *10486 >> 20.
    let hundreds = ((x * 10_486) >> 20) & 0x0000_007f_0000_007f;
    let x = hundreds | ((x - hundreds * 100) << 16);
    // Each 16-bit lane (below 100): /10 as *103 >> 10.
    let tens = ((x * 103) >> 10) & 0x000f_000f_000f_000f;
    tens | ((x - tens * 10) << 8)
}

/// A number with at most 8 integer digits and 8 decimals: each part
/// printed as one 8-byte word, its zeros counted from the word's bits.
/// `frac8` is the decimals scaled to eight places.
#[inline]
fn print_short(negative: bool, whole: u32, frac8: u32) -> Printed {
    const ZEROS: u64 = 0x3030_3030_3030_3030;
    let w = eight_digits(whole);
    // Leading zeros are the low bytes; a zero integer part keeps one digit.
    let whole_digits = if w == 0 {
        1
    } else {
        8 - w.trailing_zeros() as usize / 8
    };
    let f = eight_digits(frac8);
    // Trailing zeros are the high bytes; all zero: no decimals at all.
    let shown = if f == 0 {
        0
    } else {
        8 - f.leading_zeros() as usize / 8
    };
    let minus = negative as usize;
    let point = minus + whole_digits;
    let mut room = [b'-'; PRINTED_ROOM];
    room[minus..minus + 8]
        .copy_from_slice(&((w >> (8 * (8 - whole_digits))) | ZEROS).to_le_bytes());
    room[point] = b'.';
    room[point + 1..point + 9].copy_from_slice(&(f | ZEROS).to_le_bytes());
    Printed {
        room,
        len: point + 1 + shown,
        digits: whole_digits + shown,
    }
}

/// Any other number: digits two at a time from a table.
fn print_long(negative: bool, whole: u64, mut frac: u64, d: usize) -> Printed {
    let mut shown = 0;
    if frac != 0 {
        shown = d;
        while frac % 10 == 0 {
            frac /= 10;
            shown -= 1;
        }
    }
    let minus = negative as usize;
    let whole_digits = whole.checked_ilog10().map_or(1, |l| l as usize + 1);
    let point = minus + whole_digits;
    let len = point + 1 + shown;
    // Zeros the digits do not overwrite are the number's own: a zero
    // integer part, the decimals' leading zeros.
    let mut room = [b'0'; PRINTED_ROOM];
    if negative {
        room[0] = b'-';
    }
    digits_before(&mut room, point, whole);
    room[point] = b'.';
    digits_before(&mut room, len, frac);
    Printed {
        room,
        len,
        digits: whole_digits + shown,
    }
}

/// `mag` split at the point of `d` decimals into whole units and the
/// decimals' digits; the common decimals divide by a constant (a multiply)
/// rather than by a looked-up power (a division).
#[inline]
fn split_units(mag: u64, d: usize) -> (u64, u64) {
    macro_rules! by {
        ($p:expr) => {
            (mag / $p, mag % $p)
        };
    }
    match d {
        0 => (mag, 0),
        1 => by!(10),
        2 => by!(100),
        3 => by!(1_000),
        4 => by!(10_000),
        5 => by!(100_000),
        6 => by!(1_000_000),
        7 => by!(10_000_000),
        8 => by!(100_000_000),
        9 => by!(1_000_000_000),
        _ => (mag / POW10[d], mag % POW10[d]),
    }
}

/// Appends `n` units of 10^−decimals as `push_fixed` does.
pub fn push_units(out: &mut String, n: i64, decimals: u32) {
    out.extend(
        print_units(n, decimals)
            .as_bytes()
            .iter()
            .map(|&b| b as char),
    );
}

#[cfg(test)]
mod tests {
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
        proptest::prop_assert!(crate::program::check_number(p.as_bytes()).is_ok(), "{}", s);
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
            99_999_999_99,
            100_000_000_00,
            -99_999_999_00,
            -100_000_000_00,
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
}
