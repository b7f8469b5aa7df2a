//! Four `f32` lanes in one 128-bit register, for 64-bit ARM (AArch64) CPUs: the single
//! precision twin of [`super::neon`]. Loads and stores read or write exactly the four `f32`s of
//! a borrowed `[f32; 4]`.
#![allow(unsafe_code, unused_unsafe)]

use std::arch::aarch64::*;
use std::ops::{Add, Div, Mul, Neg, Sub};

use super::{Arith, Vector, ROUND_SHIFT_F32};

/// Four `f32` lanes in a 128-bit register.
#[derive(Clone, Copy, Debug)]
pub struct NeonF32(float32x4_t);

macro_rules! neon_op {
    ($trait:ident, $method:ident, $intrinsic:ident) => {
        impl $trait for NeonF32 {
            type Output = Self;
            #[inline(always)]
            fn $method(self, o: Self) -> Self {
                // SAFETY: NEON is part of every AArch64 CPU (module doc).
                NeonF32(unsafe { $intrinsic(self.0, o.0) })
            }
        }
    };
}
neon_op!(Add, add, vaddq_f32);
neon_op!(Sub, sub, vsubq_f32);
neon_op!(Mul, mul, vmulq_f32);
neon_op!(Div, div, vdivq_f32);

impl Neg for NeonF32 {
    type Output = Self;
    /// `fneg` flips the sign bit, exactly as scalar negation does.
    #[inline(always)]
    fn neg(self) -> Self {
        // SAFETY: NEON is part of every AArch64 CPU (module doc).
        NeonF32(unsafe { vnegq_f32(self.0) })
    }
}

impl Vector for NeonF32 {
    type Row = [f32; 4];
    /// A block of 16 networks is already four registers computed together.
    const INTERLEAVE: bool = false;
    /// Half of the 32 vector registers; the rest hold the firing rates and weights.
    const SUM_REGISTERS: usize = 16;

    #[inline(always)]
    fn load(row: &[f32; 4]) -> Self {
        // SAFETY: reads the 4 values of `row`.
        NeonF32(unsafe { vld1q_f32(row.as_ptr()) })
    }
    #[inline(always)]
    fn store(self, row: &mut [f32; 4]) {
        // SAFETY: writes the 4 values of `row`.
        unsafe { vst1q_f32(row.as_mut_ptr(), self.0) }
    }
    #[inline(always)]
    fn rows(flat: &[f32]) -> &[[f32; 4]] {
        let (rows, rest) = flat.as_chunks();
        debug_assert!(rest.is_empty());
        rows
    }
    #[inline(always)]
    fn rows_mut(flat: &mut [f32]) -> &mut [[f32; 4]] {
        let (rows, rest) = flat.as_chunks_mut();
        debug_assert!(rest.is_empty());
        rows
    }
}

impl Arith for NeonF32 {
    type Elem = f32;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        // SAFETY: NEON is part of every AArch64 CPU (module doc).
        NeonF32(unsafe { vdupq_n_f32(x as f32) })
    }
    /// `vfmaq_f32(b, s, a)` is `b + s * a` with one rounding.
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        // SAFETY: NEON is part of every AArch64 CPU (module doc).
        NeonF32(unsafe { vfmaq_f32(b.0, self.0, a.0) })
    }
    /// `min(max(x, lo), hi)`: ARM's `fmax` and `fmin` return NaN when an operand is NaN, so NaN
    /// stays NaN as with [`f32::clamp`].
    #[inline(always)]
    fn clamp(self, lo: f64, hi: f64) -> Self {
        // SAFETY: NEON is part of every AArch64 CPU (module doc).
        NeonF32(unsafe {
            vminq_f32(
                vmaxq_f32(self.0, vdupq_n_f32(lo as f32)),
                vdupq_n_f32(hi as f32),
            )
        })
    }
    /// Builds `2^k` from its bits with 32-bit integer lanes, as the portable backend does, and
    /// multiplies: the same bits.
    #[inline(always)]
    fn mul_pow2(self, k: Self) -> Self {
        // SAFETY: NEON is part of every AArch64 CPU (module doc).
        NeonF32(unsafe {
            let shift = vdupq_n_f32(ROUND_SHIFT_F32);
            let k_int = vsubq_s32(
                vreinterpretq_s32_f32(vaddq_f32(k.0, shift)),
                vreinterpretq_s32_f32(shift),
            );
            let biased = vaddq_s32(k_int, vdupq_n_s32(127));
            vmulq_f32(self.0, vreinterpretq_f32_s32(vshlq_n_s32::<23>(biased)))
        })
    }
}
