//! Eight `f32` lanes in one 256-bit register, for x86-64 CPUs with AVX2 and FMA: the single
//! precision twin of [`super::avx2`].
//!
//! The operations below are inlined into [`super::avx2::enabled`] (or the AVX-512 one), which
//! has the features, and they are only reached through it, when [`crate::simd::kernel`] says the
//! CPU has them. Loads and stores read or write exactly the eight `f32`s of a borrowed
//! `[f32; 8]`.
#![allow(unsafe_code)]

use std::arch::x86_64::*;
use std::ops::{Add, Div, Mul, Neg, Sub};

use super::{Arith, Vector, ROUND_SHIFT_F32};

/// Eight `f32` lanes in a 256-bit register.
#[derive(Clone, Copy, Debug)]
pub struct Avx2F32(__m256);

macro_rules! avx2_op {
    ($trait:ident, $method:ident, $intrinsic:ident) => {
        impl $trait for Avx2F32 {
            type Output = Self;
            #[inline(always)]
            fn $method(self, o: Self) -> Self {
                // SAFETY: reached only through `enabled` (module doc).
                Avx2F32(unsafe { $intrinsic(self.0, o.0) })
            }
        }
    };
}
avx2_op!(Add, add, _mm256_add_ps);
avx2_op!(Sub, sub, _mm256_sub_ps);
avx2_op!(Mul, mul, _mm256_mul_ps);
avx2_op!(Div, div, _mm256_div_ps);

impl Neg for Avx2F32 {
    type Output = Self;
    /// Flips the sign bit, exactly as scalar negation does (so `-0.0` stays distinct from `0.0`).
    #[inline(always)]
    fn neg(self) -> Self {
        // SAFETY: reached only through `enabled` (module doc).
        Avx2F32(unsafe { _mm256_xor_ps(self.0, _mm256_set1_ps(-0.0)) })
    }
}

impl Vector for Avx2F32 {
    type Row = [f32; 8];
    /// As for f64: a block is already two registers computed together.
    const INTERLEAVE: bool = false;
    /// Half of the 16 `ymm` registers; the rest hold the firing rates and weights.
    const SUM_REGISTERS: usize = 8;

    #[inline(always)]
    fn load(row: &[f32; 8]) -> Self {
        // SAFETY: reads the 8 values of `row`; reached only through `enabled` (module doc).
        Avx2F32(unsafe { _mm256_loadu_ps(row.as_ptr()) })
    }
    #[inline(always)]
    fn store(self, row: &mut [f32; 8]) {
        // SAFETY: writes the 8 values of `row`; reached only through `enabled` (module doc).
        unsafe { _mm256_storeu_ps(row.as_mut_ptr(), self.0) }
    }
    #[inline(always)]
    fn rows(flat: &[f32]) -> &[[f32; 8]] {
        let (rows, rest) = flat.as_chunks();
        debug_assert!(rest.is_empty());
        rows
    }
    #[inline(always)]
    fn rows_mut(flat: &mut [f32]) -> &mut [[f32; 8]] {
        let (rows, rest) = flat.as_chunks_mut();
        debug_assert!(rest.is_empty());
        rows
    }
    #[inline(always)]
    fn prefetch(row: &[f32; 8]) {
        // SAFETY: a prefetch is a hint and never faults; the address is that of `row`.
        unsafe { _mm_prefetch::<_MM_HINT_T0>(row.as_ptr().cast()) }
    }
}

impl Arith for Avx2F32 {
    type Elem = f32;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        // SAFETY: reached only through `enabled` (module doc).
        Avx2F32(unsafe { _mm256_set1_ps(x as f32) })
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        // SAFETY: reached only through `enabled` (module doc).
        Avx2F32(unsafe { _mm256_fmadd_ps(self.0, a.0, b.0) })
    }
    /// `min(hi, max(lo, x))` with `x` second: on NaN, x86's min and max return their second
    /// operand, so NaN stays NaN as with [`f32::clamp`].
    #[inline(always)]
    fn clamp(self, lo: f64, hi: f64) -> Self {
        // SAFETY: reached only through `enabled` (module doc).
        Avx2F32(unsafe {
            let low = _mm256_max_ps(_mm256_set1_ps(lo as f32), self.0);
            _mm256_min_ps(_mm256_set1_ps(hi as f32), low)
        })
    }
    /// Builds `2^k` from its bits with 32-bit integer lanes, as the portable backend does, and
    /// multiplies: the same bits.
    #[inline(always)]
    fn mul_pow2(self, k: Self) -> Self {
        // SAFETY: reached only through `enabled` (module doc).
        Avx2F32(unsafe {
            let shift = _mm256_set1_ps(ROUND_SHIFT_F32);
            let k_int = _mm256_sub_epi32(
                _mm256_castps_si256(_mm256_add_ps(k.0, shift)),
                _mm256_castps_si256(shift),
            );
            let biased = _mm256_add_epi32(k_int, _mm256_set1_epi32(127));
            let pow2 = _mm256_castsi256_ps(_mm256_slli_epi32::<23>(biased));
            _mm256_mul_ps(self.0, pow2)
        })
    }
}
