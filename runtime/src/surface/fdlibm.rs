//! sin, cos and exp as surface kernels compute them, in both backends:
//! fdlibm's algorithms (Sun, 1993, as in musl and Rust's `libm` crate),
//! within 1 ulp of the host's libm, with no fused multiply-add so the bits
//! are the same on every x86-64; arguments outside their bounds (huge,
//! infinite, NaN; exp's overflow and underflow) are libm's own. The JIT
//! emits the same operations inline on two lanes (`jit/vecmath.rs`);
//! its tests hold both to libm and to each other. Constant folding in the
//! IR keeps libm (`ir::apply_unary`).

/// 1.5 · 2^52: adding it rounds a double below 2^51 to a whole number,
/// which then sits in the low bits of the sum's mantissa.
pub(crate) const TO_INT: f64 = 1.5 / f64::EPSILON;

// Reduction by π/2 (fdlibm `__rem_pio2`, its medium case with all three
// rounds always taken): π/2 = PIO2_1 + PIO2_2 + PIO2_3 + PIO2_3T, each of the
// first three with 33 bits so that n · PIO2_k is exact for |n| < 2^20.
pub(crate) const INV_PIO2: u64 = 0x3FE4_5F30_6DC9_C883;
pub(crate) const PIO2_1: u64 = 0x3FF9_21FB_5440_0000;
pub(crate) const PIO2_2: u64 = 0x3DD0_B461_1A60_0000;
pub(crate) const PIO2_3: u64 = 0x3BA3_198A_2E00_0000;
pub(crate) const PIO2_3T: u64 = 0x397B_839A_2520_49C1;
/// The reduction is exact below 2^20 · π/2 (fdlibm's medium case);
/// larger arguments go to libm.
pub(crate) const TRIG_LIMIT: f64 = 1_647_099.0;

// sin on [−π/4, π/4] (fdlibm `__kernel_sin`).
pub(crate) const S1: u64 = 0xBFC5_5555_5555_5549;
pub(crate) const S2: u64 = 0x3F81_1111_1110_F8A6;
pub(crate) const S3: u64 = 0xBF2A_01A0_19C1_61D5;
pub(crate) const S4: u64 = 0x3EC7_1DE3_57B1_FE7D;
pub(crate) const S5: u64 = 0xBE5A_E5E6_8A2B_9CEB;
pub(crate) const S6: u64 = 0x3DE5_D93A_5ACF_D57C;

// cos on [−π/4, π/4] (fdlibm `__kernel_cos`).
pub(crate) const C1: u64 = 0x3FA5_5555_5555_554C;
pub(crate) const C2: u64 = 0xBF56_C16C_16C1_5177;
pub(crate) const C3: u64 = 0x3EFA_01A0_19CB_1590;
pub(crate) const C4: u64 = 0xBE92_7E4F_809C_52AD;
pub(crate) const C5: u64 = 0x3E21_EE9E_BDB4_B1C4;
pub(crate) const C6: u64 = 0xBDA8_FAE9_BE88_38D4;

// exp (fdlibm `e_exp.c`): x = k ln2 + r, |r| ≤ ln2/2, ln2 = LN2HI + LN2LO.
pub(crate) const INV_LN2: u64 = 0x3FF7_1547_652B_82FE;
pub(crate) const LN2HI: u64 = 0x3FE6_2E42_FEE0_0000;
pub(crate) const LN2LO: u64 = 0x3DEA_39EF_3579_3C76;
pub(crate) const P1: u64 = 0x3FC5_5555_5555_553E;
pub(crate) const P2: u64 = 0xBF66_C16C_16BE_BD93;
pub(crate) const P3: u64 = 0x3F11_566A_AF25_DE2C;
pub(crate) const P4: u64 = 0xBEBB_BD41_C5D2_6BF1;
pub(crate) const P5: u64 = 0x3E66_3769_72BE_A4D0;
/// Below this |x| both exp(x) and 2^k are normal numbers; beyond it
/// (overflow, underflow, subnormal results) libm answers.
pub(crate) const EXP_LIMIT: f64 = 708.0;
/// Below this, e^a rounds to +0 (a < −1075 ln 2 ≈ −745.133): libm's value,
/// which the kernel's inline exp gives without leaving the vector pass.
/// (Read only by the JIT's vector pass.)
#[cfg_attr(not(feature = "jit"), allow(dead_code))]
pub(crate) const EXP_ZERO_BELOW: f64 = -746.0;

/// sin a and cos a, from one reduction: the same bits as `sin` and `cos`.
pub fn sin_cos(a: f64) -> (f64, f64) {
    let Some((q, y0, y1)) = reduce(a) else {
        return (a.sin(), a.cos());
    };
    let (odd, half) = (q & 1 != 0, q & 2 != 0);
    let (s, c) = (sin_poly(y0, y1), cos_poly(y0, y1));
    let (s, c) = if odd { (c, s) } else { (s, c) };
    (if half { -s } else { s }, if odd != half { -c } else { c })
}

/// sin a (only the polynomial it needs).
pub fn sin(a: f64) -> f64 {
    let Some((q, y0, y1)) = reduce(a) else {
        return a.sin();
    };
    let (odd, half) = (q & 1 != 0, q & 2 != 0);
    let s = if odd {
        cos_poly(y0, y1)
    } else {
        sin_poly(y0, y1)
    };
    if half { -s } else { s }
}

/// cos a (only the polynomial it needs).
pub fn cos(a: f64) -> f64 {
    let Some((q, y0, y1)) = reduce(a) else {
        return a.cos();
    };
    let (odd, half) = (q & 1 != 0, q & 2 != 0);
    let c = if odd {
        sin_poly(y0, y1)
    } else {
        cos_poly(y0, y1)
    };
    if odd != half { -c } else { c }
}

/// a = n π/2 + y0 + y1 as the inline reduction computes it, with the
/// bits of rint(a · 2/π) + 1.5 · 2^52 (n in the low bits); `None` where
/// the inline code leaves the argument to libm.
fn reduce(a: f64) -> Option<(u64, f64, f64)> {
    // Huge, infinite or NaN: libm's.
    if a.is_nan() || a.abs() >= TRIG_LIMIT {
        return None;
    }
    let k = f64::from_bits;
    let t = a * k(INV_PIO2) + TO_INT;
    let n = t - TO_INT;
    let r = a - n * k(PIO2_1);
    let round = |r: f64, head: u64| {
        let nh = n * k(head);
        let r2 = r - nh;
        (r2, (r - r2) - nh)
    };
    let (r, lost2) = round(r, PIO2_2);
    let (r, lost3) = round(r, PIO2_3);
    let w = (n * k(PIO2_3T) - lost3) - lost2;
    let y0 = r - w;
    Some((t.to_bits(), y0, (r - y0) - w))
}

/// `kernel_sin` on one double.
fn sin_poly(y0: f64, y1: f64) -> f64 {
    let k = f64::from_bits;
    let z = y0 * y0;
    let zz = z * z;
    let r = (k(S2) + z * (k(S3) + z * k(S4))) + (z * zz) * (k(S5) + z * k(S6));
    let v = z * y0;
    y0 - ((z * (0.5 * y1 - v * r) - y1) - v * k(S1))
}

/// `kernel_cos` on one double.
fn cos_poly(y0: f64, y1: f64) -> f64 {
    let k = f64::from_bits;
    let z = y0 * y0;
    let zz = z * z;
    let r = z * (k(C1) + z * (k(C2) + z * k(C3))) + (zz * zz) * (k(C4) + z * (k(C5) + z * k(C6)));
    let hz = 0.5 * z;
    let w = 1.0 - hz;
    w + (((1.0 - w) - hz) + (z * r - y0 * y1))
}

/// e^a: libm's beyond |a| ≥ 708 (overflow, underflow, subnormal results).
pub fn exp(a: f64) -> f64 {
    if a.is_nan() || a.abs() >= EXP_LIMIT {
        return a.exp();
    }
    let k = f64::from_bits;
    let t = a * k(INV_LN2) + TO_INT;
    let n = t - TO_INT;
    let hi = a - n * k(LN2HI);
    let lo = n * k(LN2LO);
    let x = hi - lo;
    let xx = x * x;
    let p = [P4, P3, P2, P1]
        .into_iter()
        .fold(k(P5), |p, c| k(c) + xx * p);
    let c = x - xx * p;
    let y = 1.0 - ((lo - (x * c) / (2.0 - c)) - hi);
    let e = t
        .to_bits()
        .wrapping_add((1023 - TO_INT.to_bits() as i64) as u64)
        << 52;
    y * f64::from_bits(e)
}

#[cfg(test)]
mod tests {
    /// `sin_cos` shares one reduction and gives `sin`'s and `cos`'s bits:
    /// every quadrant, both signs, the libm cases beyond the bound.
    #[test]
    fn sin_cos_is_sin_and_cos() {
        let mut args = vec![0.0, -0.0, f64::NAN, f64::INFINITY, -f64::INFINITY, 1e300];
        args.extend([super::TRIG_LIMIT, -super::TRIG_LIMIT, 5e-324, 1e-8]);
        let mut w: u64 = 0x2545_F491_4F6C_DD1D;
        for i in 0..200_000 {
            w ^= w << 13;
            w ^= w >> 7;
            w ^= w << 17;
            let u = (w >> 11) as f64 / (1u64 << 53) as f64;
            args.push((2.0 * u - 1.0) * [4.0, 100.0, 1e6, 2e6][i % 4]);
        }
        for a in args {
            let (s, c) = super::sin_cos(a);
            let same = |x: f64, y: f64| x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan());
            assert!(same(s, super::sin(a)), "sin {a:e}");
            assert!(same(c, super::cos(a)), "cos {a:e}");
        }
    }
}
