//! The logistic sigmoid and the exponential behind it, written so that loops over them vectorise.
//!
//! `f64::exp` calls the C library and blocks vectorisation, and its last bit differs between
//! platforms. [`exp`] is a branch-free range reduction plus a degree-13 polynomial: within 2 ulp of
//! the exact value, the same bits on every platform, and cheap enough that an integration step is
//! limited by arithmetic, not by calls.
//!
//! Both are written once, over the crate's lane vectors, and run on one network or on a block of
//! networks with the same operations in the same order; [`exp`] and [`sigmoid`] are the
//! one-value versions.
//!
//! Multiply-adds are written as [`f64::mul_add`], which is always fused (one rounding): a single
//! FMA instruction in code compiled for a CPU that has one (every x86-64 kernel but the portable
//! one, and every 64-bit ARM), and the same bits, slowly, in software elsewhere. Every code path in dnnevo (single network, population,
//! tasks) uses [`sigmoid`], which is what makes them agree bit for bit.

use crate::vector::{Arith, ROUND_SHIFT};

const INV_LN2: f64 = std::f64::consts::LOG2_E;
/// ln 2 split into a part with trailing zero bits (exact when multiplied by k) and the rest.
const LN2_HI: f64 = f64::from_bits(0x3FE6_2E42_FEE0_0000);
const LN2_LO: f64 = f64::from_bits(0x3DEA_39EF_3579_3C76);
/// Arguments are clamped to this range, where `2^k` stays a normal number.
pub(crate) const EXP_MIN: f64 = -708.0;
pub(crate) const EXP_MAX: f64 = 709.0;
/// 1/n! for n = 13 down to 2 (Taylor coefficients of e^r; with |r| <= ln2/2 the truncation error
/// is below 1e-17 relative).
const TAYLOR: [f64; 12] = [
    1.0 / 6_227_020_800.0,
    1.0 / 479_001_600.0,
    1.0 / 39_916_800.0,
    1.0 / 3_628_800.0,
    1.0 / 362_880.0,
    1.0 / 40_320.0,
    1.0 / 5_040.0,
    1.0 / 720.0,
    1.0 / 120.0,
    1.0 / 24.0,
    1.0 / 6.0,
    0.5,
];

/// e^x, within 2 ulp for x in [-708, 709]; arguments outside are clamped to that range, so the
/// result is never 0 or infinite. NaN stays NaN.
///
/// # Example
/// ```
/// let e = ctrnn::math::exp(1.0);
/// assert!((e - std::f64::consts::E).abs() <= 2.0 * f64::EPSILON * e);
/// ```
#[inline]
pub fn exp(x: f64) -> f64 {
    with_fma(
        #[inline(always)]
        || exp_lanes(x),
    )
}

/// The logistic firing rate `1 / (1 + e^(-x))`.
///
/// # Example
/// ```
/// assert_eq!(ctrnn::math::sigmoid(0.0), 0.5);
/// ```
#[inline]
pub fn sigmoid(x: f64) -> f64 {
    with_fma(
        #[inline(always)]
        || sigmoid_lanes(x),
    )
}

/// Firing rates `out[i] = f(v[i] - theta[i])`, each with the same bits as [`sigmoid`], in one
/// call: cheaper than one [`sigmoid`] call per neuron.
///
/// # Example
/// ```
/// let mut out = [0.0; 2];
/// ctrnn::math::firing_rates(&[1.0, 0.5], &[1.0, 2.0], &mut out);
/// assert_eq!(out, [0.5, ctrnn::math::sigmoid(-1.5)]);
/// ```
pub fn firing_rates(v: &[f64], theta: &[f64], out: &mut [f64]) {
    with_fma(
        #[inline(always)]
        || {
            for ((o, x), t) in out.iter_mut().zip(v).zip(theta) {
                *o = sigmoid_lanes(x - t);
            }
        },
    )
}

/// `f()`, compiled with the CPU's fused multiply-add instruction where the kernel in use has one
/// ([`crate::simd`]); elsewhere `f64::mul_add` is done in software. The same bits either way.
/// `f` must be `#[inline(always)]`, or it is compiled without the instruction.
#[inline(always)]
fn with_fma<R>(f: impl FnOnce() -> R) -> R {
    #[cfg(target_arch = "x86_64")]
    if crate::simd::kernel() != crate::simd::Kernel::Portable {
        // SAFETY: every kernel but the portable one needs AVX2 and FMA, and `simd` only hands
        // out kernels that the CPU supports.
        #[allow(unsafe_code)]
        return unsafe { crate::vector::avx2::enabled(f) };
    }
    f()
}

/// [`exp`] in every lane.
#[inline(always)]
pub(crate) fn exp_lanes<V: Arith>(x: V) -> V {
    let x = x.clamp(EXP_MIN, EXP_MAX);
    // k = round(x / ln2), computed without a float-to-int conversion.
    let shifted = x.mul_add(V::splat(INV_LN2), V::splat(ROUND_SHIFT));
    let k = shifted - V::splat(ROUND_SHIFT);
    let r = (-k).mul_add(V::splat(LN2_LO), (-k).mul_add(V::splat(LN2_HI), x));
    // Estrin's scheme: the same polynomial as Horner's, with a dependency chain a third as long.
    // (No closures or `map` here: see `Group` on why the kernel is inlined all the way.)
    #[inline(always)]
    fn c<V: Arith>(i: usize) -> V {
        V::splat(TAYLOR[i])
    }
    let r2 = r * r;
    let r4 = r2 * r2;
    let r8 = r4 * r4;
    let s0 = c::<V>(8)
        .mul_add(r, c::<V>(9))
        .mul_add(r2, c::<V>(10).mul_add(r, c::<V>(11)));
    let s1 = c::<V>(4)
        .mul_add(r, c::<V>(5))
        .mul_add(r2, c::<V>(6).mul_add(r, c::<V>(7)));
    let s2 = c::<V>(0)
        .mul_add(r, c::<V>(1))
        .mul_add(r2, c::<V>(2).mul_add(r, c::<V>(3)));
    let p = s2.mul_add(r8, s1.mul_add(r4, s0));
    let er = V::splat(1.0) + r2.mul_add(p, r);
    er.mul_pow2(k)
}

/// [`sigmoid`] in every lane.
#[inline(always)]
pub(crate) fn sigmoid_lanes<V: Arith>(x: V) -> V {
    let one = V::splat(1.0);
    one / (one + exp_lanes(-x))
}
