//! Eight lanes in one AVX-512 register, for x86-64 CPUs with AVX-512F.
//!
//! The intrinsics are `#[target_feature(enable = "avx512f")]` functions. The operations below
//! are inlined into [`enabled`], which has that feature, and they are only reached through it,
//! when [`crate::simd::kernel`] says the CPU has it. Loads and stores read or write exactly the
//! eight `f64`s of a borrowed `[f64; 8]`.
#![allow(unsafe_code)]

use std::arch::x86_64::*;
use std::ops::{Add, Div, Mul, Neg, Sub};

use super::{Arith, Vector};

/// Runs `f` compiled for AVX-512F (and the AVX2 and FMA it implies): the generic kernel that
/// `f` calls is inlined here, so it is compiled for these features.
///
/// # Safety
/// The CPU must have AVX-512F, AVX2 and FMA ([`crate::simd::Kernel::Avx512`] is supported).
#[target_feature(enable = "avx512f,avx2,fma")]
pub unsafe fn enabled<R>(f: impl FnOnce() -> R) -> R {
    f()
}

/// Eight `f64` lanes in a 512-bit register.
#[derive(Clone, Copy, Debug)]
pub struct Avx512(__m512d);

macro_rules! avx512_op {
    ($trait:ident, $method:ident, $intrinsic:ident) => {
        impl $trait for Avx512 {
            type Output = Self;
            #[inline(always)]
            fn $method(self, o: Self) -> Self {
                // SAFETY: reached only through `enabled` (module doc).
                Avx512(unsafe { $intrinsic(self.0, o.0) })
            }
        }
    };
}
avx512_op!(Add, add, _mm512_add_pd);
avx512_op!(Sub, sub, _mm512_sub_pd);
avx512_op!(Mul, mul, _mm512_mul_pd);
avx512_op!(Div, div, _mm512_div_pd);

impl Neg for Avx512 {
    type Output = Self;
    /// Flips the sign bit, exactly as scalar negation does (so `-0.0` stays distinct from `0.0`).
    #[inline(always)]
    fn neg(self) -> Self {
        // SAFETY: reached only through `enabled` (module doc).
        Avx512(unsafe {
            let sign = _mm512_set1_epi64(i64::MIN);
            _mm512_castsi512_pd(_mm512_xor_si512(_mm512_castpd_si512(self.0), sign))
        })
    }
}

impl Vector for Avx512 {
    type Row = [f64; 8];
    const INTERLEAVE: bool = true;
    /// Half of the 32 `zmm` registers; the rest hold the firing rates and weights.
    const SUM_REGISTERS: usize = 16;

    #[inline(always)]
    fn load(row: &[f64; 8]) -> Self {
        // SAFETY: reads the 8 values of `row`; reached only through `enabled` (module doc).
        Avx512(unsafe { _mm512_loadu_pd(row.as_ptr()) })
    }
    #[inline(always)]
    fn store(self, row: &mut [f64; 8]) {
        // SAFETY: writes the 8 values of `row`; reached only through `enabled` (module doc).
        unsafe { _mm512_storeu_pd(row.as_mut_ptr(), self.0) }
    }
    #[inline(always)]
    fn rows(flat: &[f64]) -> &[[f64; 8]] {
        let (rows, rest) = flat.as_chunks();
        debug_assert!(rest.is_empty());
        rows
    }
    #[inline(always)]
    fn rows_mut(flat: &mut [f64]) -> &mut [[f64; 8]] {
        let (rows, rest) = flat.as_chunks_mut();
        debug_assert!(rest.is_empty());
        rows
    }
    #[inline(always)]
    fn prefetch(row: &[f64; 8]) {
        // SAFETY: a prefetch is a hint and never faults; the address is that of `row`.
        unsafe { _mm_prefetch::<_MM_HINT_T0>(row.as_ptr().cast()) }
    }
}

impl Arith for Avx512 {
    type Elem = f64;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        // SAFETY: reached only through `enabled` (module doc).
        Avx512(unsafe { _mm512_set1_pd(x) })
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        // SAFETY: reached only through `enabled` (module doc).
        Avx512(unsafe { _mm512_fmadd_pd(self.0, a.0, b.0) })
    }
    /// `min(hi, max(lo, x))` with `x` second: on NaN, x86's min and max return their second
    /// operand, so NaN stays NaN as with [`f64::clamp`].
    #[inline(always)]
    fn clamp(self, lo: f64, hi: f64) -> Self {
        // SAFETY: reached only through `enabled` (module doc).
        Avx512(unsafe {
            let low = _mm512_max_pd(_mm512_set1_pd(lo), self.0);
            _mm512_min_pd(_mm512_set1_pd(hi), low)
        })
    }
    /// `vscalefpd`: `self * 2^floor(k)` with one rounding, which is exact for the lanes the
    /// trait allows, so it agrees with the portable multiply by a constructed `2^k`.
    #[inline(always)]
    fn mul_pow2(self, k: Self) -> Self {
        // SAFETY: reached only through `enabled` (module doc).
        Avx512(unsafe { _mm512_scalef_pd(self.0, k.0) })
    }
}
