//! Eight lanes in one AVX-512 register, for x86-64 builds whose target CPU has AVX-512F.
//!
//! This is the only file in dnnevo with `unsafe` code. Two kinds of call need it, and both are
//! sound here:
//! - The `_mm512_*` intrinsics are `#[target_feature(enable = "avx512f")]` functions. This module
//!   is compiled only when AVX-512F is enabled for the whole crate, so the compiler may already
//!   emit these instructions anywhere in it, and a CPU without them could not run the crate at all.
//! - Loads and stores take raw pointers. Each one reads or writes exactly the eight `f64`s of a
//!   `&[f64; 8]` or `&mut [f64; 8]`, which the borrow checker has already proved valid.
#![allow(unsafe_code)]

use std::arch::x86_64::*;
use std::ops::{Add, Div, Mul, Neg, Sub};

use super::{Arith, Vector};

/// Eight `f64` lanes in a 512-bit register.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Avx512(__m512d);

macro_rules! avx512_op {
    ($trait:ident, $method:ident, $intrinsic:ident) => {
        impl $trait for Avx512 {
            type Output = Self;
            #[inline(always)]
            fn $method(self, o: Self) -> Self {
                // SAFETY: AVX-512F is enabled for the whole crate (module doc).
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
        // SAFETY: AVX-512F is enabled for the whole crate (module doc).
        Avx512(unsafe {
            let sign = _mm512_set1_epi64(i64::MIN);
            _mm512_castsi512_pd(_mm512_xor_si512(_mm512_castpd_si512(self.0), sign))
        })
    }
}

impl Vector for Avx512 {
    type Row = [f64; 8];
    const INTERLEAVE: bool = true;

    #[inline(always)]
    fn load(row: &[f64; 8]) -> Self {
        // SAFETY: reads the 8 values of `row`; AVX-512F is enabled (module doc).
        Avx512(unsafe { _mm512_loadu_pd(row.as_ptr()) })
    }
    #[inline(always)]
    fn store(self, row: &mut [f64; 8]) {
        // SAFETY: writes the 8 values of `row`; AVX-512F is enabled (module doc).
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
    #[inline(always)]
    fn splat(x: f64) -> Self {
        // SAFETY: AVX-512F is enabled for the whole crate (module doc).
        Avx512(unsafe { _mm512_set1_pd(x) })
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        // SAFETY: AVX-512F is enabled for the whole crate (module doc).
        Avx512(unsafe { _mm512_fmadd_pd(self.0, a.0, b.0) })
    }
    /// `min(hi, max(lo, x))` with `x` second: on NaN, x86's min and max return their second
    /// operand, so NaN stays NaN as with [`f64::clamp`].
    #[inline(always)]
    fn clamp(self, lo: f64, hi: f64) -> Self {
        // SAFETY: AVX-512F is enabled for the whole crate (module doc).
        Avx512(unsafe {
            let low = _mm512_max_pd(_mm512_set1_pd(lo), self.0);
            _mm512_min_pd(_mm512_set1_pd(hi), low)
        })
    }
    /// `vscalefpd`: `self * 2^floor(k)` with one rounding, which is exact for the lanes the
    /// trait allows, so it agrees with the portable multiply by a constructed `2^k`.
    #[inline(always)]
    fn mul_pow2(self, k: Self) -> Self {
        // SAFETY: AVX-512F is enabled for the whole crate (module doc).
        Avx512(unsafe { _mm512_scalef_pd(self.0, k.0) })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{exp_lanes, sigmoid_lanes};
    use crate::vector::{Group, Portable};

    /// Runs `f` on both backends, eight inputs at a time, and demands the same bits.
    fn same_bits(
        inputs: &[f64],
        f_avx: fn(Avx512) -> Avx512,
        f_ref: fn(Portable<8>) -> Portable<8>,
    ) {
        for chunk in inputs.chunks(8) {
            let mut x = [0.0; 8];
            x[..chunk.len()].copy_from_slice(chunk);
            let mut got = [0.0; 8];
            f_avx(Avx512::load(&x)).store(&mut got);
            let want = f_ref(Group(x)).0;
            for l in 0..8 {
                assert!(
                    got[l].to_bits() == want[l].to_bits() || got[l].is_nan() && want[l].is_nan(),
                    "x = {:e}: {:e} (AVX-512) vs {:e} (portable)",
                    x[l],
                    got[l],
                    want[l]
                );
            }
        }
    }

    fn inputs() -> Vec<f64> {
        let mut x: Vec<f64> = (0..=400_000)
            .map(|i| -40.0 + 80.0 * i as f64 / 4e5)
            .collect();
        x.extend((0..=20_000).map(|i| -800.0 + 1600.0 * i as f64 / 2e4));
        x.extend([
            0.0,
            -0.0,
            -708.0,
            709.0,
            -708.0000001,
            709.0000001,
            -745.2,
            1e300,
            -1e300,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            f64::MIN_POSITIVE,
            -f64::MIN_POSITIVE,
            5e-324,
        ]);
        x
    }

    #[test]
    fn exp_matches_the_portable_backend_bit_for_bit() {
        same_bits(&inputs(), exp_lanes, exp_lanes);
    }

    #[test]
    fn sigmoid_matches_the_portable_backend_bit_for_bit() {
        same_bits(&inputs(), sigmoid_lanes, sigmoid_lanes);
    }

    #[test]
    fn negation_keeps_the_sign_of_zero() {
        let mut out = [1.0; 8];
        (-Avx512::splat(0.0)).store(&mut out);
        assert!(out.iter().all(|x| x.to_bits() == (-0.0f64).to_bits()));
    }
}
