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

/// 10^`decimals`, exactly, for up to 18 decimals (more are taken as 18).
#[inline(always)]
pub(super) fn pow10(decimals: u32) -> u64 {
    POW10[decimals.min(18) as usize]
}

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
    Decimals::new(decimals).units(value)
}

/// A number of decimals (at most 18) and what rounding to it and
/// printing it take, worked out once for a word that prints many
/// numbers: `fixed_units` and `print_units` are these two methods.
#[derive(Clone, Copy, Debug)]
pub struct Decimals {
    /// 10^d as a double (exact).
    scale: f64,
    /// 10^(8 − d) where d ≤ 8: a count of units times this is the
    /// number in units of 10^−8, split at a constant.
    to_eighths: u64,
    /// 10^(8 + d) where d ≤ 8, else 0: unit counts below it have at most
    /// eight digits either side of the point.
    short_below: u64,
    d: u32,
}

impl Decimals {
    /// `decimals` places (more than 18 are taken as 18).
    pub const fn new(decimals: u32) -> Decimals {
        let d = if decimals < 18 { decimals } else { 18 };
        Decimals {
            scale: POW10_F64[d as usize],
            to_eighths: if d <= 8 { POW10[8 - d as usize] } else { 0 },
            short_below: if d <= 8 { POW10[8 + d as usize] } else { 0 },
            d,
        }
    }

    /// The number of decimals.
    #[inline(always)]
    pub fn places(&self) -> u32 {
        self.d
    }

    /// `value` in units of the last decimal, rounded half away from zero;
    /// `None` if it is not finite or does not fit in 18 digits.
    #[inline(always)]
    pub fn units(&self, value: f64) -> Option<i64> {
        let scaled = value * self.scale;
        // NaN fails the comparison. Rounding cannot cross 1e18: doubles
        // that large are spaced 128 apart, so they are whole numbers already.
        if scaled.abs() < 1e18 {
            Some(round_half_away(scaled))
        } else {
            None
        }
    }

    /// Prints `n` units into `room`, whatever it held, as `print_units`
    /// prints them; returns the number's length and its count of digits
    /// (bytes of `room` after the number are left as filler).
    #[inline(always)]
    pub fn print(&self, room: &mut [u8; PRINTED_ROOM], n: i64) -> (usize, usize) {
        self.digits(n).store(room)
    }

    /// `n` units' digits worked out, to be stored later (`Digits::store`):
    /// a block works out all its numbers' digits side by side before it
    /// stores any, so their chains of multiplies overlap.
    #[inline(always)]
    pub fn digits(&self, n: i64) -> Digits {
        let mag = n.unsigned_abs();
        if mag < self.short_below {
            // At most 8 digits either side of the point: scaled to 8
            // decimals it splits at a constant (a multiply, where 10^d
            // would divide).
            let m8 = mag * self.to_eighths;
            short_digits(n < 0, (m8 / 100_000_000) as u32, (m8 % 100_000_000) as u32)
        } else {
            Digits {
                whole: mag,
                negative: n < 0,
                long: Some(self.d),
                ..Digits::default()
            }
        }
    }
}

/// A number's digits, worked out and not yet stored (`Decimals::digits`).
#[derive(Clone, Copy, Debug, Default)]
pub struct Digits {
    /// At most eight integer digits: their ASCII, the first in the
    /// lowest byte ('0' after the last); a longer number's magnitude in
    /// units.
    whole: u64,
    /// The eight decimals' ASCII, the first in the lowest byte.
    frac: u64,
    /// How many integer digits and decimals are shown.
    whole_digits: usize,
    shown: usize,
    negative: bool,
    /// A number with more than eight digits either side: its decimals
    /// (printed digit pair by digit pair when stored).
    long: Option<u32>,
}

impl Digits {
    /// Stores the number into `room`, whatever it held; returns its
    /// length and its count of digits (bytes of `room` after the number
    /// are left as filler).
    #[inline(always)]
    pub fn store(&self, room: &mut [u8; PRINTED_ROOM]) -> (usize, usize) {
        match self.long {
            None => store_short(room, self),
            Some(d) => {
                let p = POW10[d as usize];
                print_long(
                    room,
                    self.negative,
                    self.whole / p,
                    self.whole % p,
                    d as usize,
                )
            }
        }
    }
}

/// `scaled.round() as i64` for |scaled| < 1e18, without the library call
/// and without a branch on the digits (which way a value rounds is a coin
/// toss a branch predictor loses): the largest double below one half,
/// with `scaled`'s sign, added and the sum truncated. The sum is rounded
/// to the nearest double (ties to even), and that rounding is what makes
/// it exact: below a tie (the part after the point under one half, so
/// at most one half less a unit of `scaled`'s last place, or a double
/// below one half) the sum stays below the next whole number; at a tie
/// or above it it reaches it (0.5 + (0.5 − 2^−54) = 1 − 2^−54, halfway
/// between 1 − 2^−53 and 1, goes to the even 1); from 2^52 on every
/// double is whole and the added part is less than half a unit of its
/// last place, so the sum is the value itself.
/// `round_half_away_is_f64_round` holds it to `f64::round` at and around
/// every tie. The truncation is one instruction: `as` would guard
/// against NaN and values past `i64`'s range, which the caller's range
/// test has already ruled out. (It replaces a truncation, its distance
/// from the value and two comparisons with one half: a chain of seven
/// operations per number where this one is four.)
#[inline]
fn round_half_away(scaled: f64) -> i64 {
    debug_assert!(scaled.abs() < 1e18);
    let sum = scaled + BELOW_HALF.copysign(scaled);
    // SAFETY: the caller (`units`) passes only |scaled| < 1e18, a finite
    // value, so |sum| < 1e18 + 1/2 and its truncation fits in an i64
    // (< 2^63 ≈ 9.2e18).
    unsafe { sum.to_int_unchecked::<i64>() }
}

/// The largest double below one half: 1/2 − 2^−54 (doubles from 1/4 to
/// 1/2 are 2^−54 apart).
const BELOW_HALF: f64 = 0.5 - f64::EPSILON / 4.0;

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

/// Prints `n` units of 10^−decimals into `room`, whatever it held, as
/// `print_units` prints them; returns the number's length and its count
/// of digits (bytes of `room` after the number are left as filler).
#[inline(always)]
fn print_into(room: &mut [u8; PRINTED_ROOM], n: i64, decimals: u32) -> (usize, usize) {
    Decimals::new(decimals).print(room, n)
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
/// multiplying (exact in these ranges). The printer's own on machines
/// without SSE2; on x86-64 the reference `sixteen_digits` is tested against.
#[cfg(any(test, not(all(target_arch = "x86_64", target_feature = "sse2"))))]
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

/// The digits of `whole` and of `frac8` (each below 10^8, leading zeros
/// included), one a byte, the first in the lowest byte: the integer
/// part's eight in the first word, the decimals' in the second.
#[cfg(not(all(target_arch = "x86_64", target_feature = "sse2")))]
#[inline(always)]
fn sixteen_digits(whole: u32, frac8: u32) -> (u64, u64) {
    (eight_digits(whole), eight_digits(frac8))
}

/// The digits of `whole` and of `frac8` (each below 10^8, leading zeros
/// included), one a byte, the first in the lowest byte: the integer
/// part's eight in the first word, the decimals' in the second. Both
/// numbers in one SSE2 register (always there on x86-64), split as
/// `eight_digits` splits one, every lane at once: into halves (below
/// 10^4) by a 32-bit multiply, quarters (below 100) and digits by
/// 16-bit high multiplies, all exact in these ranges (checked value by
/// value against `eight_digits` by `sixteen_digits_are_eight_and_eight`).
#[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
#[inline(always)]
fn sixteen_digits(whole: u32, frac8: u32) -> (u64, u64) {
    use std::arch::x86_64::*;
    // SAFETY: these intrinsics only need SSE2, which this build targets
    // (the `cfg` above; it is part of x86-64 itself); they touch no memory.
    unsafe {
        // [whole, frac8] as 64-bit lanes.
        let v = _mm_set_epi64x(frac8 as i64, whole as i64);
        // /10^4 as ·0xd1b71759 >> 45, exact below 2^32.
        let high = _mm_srli_epi64::<45>(_mm_mul_epu32(v, _mm_set1_epi32(0xd1b7_1759_u32 as i32)));
        let low = _mm_sub_epi32(v, _mm_mul_epu32(high, _mm_set1_epi32(10_000)));
        // 32-bit lanes [whole / 10^4, whole % 10^4, frac / 10^4, frac % 10^4].
        let halves = _mm_or_si128(high, _mm_slli_epi64::<32>(low));
        // Each half's hundreds (/100 as ·5243 >> 19, exact below 43699)
        // and the rest, side by side in 16-bit lanes.
        let hundreds = _mm_srli_epi16::<3>(_mm_mulhi_epu16(halves, _mm_set1_epi16(5243)));
        let rest = _mm_sub_epi16(halves, _mm_mullo_epi16(hundreds, _mm_set1_epi16(100)));
        let pairs = _mm_or_si128(hundreds, _mm_slli_epi32::<16>(rest));
        // Each pair's tens (/10 as ·6554 >> 16, exact below 16389) and
        // units, side by side in bytes.
        let tens = _mm_mulhi_epu16(pairs, _mm_set1_epi16(6554));
        let units = _mm_sub_epi16(pairs, _mm_mullo_epi16(tens, _mm_set1_epi16(10)));
        let digits = _mm_or_si128(tens, _mm_slli_epi16::<8>(units));
        (
            _mm_cvtsi128_si64(digits) as u64,
            _mm_cvtsi128_si64(_mm_unpackhi_epi64(digits, digits)) as u64,
        )
    }
}

/// A number with at most 8 integer digits and 8 decimals: each part
/// split into digits as one 8-byte word, its zeros counted from the
/// word's bits. `frac8` is the decimals scaled to eight places.
#[inline(always)]
fn short_digits(negative: bool, whole: u32, frac8: u32) -> Digits {
    const ZEROS: u64 = 0x3030_3030_3030_3030;
    let (w, f) = sixteen_digits(whole, frac8);
    // Leading zeros are the low bytes; the last digit is always shown.
    let whole_digits = 8 - (w | 1 << 56).trailing_zeros() as usize / 8;
    let w = w >> (8 * (8 - whole_digits));
    // Trailing zeros are the high bytes; all zero: no decimals at all.
    let shown = 8 - f.leading_zeros() as usize / 8;
    Digits {
        whole: w | ZEROS,
        frac: f | ZEROS,
        whole_digits,
        shown,
        negative,
        long: None,
    }
}

/// Stores a short number (`short_digits`): each part as one 8-byte word.
#[inline(always)]
fn store_short(room: &mut [u8; PRINTED_ROOM], d: &Digits) -> (usize, usize) {
    let minus = d.negative as usize;
    let point = minus + d.whole_digits;
    // A positive number's digits overwrite the '0' put where a minus goes.
    room[0] = if d.negative { b'-' } else { b'0' };
    room[minus..minus + 8].copy_from_slice(&d.whole.to_le_bytes());
    room[point] = b'.';
    room[point + 1..point + 9].copy_from_slice(&d.frac.to_le_bytes());
    (point + 1 + d.shown, d.whole_digits + d.shown)
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
    // The zeros the digits do not overwrite are the number's own (a zero
    // integer part, the decimals' leading zeros): put them there first.
    *room = [b'0'; PRINTED_ROOM];
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
mod tests;
