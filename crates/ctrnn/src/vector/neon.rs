//! Two lanes in one 128-bit register, for 64-bit ARM (AArch64) CPUs.
//!
//! NEON, with its fused multiply-add, is part of every AArch64 CPU, so unlike the x86-64
//! backends this one needs no run-time check and no `enabled` wrapper: the whole crate is
//! compiled with it. Loads and stores read or write exactly the two `f64`s of a borrowed
//! `[f64; 2]`. (Older compilers declare even the arithmetic intrinsics `unsafe`; the blocks
//! below keep the code building on both.)
#![allow(unsafe_code, unused_unsafe)]

use std::arch::aarch64::*;
use std::ops::{Add, Div, Mul, Neg, Sub};

use super::{Arith, Vector, ROUND_SHIFT};

/// Two `f64` lanes in a 128-bit register.
#[derive(Clone, Copy, Debug)]
pub struct Neon(float64x2_t);

macro_rules! neon_op {
    ($trait:ident, $method:ident, $intrinsic:ident) => {
        impl $trait for Neon {
            type Output = Self;
            #[inline(always)]
            fn $method(self, o: Self) -> Self {
                // SAFETY: NEON is part of every AArch64 CPU (module doc).
                Neon(unsafe { $intrinsic(self.0, o.0) })
            }
        }
    };
}
neon_op!(Add, add, vaddq_f64);
neon_op!(Sub, sub, vsubq_f64);
neon_op!(Mul, mul, vmulq_f64);
neon_op!(Div, div, vdivq_f64);

impl Neg for Neon {
    type Output = Self;
    /// `fneg` flips the sign bit, exactly as scalar negation does.
    #[inline(always)]
    fn neg(self) -> Self {
        // SAFETY: NEON is part of every AArch64 CPU (module doc).
        Neon(unsafe { vnegq_f64(self.0) })
    }
}

impl Vector for Neon {
    type Row = [f64; 2];
    /// A block of 16 networks is already eight registers computed together.
    const INTERLEAVE: bool = false;
    /// Half of the 32 vector registers; the rest hold the firing rates and weights.
    const SUM_REGISTERS: usize = 16;

    #[inline(always)]
    fn load(row: &[f64; 2]) -> Self {
        // SAFETY: reads the 2 values of `row`.
        Neon(unsafe { vld1q_f64(row.as_ptr()) })
    }
    #[inline(always)]
    fn store(self, row: &mut [f64; 2]) {
        // SAFETY: writes the 2 values of `row`.
        unsafe { vst1q_f64(row.as_mut_ptr(), self.0) }
    }
    #[inline(always)]
    fn rows(flat: &[f64]) -> &[[f64; 2]] {
        let (rows, rest) = flat.as_chunks();
        debug_assert!(rest.is_empty());
        rows
    }
    #[inline(always)]
    fn rows_mut(flat: &mut [f64]) -> &mut [[f64; 2]] {
        let (rows, rest) = flat.as_chunks_mut();
        debug_assert!(rest.is_empty());
        rows
    }
}

impl Arith for Neon {
    type Elem = f64;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        // SAFETY: NEON is part of every AArch64 CPU (module doc).
        Neon(unsafe { vdupq_n_f64(x) })
    }
    /// `vfmaq_f64(b, s, a)` is `b + s * a` with one rounding.
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        // SAFETY: NEON is part of every AArch64 CPU (module doc).
        Neon(unsafe { vfmaq_f64(b.0, self.0, a.0) })
    }
    /// `min(max(x, lo), hi)`: ARM's `fmax` and `fmin` return NaN when an operand is NaN, so NaN
    /// stays NaN as with [`f64::clamp`].
    #[inline(always)]
    fn clamp(self, lo: f64, hi: f64) -> Self {
        // SAFETY: NEON is part of every AArch64 CPU (module doc).
        Neon(unsafe { vminq_f64(vmaxq_f64(self.0, vdupq_n_f64(lo)), vdupq_n_f64(hi)) })
    }
    /// Builds `2^k` from its bits with 64-bit integer lanes, as the portable backend does, and
    /// multiplies: the same bits.
    #[inline(always)]
    fn mul_pow2(self, k: Self) -> Self {
        // SAFETY: NEON is part of every AArch64 CPU (module doc).
        Neon(unsafe {
            let shift = vdupq_n_f64(ROUND_SHIFT);
            let k_int = vsubq_s64(
                vreinterpretq_s64_f64(vaddq_f64(k.0, shift)),
                vreinterpretq_s64_f64(shift),
            );
            let biased = vaddq_s64(k_int, vdupq_n_s64(1023));
            vmulq_f64(self.0, vreinterpretq_f64_s64(vshlq_n_s64::<52>(biased)))
        })
    }
}
