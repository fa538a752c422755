//! The one canonical number formatter every dialect uses: round to a fixed
//! number of decimals as an integer count of units, print that count's
//! digits (eight at a time, in place). It never prints an exponent, `-0`,
//! NaN or infinity (those are refused before this point), and prints
//! exactly what `{:.N}` prints of the rounded value, trailing zeros trimmed.

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

/// The same as doubles (all exact: 10^18 = 2^18 · 5^18 and 5^18 < 2^53).
const POW10_F64: [f64; 19] = {
    let mut t = [1f64; 19];
    let mut i = 1;
    while i < 19 {
        t[i] = POW10[i] as f64;
        i += 1;
    }
    t
};

/// `value` in units of 10^−decimals, rounded half away from zero (what
/// `push_fixed` prints); `None` if it is not finite or does not fit in 18
/// digits. Two values print the same exactly when their units are equal.
#[inline]
pub fn fixed_units(value: f64, decimals: u32) -> Option<i64> {
    let scaled = value * POW10_F64[decimals.min(18) as usize];
    // NaN fails the comparison. Rounding cannot cross 1e18: doubles that
    // large are spaced 128 apart, so they are whole numbers already.
    if scaled.abs() < 1e18 {
        Some(round_half_away(scaled))
    } else {
        None
    }
}

/// `scaled.round() as i64` for |scaled| < 1e18, without the library call
/// and without a branch on the digits (which way a value rounds is a coin
/// toss a branch predictor loses): below 2^52 a double's distance from its
/// truncation is exact, so the comparison with one half is too; from 2^52
/// on, every double is whole and the distance is zero.
#[inline]
fn round_half_away(scaled: f64) -> i64 {
    let t = scaled as i64;
    let rest = scaled - t as f64;
    t + (rest >= 0.5) as i64 - (rest <= -0.5) as i64
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

/// `n` units of 10^−decimals (at most 18) printed as `push_units` writes
/// them: the integer part (at least `0`), the point, the decimals with
/// trailing zeros trimmed.
pub fn print_units(n: i64, decimals: u32) -> Printed {
    let mut room = [b'0'; PRINTED_ROOM];
    let (len, digits) = print_into(&mut room, n, decimals);
    Printed { room, len, digits }
}

/// Appends `n` units of 10^−decimals as `print_units` prints them to
/// `text`, printing in place (room for the longest number is added and
/// cut back: the digits are stored once, never copied or read back);
/// returns how many digits it has (what a dialect's digit limit counts).
#[inline(always)]
pub fn push_units_to(text: &mut Vec<u8>, n: i64, decimals: u32) -> usize {
    let at = text.len();
    text.extend_from_slice(&[b'0'; PRINTED_ROOM]);
    let (len, digits) = match text.split_last_chunk_mut::<PRINTED_ROOM>() {
        Some((_, room)) => print_into(room, n, decimals),
        None => unreachable!("the room was just added"),
    };
    text.truncate(at + len);
    digits
}

/// Prints into `room` (at least `PRINTED_ROOM` long, all `'0'`); returns
/// the number's length and its count of digits.
#[inline(always)]
fn print_into(room: &mut [u8; PRINTED_ROOM], n: i64, decimals: u32) -> (usize, usize) {
    let d = decimals.min(18) as usize;
    let mag = n.unsigned_abs();
    if d <= 8 && mag < POW10[8 + d] {
        // At most 8 digits either side of the point: scaled to 8 decimals
        // it splits at a constant (a multiply, where 10^d would divide).
        let m8 = mag * POW10[8 - d];
        print_short(
            room,
            n < 0,
            (m8 / 100_000_000) as u32,
            (m8 % 100_000_000) as u32,
        )
    } else {
        let p = POW10[d];
        print_long(room, n < 0, mag / p, mag % p, d)
    }
}

/// Writes `v`'s digits right-aligned to end at `end`, two at a time.
/// Zero writes nothing.
#[inline]
fn digits_before(buf: &mut [u8], end: usize, mut v: u64) {
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
#[inline(always)]
fn print_short(
    room: &mut [u8; PRINTED_ROOM],
    negative: bool,
    whole: u32,
    frac8: u32,
) -> (usize, usize) {
    const ZEROS: u64 = 0x3030_3030_3030_3030;
    // Most integer parts are short (a radius, a height): up to two
    // digits come straight from the table.
    let (w, whole_digits) = if whole < 100 {
        let pair = whole as usize * 2;
        let short = (whole >= 10) as usize;
        let word = u16::from_le_bytes([PAIRS[pair], PAIRS[pair + 1]]) as u64 & !ZEROS;
        (word >> (8 * (1 - short)), 1 + short)
    } else {
        let w = eight_digits(whole);
        // Leading zeros are the low bytes; the last digit is always shown.
        let digits = 8 - w.trailing_zeros() as usize / 8;
        (w >> (8 * (8 - digits)), digits)
    };
    let f = eight_digits(frac8);
    // Trailing zeros are the high bytes; all zero: no decimals at all.
    let shown = 8 - f.leading_zeros() as usize / 8;
    let minus = negative as usize;
    let point = minus + whole_digits;
    // A positive number's digits overwrite the '0' put where a minus goes.
    room[0] = if negative { b'-' } else { b'0' };
    room[minus..minus + 8].copy_from_slice(&(w | ZEROS).to_le_bytes());
    room[point] = b'.';
    room[point + 1..point + 9].copy_from_slice(&(f | ZEROS).to_le_bytes());
    (point + 1 + shown, whole_digits + shown)
}

/// Any other number: digits two at a time from a table.
#[inline(never)]
fn print_long(
    room: &mut [u8; PRINTED_ROOM],
    negative: bool,
    whole: u64,
    mut frac: u64,
    d: usize,
) -> (usize, usize) {
    let mut shown = 0;
    if frac != 0 {
        shown = d;
        while frac.is_multiple_of(10) {
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
    if negative {
        room[0] = b'-';
    }
    digits_before(room, point, whole);
    room[point] = b'.';
    digits_before(room, len, frac);
    (len, whole_digits + shown)
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
}
