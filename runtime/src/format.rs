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

/// `value` in units of 10^−decimals, rounded (what `push_fixed` prints);
/// `None` if it is not finite or does not fit in 18 digits. Two values
/// print the same exactly when their units are equal.
pub fn fixed_units(value: f64, decimals: u32) -> Option<i64> {
    let scaled = (value * POW10[decimals.min(18) as usize] as f64).round();
    (scaled.is_finite() && scaled.abs() < 1e18).then_some(scaled as i64)
}

/// Appends `n` units of 10^−decimals as `push_fixed` does.
pub fn push_units(out: &mut String, n: i64, decimals: u32) {
    if n < 0 {
        out.push('-');
    }
    let mag = n.unsigned_abs();
    let pow = POW10[decimals.min(18) as usize];
    let mut ib = itoa::Buffer::new();
    out.push_str(ib.format(mag / pow));
    out.push('.');
    if decimals > 0 {
        let frac = mag % pow;
        if frac != 0 {
            let digits = ib.format(frac);
            for _ in digits.len()..decimals as usize {
                out.push('0');
            }
            out.push_str(digits.trim_end_matches('0'));
        }
    }
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
}
