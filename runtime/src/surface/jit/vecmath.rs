//! The kernel's own sine, cosine and exponential, emitted inline on both
//! lanes of an `F64X2` for the main loop (a call to libm spills every live
//! vector register and runs once per lane): the same IEEE operations in
//! the same order as `crate::surface::fdlibm`, which the scalar pass calls,
//! which answer the lanes the inline code leaves out, and which the
//! interpreter uses, so a point gets the same bits in either pass and
//! either backend. The algorithms of fdlibm (Sun, 1993, as in musl
//! and Rust's `libm` crate), accurate to within 1 ulp of the host's libm
//! on the arguments they cover, with every operation an IEEE-exact
//! instruction (no fused multiply-add, so the bits are the same on every
//! x86-64).
//!
//! Each emitter returns its value and a lane mask of the arguments it
//! covers (|a| below a bound, never NaN or infinite); where a lane falls
//! outside, the kernel takes the pair again point by point in its scalar
//! pass (`jit.rs`, `define_kernel`), whose `fdlibm` calls hand such
//! arguments to libm, so NaN, infinities, huge arguments and exp's
//! overflow and subnormal results are libm's own (exp's +0 far below the
//! range is inline: the same bits).

use cranelift_codegen::ir::condcodes::{FloatCC, IntCC};
use cranelift_codegen::ir::{InstBuilder, MemFlagsData, Value, types};
use cranelift_frontend::FunctionBuilder;

use super::{Lanes, constant};

use crate::surface::fdlibm::*;

/// Short names for building lane-wise arithmetic on `F64X2`.
struct Ops<'a, 'b> {
    b: &'a mut FunctionBuilder<'b>,
}

impl Ops<'_, '_> {
    fn k(&mut self, bits: u64) -> Value {
        constant(self.b, Lanes::Two, bits)
    }
    fn f(&mut self, v: f64) -> Value {
        self.k(v.to_bits())
    }
    fn add(&mut self, a: Value, c: Value) -> Value {
        self.b.ins().fadd(a, c)
    }
    fn sub(&mut self, a: Value, c: Value) -> Value {
        self.b.ins().fsub(a, c)
    }
    fn mul(&mut self, a: Value, c: Value) -> Value {
        self.b.ins().fmul(a, c)
    }
    /// c0 + z·c1, with c1 a node and c0 a constant.
    fn fma_k(&mut self, c0: u64, z: Value, c1: Value) -> Value {
        let k = self.k(c0);
        let p = self.mul(z, c1);
        self.add(k, p)
    }
    /// The lanes where |a| < limit (false for NaN), as a lane mask.
    fn below(&mut self, a: Value, limit: f64) -> Value {
        let abs = self.b.ins().fabs(a);
        let lim = self.f(limit);
        self.b.ins().fcmp(FloatCC::LessThan, abs, lim)
    }
    /// The bits of a double as a 64-bit integer, lane by lane.
    fn bits(&mut self, a: Value) -> Value {
        self.b.ins().bitcast(types::I64X2, MemFlagsData::new(), a)
    }
    /// Those bits back as a double.
    fn double(&mut self, i: Value) -> Value {
        self.b.ins().bitcast(types::F64X2, MemFlagsData::new(), i)
    }
    /// A 64-bit integer in both lanes.
    fn int(&mut self, v: i64) -> Value {
        let mut bytes = v.to_le_bytes().to_vec();
        bytes.extend_from_slice(&v.to_le_bytes());
        let c = self.b.func.dfg.constants.insert(bytes.into());
        self.b.ins().vconst(types::I64X2, c)
    }
}

/// sin a and cos a on both lanes, and the lane mask of where they hold.
pub(super) fn sin_cos(b: &mut FunctionBuilder, a: Value) -> (Value, Value, Value) {
    let mut l = Ops { b };
    let ok = l.below(a, TRIG_LIMIT);
    // n = rint(a · 2/π), in the low bits of t; a = n π/2 + y0 + y1.
    let inv = l.k(INV_PIO2);
    let to_int = l.f(TO_INT);
    let scaled = l.mul(a, inv);
    let t = l.add(scaled, to_int);
    let n = l.sub(t, to_int);
    let p1 = l.k(PIO2_1);
    let np1 = l.mul(n, p1);
    let r = l.sub(a, np1);
    // Two more rounds, each keeping what its subtraction rounded away:
    // a − n π/2 = r − w.
    let (r, lost2) = reduce_round(&mut l, n, r, PIO2_2);
    let (r, lost3) = reduce_round(&mut l, n, r, PIO2_3);
    let tail = l.k(PIO2_3T);
    let nt = l.mul(n, tail);
    let w = l.sub(nt, lost3);
    let w = l.sub(w, lost2);
    let y0 = l.sub(r, w);
    let ry = l.sub(r, y0);
    let y1 = l.sub(ry, w);

    let z = l.mul(y0, y0);
    let zz = l.mul(z, z);
    let sin = kernel_sin(&mut l, y0, y1, z, zz);
    let cos = kernel_cos(&mut l, y0, y1, z, zz);

    // Quadrant n mod 4: sin = (sin, cos, −sin, −cos)[n], cos = (cos, −sin,
    // −cos, sin)[n]. On the bits, lane by lane: swap where bit 0 of n is
    // set; flip sin's sign bit by bit 1 of n, cos's by bit 0 xor bit 1.
    let ti = l.bits(t);
    let one = l.int(1);
    let low = l.b.ins().band(ti, one);
    let odd = l.b.ins().icmp(IntCC::Equal, low, one);
    let (si, ci) = (l.bits(sin), l.bits(cos));
    let s = l.b.ins().bitselect(odd, ci, si);
    let c = l.b.ins().bitselect(odd, si, ci);
    let sign = l.int(i64::MIN);
    let bit1 = l.b.ins().ishl_imm_u(ti, 62);
    let s_flip = l.b.ins().band(bit1, sign);
    let bit0 = l.b.ins().ishl_imm_u(ti, 63);
    let both = l.b.ins().bxor(bit0, bit1);
    let c_flip = l.b.ins().band(both, sign);
    let s = l.b.ins().bxor(s, s_flip);
    let c = l.b.ins().bxor(c, c_flip);
    (l.double(s), l.double(c), ok)
}

/// One round of the reduction: r − n·head, and what its rounding lost
/// ((r − r′) − n·head, exact as in fdlibm: n·head is exact, and where the
/// subtraction cancels it is exact too). fdlibm takes its third round only
/// after a cancellation, where the second round loses nothing; taking it
/// always, the second round's loss is carried instead of dropped.
fn reduce_round(l: &mut Ops, n: Value, r: Value, head: u64) -> (Value, Value) {
    let h = l.k(head);
    let nh = l.mul(n, h);
    let r2 = l.sub(r, nh);
    let lost = l.sub(r, r2);
    (r2, l.sub(lost, nh))
}

/// sin(y0 + y1) for |y0| ≤ π/4, y1 the tail of y0; z = y0², zz = z².
fn kernel_sin(l: &mut Ops, y0: Value, y1: Value, z: Value, zz: Value) -> Value {
    // r = S2 + z (S3 + z S4) + z zz (S5 + z S6)
    let s4 = l.k(S4);
    let a = l.fma_k(S3, z, s4);
    let a = l.fma_k(S2, z, a);
    let s6 = l.k(S6);
    let c = l.fma_k(S5, z, s6);
    let zzz = l.mul(z, zz);
    let c = l.mul(zzz, c);
    let r = l.add(a, c);
    // y0 − ((z (y1/2 − v r) − y1) − v S1), v = z y0
    let v = l.mul(z, y0);
    let half = l.f(0.5);
    let hy = l.mul(half, y1);
    let vr = l.mul(v, r);
    let d = l.sub(hy, vr);
    let zd = l.mul(z, d);
    let e = l.sub(zd, y1);
    let s1 = l.k(S1);
    let vs = l.mul(v, s1);
    let e = l.sub(e, vs);
    l.sub(y0, e)
}

/// cos(y0 + y1) for |y0| ≤ π/4, y1 the tail of y0; z = y0², zz = z².
fn kernel_cos(l: &mut Ops, y0: Value, y1: Value, z: Value, zz: Value) -> Value {
    // r = z (C1 + z (C2 + z C3)) + zz² (C4 + z (C5 + z C6))
    let c3 = l.k(C3);
    let a = l.fma_k(C2, z, c3);
    let a = l.fma_k(C1, z, a);
    let a = l.mul(z, a);
    let c6 = l.k(C6);
    let c = l.fma_k(C5, z, c6);
    let c = l.fma_k(C4, z, c);
    let z4 = l.mul(zz, zz);
    let c = l.mul(z4, c);
    let r = l.add(a, c);
    // w + (((1 − w) − z/2) + (z r − y0 y1)), w = 1 − z/2
    let half = l.f(0.5);
    let hz = l.mul(half, z);
    let one = l.f(1.0);
    let w = l.sub(one, hz);
    let lost = l.sub(one, w);
    let lost = l.sub(lost, hz);
    let zr = l.mul(z, r);
    let yy = l.mul(y0, y1);
    let tail = l.sub(zr, yy);
    let tail = l.add(lost, tail);
    l.add(w, tail)
}

/// e^a on both lanes, and the lane mask of where it holds.
pub(super) fn exp(b: &mut FunctionBuilder, a: Value) -> (Value, Value) {
    let mut l = Ops { b };
    let ok = l.below(a, EXP_LIMIT);
    // k = rint(a / ln2), in the low bits of t; a = k ln2 + (hi − lo).
    let inv = l.k(INV_LN2);
    let to_int = l.f(TO_INT);
    let scaled = l.mul(a, inv);
    let t = l.add(scaled, to_int);
    let k = l.sub(t, to_int);
    let ln2hi = l.k(LN2HI);
    let kh = l.mul(k, ln2hi);
    let hi = l.sub(a, kh);
    let ln2lo = l.k(LN2LO);
    let lo = l.mul(k, ln2lo);
    let x = l.sub(hi, lo);
    // c = x − x² (P1 + x² (P2 + x² (P3 + x² (P4 + x² P5))))
    let xx = l.mul(x, x);
    let mut p = l.k(P5);
    for coeff in [P4, P3, P2, P1] {
        p = l.fma_k(coeff, xx, p);
    }
    let xp = l.mul(xx, p);
    let c = l.sub(x, xp);
    // e^r = 1 − ((lo − x c / (2 − c)) − hi)
    let two = l.f(2.0);
    let den = l.sub(two, c);
    let xc = l.mul(x, c);
    let q = l.b.ins().fdiv(xc, den);
    let d = l.sub(lo, q);
    let d = l.sub(d, hi);
    let one = l.f(1.0);
    let y = l.sub(one, d);
    // 2^k: the exponent field k + 1023, k = bits(t) − bits(TO_INT).
    let ti = l.bits(t);
    let bias = l.int(1023 - TO_INT.to_bits() as i64);
    let e = l.b.ins().iadd(ti, bias);
    let e = l.b.ins().ishl_imm_u(e, 52);
    let scale = l.double(e);
    let e = l.mul(y, scale);
    // Far below the range, libm's +0 (seen where a Gaussian has decayed
    // away): covered here rather than sending the pair to libm.
    let floor = l.f(EXP_ZERO_BELOW);
    let zero = l.b.ins().fcmp(FloatCC::LessThan, a, floor);
    let ok = l.b.ins().bor(ok, zero);
    let zero = l.double(zero);
    (l.b.ins().band_not(e, zero), ok)
}

#[cfg(test)]
mod tests {
    use std::f64::consts::FRAC_PI_2;

    use crate::surface::ir::{Graph, SurfaceFn, SurfaceTape, Unary};
    use crate::surface::jit::JitSurface;

    /// The distance from `got` to `want` in units in the last place, NaN
    /// equal to NaN (and never near anything else); +0 and −0 are one ulp
    /// apart, so a lost sign of zero fails.
    fn ulps(got: f64, want: f64) -> u64 {
        if got.is_nan() || want.is_nan() {
            return if got.is_nan() && want.is_nan() {
                0
            } else {
                u64::MAX
            };
        }
        // Doubles ordered as integers: negative ones mirrored below zero.
        let key = |v: f64| {
            let b = v.to_bits() as i64;
            if b < 0 { -(b & i64::MAX) - 1 } else { b }
        };
        key(got).abs_diff(key(want))
    }

    /// A kernel whose outputs are sin x, cos x, exp x, sin y, cos y, exp y,
    /// or, with `alone`, only sin x (outputs 0 and 3), only cos y: sin and
    /// cos of an argument on their own, not sharing a reduction.
    fn kernel(alone: bool) -> JitSurface {
        let mut g = Graph::new();
        let (x, y) = (g.x(), g.y());
        let outputs = if alone {
            let s = g.unary(Unary::Sin, x);
            let c = g.unary(Unary::Cos, y);
            let e = g.unary(Unary::Exp, y);
            [s, c, e, s, c, e]
        } else {
            [
                Unary::Sin,
                Unary::Cos,
                Unary::Exp,
                Unary::Sin,
                Unary::Cos,
                Unary::Exp,
            ]
            .into_iter()
            .zip([x, x, x, y, y, y])
            .map(|(op, v)| g.unary(op, v))
            .collect::<Vec<_>>()
            .try_into()
            .expect("six outputs")
        };
        JitSurface::compile(&SurfaceTape::with_outputs(g, outputs)).expect("compiles")
    }

    /// Deterministic pseudo-random 64-bit words (xorshift64*).
    struct Words(u64);

    impl Words {
        fn next(&mut self) -> u64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
        }
        /// Uniform in [−m, m].
        fn within(&mut self, m: f64) -> f64 {
            let u = (self.next() >> 11) as f64 / (1u64 << 53) as f64;
            m * (2.0 * u - 1.0)
        }
    }

    /// Arguments: edges (zeros, subnormals, infinities, NaN, the bounds of
    /// the inline code), doubles of every exponent, uniform spreads up to
    /// and past the trig bound, and the doubles nearest multiples of π/2
    /// (where the reduction cancels) with their neighbours.
    fn arguments() -> Vec<f64> {
        let mut a = vec![
            0.0,
            -0.0,
            f64::MIN_POSITIVE,
            -f64::MIN_POSITIVE,
            5e-324,
            -5e-324,
            1e-310,
            1e-300,
            1e-20,
            -1e-20,
            1.5e-8,
            f64::EPSILON,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            -f64::NAN,
            f64::MAX,
            f64::MIN,
            crate::surface::fdlibm::TRIG_LIMIT,
            -crate::surface::fdlibm::TRIG_LIMIT,
            crate::surface::fdlibm::EXP_LIMIT,
            -crate::surface::fdlibm::EXP_LIMIT,
            709.78,
            709.79,
            -745.1,
            -745.2,
            1e22,
            1e300,
            std::f64::consts::PI,
            FRAC_PI_2,
            std::f64::consts::FRAC_PI_4,
        ];
        for v in a.clone() {
            if v.is_finite() {
                a.push(f64::from_bits(v.to_bits() + 1));
                a.push(f64::from_bits(v.to_bits().saturating_sub(1)));
            }
        }
        let mut w = Words(0x9E37_79B9_7F4A_7C15);
        for _ in 0..100_000 {
            // Any double at all, NaNs and infinities included.
            a.push(f64::from_bits(w.next()));
        }
        for m in [1.0, 10.0, 750.0, 1e3, 1e5, 1.7e6, 1e9] {
            for _ in 0..100_000 {
                a.push(w.within(m));
            }
        }
        for _ in 0..50_000 {
            // Near n π/2 for n up to 2^20.
            let n = (w.next() >> 44) as f64;
            let c = n * FRAC_PI_2;
            let b = c.to_bits();
            for d in 0..3 {
                a.push(f64::from_bits(b + d));
                a.push(f64::from_bits(b.saturating_sub(d)));
                a.push(-f64::from_bits(b + d));
            }
        }
        a
    }

    /// The worst distance of output `k` from libm's `f` over `args`, as
    /// (ulps, argument), and how many arguments were off by one.
    fn worst(out: &[f64], args: &[f64], k: usize, f: fn(f64) -> f64) -> (u64, f64, usize) {
        let mut worst = (0, 0.0, 0);
        for (i, &a) in args.iter().enumerate() {
            let d = ulps(out[6 * i + k], f(a));
            if d > worst.0 {
                (worst.0, worst.1) = (d, a);
            }
            worst.2 += usize::from(d == 1);
        }
        worst
    }

    #[test]
    fn sin_cos_and_exp_are_within_one_ulp_of_libm() {
        let args = arguments();
        type Check = (&'static str, usize, fn(f64) -> f64);
        let checks: [Check; 6] = [
            ("sin x", 0, f64::sin),
            ("cos x", 1, f64::cos),
            ("exp x", 2, f64::exp),
            ("sin y", 3, f64::sin),
            ("cos y", 4, f64::cos),
            ("exp y", 5, f64::exp),
        ];
        let mut out = vec![0.0; 6 * args.len()];
        kernel(false).eval_batch(&args, &args, &mut out);
        for (name, k, f) in checks {
            let (d, at, ones) = worst(&out, &args, k, f);
            println!(
                "{name}: worst {d} ulp (at {at:e}), {ones} of {} off by one",
                args.len()
            );
            assert!(d <= 1, "{name} is {d} ulp from libm at {at:e}");
        }
        // Each on its own, and a point alone (the scalar pass): the same
        // bits as in the shared batch.
        let mut alone = vec![0.0; 6 * args.len()];
        let single = kernel(true);
        single.eval_batch(&args, &args, &mut alone);
        for (i, &a) in args.iter().enumerate() {
            assert_eq!(alone[6 * i].to_bits(), out[6 * i].to_bits(), "sin {a:e}");
            assert_eq!(
                alone[6 * i + 1].to_bits(),
                out[6 * i + 4].to_bits(),
                "cos {a:e}"
            );
            if i % 5 == 0 || i < 100 {
                let one = single.eval(a, a);
                let same = |k: usize, j: usize| {
                    one[k].to_bits() == out[6 * i + j].to_bits()
                        || (one[k].is_nan() && out[6 * i + j].is_nan())
                };
                assert!(same(0, 0) && same(1, 4) && same(2, 5), "one point at {a:e}");
            }
        }
    }

    #[test]
    fn a_lane_gives_the_same_bits_whatever_its_neighbour() {
        // A huge argument sends its pair to the libm path; the small one
        // beside it must still get the inline value.
        let f = kernel(false);
        let mut w = Words(7);
        for _ in 0..2_000 {
            let a = w.within(10.0);
            let alone = f.eval(a, a);
            for other in [1e300, f64::NAN, f64::INFINITY, -800.0, 0.5] {
                let mut pair = [0.0; 12];
                f.eval_batch(&[a, other], &[a, other], &mut pair);
                for k in 0..6 {
                    assert_eq!(pair[k].to_bits(), alone[k].to_bits(), "output {k} at {a}");
                }
            }
        }
    }

    #[test]
    fn special_values_are_libms() {
        let f = kernel(false);
        for a in [
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            1e300,
            -0.0,
            0.0,
            710.0,
            -746.0,
            -746.5,
            -800.0,
            -1e300,
            -745.2,
        ] {
            // Alone (the scalar pass) and in both lanes of a pair (the
            // vector pass, or the pair taken again point by point).
            let mut pair = [0.0; 12];
            f.eval_batch(&[a, a], &[0.5, 0.5], &mut pair);
            for o in [f.eval(a, a), pair[..6].try_into().expect("six")] {
                for (k, want) in [a.sin(), a.cos(), a.exp()].into_iter().enumerate() {
                    assert!(
                        o[k].to_bits() == want.to_bits() || (o[k].is_nan() && want.is_nan()),
                        "output {k} at {a}: {} vs {want}",
                        o[k]
                    );
                }
            }
            let bits = |o: &[f64]| o.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&pair[..6]), bits(&pair[6..]), "both lanes at {a}");
        }
    }
}
