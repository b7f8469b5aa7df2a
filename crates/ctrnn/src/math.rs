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
//!
//! Single precision has its own exponential, [`exp_f32`]: the same range reduction in `f32`
//! arithmetic and a degree-6 polynomial fitted for `f32` (see its bound), and [`sigmoid_f32`]
//! on it. They are what the opt-in `f32` integrator uses, with the same bits on every kernel.

use crate::vector::{Arith, Elem, ROUND_SHIFT, ROUND_SHIFT_F32};

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

/// [`exp`] in every lane, or [`exp_f32`] in every lane of an `f32` vector. Which one is known
/// when the caller is compiled, and only that one is compiled in.
#[inline(always)]
pub(crate) fn exp_lanes<V: Arith>(x: V) -> V {
    if V::Elem::SINGLE {
        exp_lanes_f32(x)
    } else {
        exp_lanes_f64(x)
    }
}

/// [`sigmoid`] or [`sigmoid_f32`], for the element type `E`.
#[inline]
pub(crate) fn sigmoid_of<E: Elem>(x: E) -> E {
    with_fma(
        #[inline(always)]
        || sigmoid_lanes(x),
    )
}

/// [`exp`] in every lane.
#[inline(always)]
pub(crate) fn exp_lanes_f64<V: Arith>(x: V) -> V {
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

/// [`sigmoid`] (or [`sigmoid_f32`]) in every lane.
#[inline(always)]
pub(crate) fn sigmoid_lanes<V: Arith>(x: V) -> V {
    let one = V::splat(1.0);
    one / (one + exp_lanes(-x))
}

/// `f32` arguments are clamped to this range, where `2^k` stays a normal `f32` (k = round(x /
/// ln 2) is in [-126, 126]) and so do the result and the sigmoid's `1 / (1 + e^x)`. A clamp at
/// 88 let the firing rates of strongly inhibited neurons become subnormal (6e-39), and every
/// multiply-add that read one took a microcode assist on Intel CPUs: the f32 population ran at a
/// third of f64's speed at N = 30.
pub(crate) const EXP_F32_MIN: f64 = -87.0;
pub(crate) const EXP_F32_MAX: f64 = 87.0;
const INV_LN2_F32: f32 = std::f64::consts::LOG2_E as f32;
/// ln 2 split for `f32`: 355/512 = 0.693359375 has 9 significant bits, so `k * LN2_F32_HI` is exact for
/// |k| <= 127 and `x - k * LN2_F32_HI` is exact; the rest goes in `LN2_F32_LO`.
const LN2_F32_HI: f32 = 355.0 / 512.0;
const LN2_F32_LO: f32 = (std::f64::consts::LN_2 - 355.0 / 512.0) as f32;
/// `q(r) = c0 + c1 r + ... + c4 r^4` with `e^r ~ 1 + r + r^2 q(r)` on |r| <= ln2/2 (and a
/// margin): fitted for the least maximum relative error (Lawson's iteration), then rounded to
/// `f32`; that error is 3.6e-9, a sixteenth of the `f32` rounding unit 2^-24. Taylor's
/// coefficients of the same degree would give 1.6e-7.
const POLY_F32: [f32; 5] = [
    f32::from_bits(0x3eff_fffe), // 0.49999994
    f32::from_bits(0x3e2a_aa49), // 0.16666521
    f32::from_bits(0x3d2a_ac79), // 0.041668389
    f32::from_bits(0x3c09_1d10), // 0.0083687454
    f32::from_bits(0x3ab5_11e8), // 0.0013814541
];

/// e^x in single precision, for x in [-87, 87]; arguments outside are clamped to that range, so
/// the result is never 0, subnormal or infinite. NaN stays NaN. The same range reduction as [`exp`], in
/// `f32` arithmetic, and a degree-6 polynomial instead of degree 13.
///
/// Its relative error against the exact value (f64 [`f64::exp`] of the same `f32` argument, as
/// the reference) is below 1e-7 (1.7 units of 2^-24; the worst found, over every `f32` of two
/// binades and 6 million more points, is 8.4e-8 at x = -70.35) over the whole range, and the same bits come out of every kernel (tested in `tests/unit/math.rs` and
/// `tests/kernels`). [`sigmoid_f32`] is within 2e-7 of f64's sigmoid of the same argument,
/// relative to the rate (1.5e-7 measured).
///
/// # Example
/// ```
/// let e = ctrnn::math::exp_f32(1.0);
/// assert!((e as f64 - std::f64::consts::E).abs() <= 1e-7 * std::f64::consts::E);
/// ```
#[inline]
pub fn exp_f32(x: f32) -> f32 {
    with_fma(
        #[inline(always)]
        || exp_lanes(x),
    )
}

/// The logistic firing rate `1 / (1 + e^(-x))` in single precision, on [`exp_f32`].
///
/// # Example
/// ```
/// assert_eq!(ctrnn::math::sigmoid_f32(0.0), 0.5);
/// ```
#[inline]
pub fn sigmoid_f32(x: f32) -> f32 {
    with_fma(
        #[inline(always)]
        || sigmoid_lanes(x),
    )
}

/// [`exp_f32`] in every lane.
#[inline(always)]
pub(crate) fn exp_lanes_f32<V: Arith>(x: V) -> V {
    let x = x.clamp(EXP_F32_MIN, EXP_F32_MAX);
    // k = round(x / ln2), computed without a float-to-int conversion.
    let shift = V::splat(ROUND_SHIFT_F32 as f64);
    let k = x.mul_add(V::splat(INV_LN2_F32 as f64), shift) - shift;
    let r = (-k).mul_add(
        V::splat(LN2_F32_LO as f64),
        (-k).mul_add(V::splat(LN2_F32_HI as f64), x),
    );
    #[inline(always)]
    fn c<V: Arith>(i: usize) -> V {
        V::splat(POLY_F32[i] as f64)
    }
    // Estrin's scheme, as in `exp_lanes_f64`.
    let r2 = r * r;
    let low = c::<V>(1).mul_add(r, c::<V>(0));
    let high = c::<V>(4).mul_add(r2, c::<V>(3).mul_add(r, c::<V>(2)));
    let q = high.mul_add(r2, low);
    let er = V::splat(1.0) + r2.mul_add(q, r);
    er.mul_pow2(k)
}
