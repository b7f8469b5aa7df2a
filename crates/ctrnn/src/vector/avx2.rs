//! Four lanes in one 256-bit register, for x86-64 CPUs with AVX2 and FMA.
//!
//! The intrinsics are `#[target_feature(enable = "avx2,fma")]` functions. The operations below
//! are inlined into [`enabled`], which has those features, and they are only reached through it,
//! when [`crate::simd::kernel`] says the CPU has them. Loads and stores read or write exactly the
//! four `f64`s of a borrowed `[f64; 4]`.
#![allow(unsafe_code)]

use std::arch::x86_64::*;
use std::ops::{Add, Div, Mul, Neg, Sub};

use super::{Arith, Vector, ROUND_SHIFT};

/// Runs `f` compiled for AVX2 and FMA: the generic kernel that `f` calls is inlined here, so it
/// is compiled for these features.
///
/// # Safety
/// The CPU must have AVX2 and FMA ([`crate::simd::Kernel::Avx2`] is supported).
#[target_feature(enable = "avx2,fma")]
pub unsafe fn enabled<R>(f: impl FnOnce() -> R) -> R {
    f()
}

/// Four `f64` lanes in a 256-bit register.
#[derive(Clone, Copy, Debug)]
pub struct Avx2(__m256d);

macro_rules! avx2_op {
    ($trait:ident, $method:ident, $intrinsic:ident) => {
        impl $trait for Avx2 {
            type Output = Self;
            #[inline(always)]
            fn $method(self, o: Self) -> Self {
                // SAFETY: reached only through `enabled` (module doc).
                Avx2(unsafe { $intrinsic(self.0, o.0) })
            }
        }
    };
}
avx2_op!(Add, add, _mm256_add_pd);
avx2_op!(Sub, sub, _mm256_sub_pd);
avx2_op!(Mul, mul, _mm256_mul_pd);
avx2_op!(Div, div, _mm256_div_pd);

impl Neg for Avx2 {
    type Output = Self;
    /// Flips the sign bit, exactly as scalar negation does (so `-0.0` stays distinct from `0.0`).
    #[inline(always)]
    fn neg(self) -> Self {
        // SAFETY: reached only through `enabled` (module doc).
        Avx2(unsafe { _mm256_xor_pd(self.0, _mm256_set1_pd(-0.0)) })
    }
}

impl Vector for Avx2 {
    type Row = [f64; 4];
    /// A block of 16 networks is already four registers computed together; grouping four neurons
    /// on top would want 16 registers per operand, all AVX2 has (measured: no faster).
    const INTERLEAVE: bool = false;
    /// Half of the 16 `ymm` registers; the rest hold the firing rates and weights.
    const SUM_REGISTERS: usize = 8;

    #[inline(always)]
    fn load(row: &[f64; 4]) -> Self {
        // SAFETY: reads the 4 values of `row`; reached only through `enabled` (module doc).
        Avx2(unsafe { _mm256_loadu_pd(row.as_ptr()) })
    }
    #[inline(always)]
    fn store(self, row: &mut [f64; 4]) {
        // SAFETY: writes the 4 values of `row`; reached only through `enabled` (module doc).
        unsafe { _mm256_storeu_pd(row.as_mut_ptr(), self.0) }
    }
    #[inline(always)]
    fn rows(flat: &[f64]) -> &[[f64; 4]] {
        let (rows, rest) = flat.as_chunks();
        debug_assert!(rest.is_empty());
        rows
    }
    #[inline(always)]
    fn rows_mut(flat: &mut [f64]) -> &mut [[f64; 4]] {
        let (rows, rest) = flat.as_chunks_mut();
        debug_assert!(rest.is_empty());
        rows
    }
    #[inline(always)]
    fn prefetch(row: &[f64; 4]) {
        // SAFETY: a prefetch is a hint and never faults; the address is that of `row`.
        unsafe { _mm_prefetch::<_MM_HINT_T0>(row.as_ptr().cast()) }
    }
}

impl Arith for Avx2 {
    type Elem = f64;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        // SAFETY: reached only through `enabled` (module doc).
        Avx2(unsafe { _mm256_set1_pd(x) })
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        // SAFETY: reached only through `enabled` (module doc).
        Avx2(unsafe { _mm256_fmadd_pd(self.0, a.0, b.0) })
    }
    /// `min(hi, max(lo, x))` with `x` second: on NaN, x86's min and max return their second
    /// operand, so NaN stays NaN as with [`f64::clamp`].
    #[inline(always)]
    fn clamp(self, lo: f64, hi: f64) -> Self {
        // SAFETY: reached only through `enabled` (module doc).
        Avx2(unsafe {
            let low = _mm256_max_pd(_mm256_set1_pd(lo), self.0);
            _mm256_min_pd(_mm256_set1_pd(hi), low)
        })
    }
    /// Builds `2^k` from its bits with 64-bit integer lanes, as the portable backend does, and
    /// multiplies: the same bits.
    #[inline(always)]
    fn mul_pow2(self, k: Self) -> Self {
        // SAFETY: reached only through `enabled` (module doc).
        Avx2(unsafe {
            let shift = _mm256_set1_pd(ROUND_SHIFT);
            let k_int = _mm256_sub_epi64(
                _mm256_castpd_si256(_mm256_add_pd(k.0, shift)),
                _mm256_castpd_si256(shift),
            );
            let biased = _mm256_add_epi64(k_int, _mm256_set1_epi64x(1023));
            let pow2 = _mm256_castsi256_pd(_mm256_slli_epi64::<52>(biased));
            _mm256_mul_pd(self.0, pow2)
        })
    }
}
