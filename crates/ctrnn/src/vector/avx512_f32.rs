//! Sixteen `f32` lanes in one AVX-512 register, for x86-64 CPUs with AVX-512F: the single
//! precision twin of [`super::avx512`].
//!
//! The operations below are inlined into [`super::avx512::enabled`], which has the features,
//! and they are only reached through it, when [`crate::simd::kernel`] says the CPU has them.
//! Loads and stores read or write exactly the sixteen `f32`s of a borrowed `[f32; 16]`.
#![allow(unsafe_code)]

use std::arch::x86_64::*;
use std::ops::{Add, Div, Mul, Neg, Sub};

use super::{Arith, Vector};

/// Sixteen `f32` lanes in a 512-bit register.
#[derive(Clone, Copy, Debug)]
pub struct Avx512F32(__m512);

macro_rules! avx512_op {
    ($trait:ident, $method:ident, $intrinsic:ident) => {
        impl $trait for Avx512F32 {
            type Output = Self;
            #[inline(always)]
            fn $method(self, o: Self) -> Self {
                // SAFETY: reached only through `enabled` (module doc).
                Avx512F32(unsafe { $intrinsic(self.0, o.0) })
            }
        }
    };
}
avx512_op!(Add, add, _mm512_add_ps);
avx512_op!(Sub, sub, _mm512_sub_ps);
avx512_op!(Mul, mul, _mm512_mul_ps);
avx512_op!(Div, div, _mm512_div_ps);

impl Neg for Avx512F32 {
    type Output = Self;
    /// Flips the sign bit, exactly as scalar negation does (so `-0.0` stays distinct from `0.0`).
    #[inline(always)]
    fn neg(self) -> Self {
        // SAFETY: reached only through `enabled` (module doc).
        Avx512F32(unsafe {
            let sign = _mm512_set1_epi32(i32::MIN);
            _mm512_castsi512_ps(_mm512_xor_si512(_mm512_castps_si512(self.0), sign))
        })
    }
}

impl Vector for Avx512F32 {
    type Row = [f32; 16];
    const INTERLEAVE: bool = true;
    /// Half of the 32 `zmm` registers; the rest hold the firing rates and weights.
    const SUM_REGISTERS: usize = 16;

    #[inline(always)]
    fn load(row: &[f32; 16]) -> Self {
        // SAFETY: reads the 16 values of `row`; reached only through `enabled` (module doc).
        Avx512F32(unsafe { _mm512_loadu_ps(row.as_ptr()) })
    }
    #[inline(always)]
    fn store(self, row: &mut [f32; 16]) {
        // SAFETY: writes the 16 values of `row`; reached only through `enabled` (module doc).
        unsafe { _mm512_storeu_ps(row.as_mut_ptr(), self.0) }
    }
    #[inline(always)]
    fn rows(flat: &[f32]) -> &[[f32; 16]] {
        let (rows, rest) = flat.as_chunks();
        debug_assert!(rest.is_empty());
        rows
    }
    #[inline(always)]
    fn rows_mut(flat: &mut [f32]) -> &mut [[f32; 16]] {
        let (rows, rest) = flat.as_chunks_mut();
        debug_assert!(rest.is_empty());
        rows
    }
    #[inline(always)]
    fn prefetch(row: &[f32; 16]) {
        // SAFETY: a prefetch is a hint and never faults; the address is that of `row`.
        unsafe { _mm_prefetch::<_MM_HINT_T0>(row.as_ptr().cast()) }
    }
}

impl Arith for Avx512F32 {
    type Elem = f32;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        // SAFETY: reached only through `enabled` (module doc).
        Avx512F32(unsafe { _mm512_set1_ps(x as f32) })
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        // SAFETY: reached only through `enabled` (module doc).
        Avx512F32(unsafe { _mm512_fmadd_ps(self.0, a.0, b.0) })
    }
    /// `min(hi, max(lo, x))` with `x` second: on NaN, x86's min and max return their second
    /// operand, so NaN stays NaN as with [`f32::clamp`].
    #[inline(always)]
    fn clamp(self, lo: f64, hi: f64) -> Self {
        // SAFETY: reached only through `enabled` (module doc).
        Avx512F32(unsafe {
            let low = _mm512_max_ps(_mm512_set1_ps(lo as f32), self.0);
            _mm512_min_ps(_mm512_set1_ps(hi as f32), low)
        })
    }
    /// `vscalefps`: `self * 2^floor(k)` with one rounding, which is exact for the lanes the
    /// trait allows, so it agrees with the portable multiply by a constructed `2^k`.
    #[inline(always)]
    fn mul_pow2(self, k: Self) -> Self {
        // SAFETY: reached only through `enabled` (module doc).
        Avx512F32(unsafe { _mm512_scalef_ps(self.0, k.0) })
    }
}
