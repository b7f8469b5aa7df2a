//! Rows of values computed on together, one value per network of a block.
//!
//! The integrator and the sigmoid are written once, generically over [`Vector`], and over its
//! element type ([`Elem`]): `f64`, the default and the reference, or `f32`, the opt-in single
//! precision. Each backend maps the same sequence of IEEE operations (add, subtract, multiply,
//! divide, fused multiply-add, exact scaling by a power of two) onto its own instructions, so
//! every backend of an element type gives the same bits:
//! - `f64` / `f32`: one lane.
//! - `Avx2` / `Avx2F32` (x86-64 with AVX2 and FMA): 4 / 8 lanes in one 256-bit register.
//! - `Avx512` / `Avx512F32` (x86-64 with AVX-512F): 8 / 16 lanes in one 512-bit register.
//! - `Neon` / `NeonF32` (every 64-bit ARM CPU): 2 / 4 lanes in one 128-bit register.
//!   LLVM does not find this layout on its own: it vectorises the sigmoid loop across neurons,
//!   with gathers and scatters, instead of across networks.
//! - [`Group<V, G>`]: `G` of those, operation by operation. A population block of 16 networks
//!   is `Group<Avx512, 2>`, `Group<Avx2, 4>` or `Group<Neon, 8>` in f64 (`Group<Avx512F32, 1>`,
//!   `Group<Avx2F32, 2>`, `Group<NeonF32, 4>` in f32); [`Portable<L>`] is `Group<f64, L>` (or
//!   `Group<f32, L>`), used for single networks (`L = 1`) and wherever no register backend
//!   applies.
//!
//! Which backend runs is chosen when the program runs ([`crate::simd`]); the register backends'
//! code is compiled for their CPU features inside their `enabled` functions, the only way in.

use std::fmt::{Debug, Display};
use std::ops::{Add, Div, Mul, Neg, Sub};

use bytemuck::Pod;

#[cfg(target_arch = "x86_64")]
pub(crate) mod avx2;
#[cfg(target_arch = "x86_64")]
pub(crate) mod avx2_f32;
#[cfg(target_arch = "x86_64")]
pub(crate) mod avx512;
#[cfg(target_arch = "x86_64")]
pub(crate) mod avx512_f32;
#[cfg(target_arch = "aarch64")]
pub(crate) mod neon;
#[cfg(target_arch = "aarch64")]
pub(crate) mod neon_f32;
#[cfg(target_arch = "x86_64")]
pub(crate) use {avx2::Avx2, avx2_f32::Avx2F32, avx512::Avx512, avx512_f32::Avx512F32};
#[cfg(target_arch = "aarch64")]
pub(crate) use {neon::Neon, neon_f32::NeonF32};

/// Lane-by-lane arithmetic that rounds as IEEE 754 does in the element type (binary64 for
/// `f64`, binary32 for `f32`), so that a backend can only change speed, never a result.
pub trait Arith:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// The type of one lane: `f64` or `f32`.
    type Elem: Elem;
    /// Every lane `x`, rounded to the element type (constants are chosen exact in it).
    fn splat(x: f64) -> Self;
    /// `self * a + b` with one rounding.
    fn mul_add(self, a: Self, b: Self) -> Self;
    /// Each lane clamped to `[lo, hi]` (bounds exact in the element type); NaN stays NaN, as
    /// with [`f64::clamp`].
    fn clamp(self, lo: f64, hi: f64) -> Self;
    /// `self * 2^k` for lanes of `k` that hold integers in the element type's normal exponent
    /// range ([-1022, 1023] for `f64`, [-126, 127] for `f32`) and products that are normal
    /// numbers, where the product is exact.
    fn mul_pow2(self, k: Self) -> Self;
}

/// An element type the integrator computes in: `f64` (the default and the reference) or `f32`
/// (opt-in single precision). It is its own one-lane [`Vector`] and names the register backends
/// that hold a block of [`crate::LANES`] networks of it.
pub trait Elem:
    Vector<Elem = Self, Row = Self>
    + Pod
    + Default
    + PartialEq
    + Debug
    + Display
    + Send
    + Sync
    + 'static
{
    /// `x` rounded to this type (to nearest, ties to even): exact for `f64`.
    fn from_f64(x: f64) -> Self;
    /// `self` as an `f64` (always exact).
    fn to_f64(self) -> f64;
    /// Neither infinite nor NaN.
    fn finite(self) -> bool;
    /// Single precision, which has an exponential of its own ([`crate::math`]).
    const SINGLE: bool;

    /// A block of [`crate::LANES`] networks in AVX-512 registers.
    #[cfg(target_arch = "x86_64")]
    type Avx512Block: Vector<Elem = Self>;
    /// A block of [`crate::LANES`] networks in AVX2 registers.
    #[cfg(target_arch = "x86_64")]
    type Avx2Block: Vector<Elem = Self>;
    /// A block of [`crate::LANES`] networks in NEON registers.
    #[cfg(target_arch = "aarch64")]
    type NeonBlock: Vector<Elem = Self>;
}

/// A row of values as the integrator stores it, one per network of a block.
pub trait Vector: Arith {
    /// How a row is stored: its lanes' values in order (`f64`, `[f64; 8]`, or arrays of those).
    type Row: Copy;
    /// Whether a `Group` of a few of these still fits in registers, so that running long
    /// dependency chains side by side pays. True for AVX-512 (32 registers); not for AVX2 (16
    /// registers, and a block is already four of them); plain lanes are left to the compiler
    /// (grouping 16-lane portable rows four at a time made an AVX2 build 4x slower, and made
    /// single networks no faster).
    const INTERLEAVE: bool;
    /// How many values of this type the integrator's running sums may hold at once: what the
    /// register file keeps besides their operands. More independent sums keep the multiply-add
    /// units busy; more than fit spill to memory (measured: four rows of a 16-lane AVX2 block,
    /// 16 registers, ran at two thirds the speed of two rows).
    const SUM_REGISTERS: usize;

    /// Reads a stored row.
    fn load(row: &Self::Row) -> Self;
    /// Writes into a stored row.
    fn store(self, row: &mut Self::Row);
    /// Views `lanes * k` values as `k` rows.
    fn rows(flat: &[Self::Elem]) -> &[Self::Row];
    /// Views `lanes * k` values as `k` mutable rows.
    fn rows_mut(flat: &mut [Self::Elem]) -> &mut [Self::Row];
    /// Asks for a row to be brought into the L1 cache (a hint; may do nothing).
    #[inline(always)]
    fn prefetch(_row: &Self::Row) {}
}

/// `G` vectors computed on together, operation by operation. A long dependency chain such as
/// the sigmoid then runs `G` times in parallel instead of one after another, which keeps more
/// of the CPU's execution units busy than its out-of-order window would on its own.
///
/// Its operations are plain loops, not `array::from_fn` or `map`: every function between a
/// backend's `enabled` and its intrinsics must be `#[inline(always)]`, or the intrinsics stay out
/// of line, compiled without the backend's features (then one call per instruction).
#[derive(Clone, Copy, Debug)]
pub struct Group<V, const G: usize>(pub [V; G]);

macro_rules! group_op {
    ($trait:ident, $method:ident) => {
        impl<V: Arith, const G: usize> $trait for Group<V, G> {
            type Output = Self;
            #[inline(always)]
            fn $method(self, o: Self) -> Self {
                let mut r = self;
                for g in 0..G {
                    r.0[g] = self.0[g].$method(o.0[g]);
                }
                r
            }
        }
    };
}
group_op!(Add, add);
group_op!(Sub, sub);
group_op!(Mul, mul);
group_op!(Div, div);

impl<V: Arith, const G: usize> Neg for Group<V, G> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        let mut r = self;
        for g in 0..G {
            r.0[g] = -self.0[g];
        }
        r
    }
}

impl<V: Arith, const G: usize> Arith for Group<V, G> {
    type Elem = V::Elem;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        Group([V::splat(x); G])
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        let mut r = self;
        for g in 0..G {
            r.0[g] = self.0[g].mul_add(a.0[g], b.0[g]);
        }
        r
    }
    #[inline(always)]
    fn clamp(self, lo: f64, hi: f64) -> Self {
        let mut r = self;
        for g in 0..G {
            r.0[g] = self.0[g].clamp(lo, hi);
        }
        r
    }
    #[inline(always)]
    fn mul_pow2(self, k: Self) -> Self {
        let mut r = self;
        for g in 0..G {
            r.0[g] = self.0[g].mul_pow2(k.0[g]);
        }
        r
    }
}

impl<V: Vector, const G: usize> Vector for Group<V, G> {
    type Row = [V::Row; G];
    const INTERLEAVE: bool = V::INTERLEAVE;
    /// One value of a group takes `G` registers.
    const SUM_REGISTERS: usize = V::SUM_REGISTERS / G;

    #[inline(always)]
    fn load(row: &Self::Row) -> Self {
        let mut r = Group([V::splat(0.0); G]);
        for g in 0..G {
            r.0[g] = V::load(&row[g]);
        }
        r
    }
    #[inline(always)]
    fn store(self, row: &mut Self::Row) {
        for (v, r) in self.0.into_iter().zip(row) {
            v.store(r);
        }
    }
    #[inline(always)]
    fn rows(flat: &[V::Elem]) -> &[Self::Row] {
        V::rows(flat).as_chunks().0
    }
    #[inline(always)]
    fn rows_mut(flat: &mut [V::Elem]) -> &mut [Self::Row] {
        V::rows_mut(flat).as_chunks_mut().0
    }
    #[inline(always)]
    fn prefetch(row: &Self::Row) {
        for r in row {
            V::prefetch(r);
        }
    }
}

/// Shifts a float so that its last mantissa bits hold an integer (valid for |k| < 2^51).
pub(crate) const ROUND_SHIFT: f64 = 6_755_399_441_055_744.0; // 1.5 * 2^52

/// `2^k` for an integer-valued `k` in [-1022, 1023], built from its bits.
#[inline(always)]
pub fn pow2(k: f64) -> f64 {
    let k_int = (k + ROUND_SHIFT)
        .to_bits()
        .wrapping_sub(ROUND_SHIFT.to_bits());
    f64::from_bits(k_int.wrapping_add(1023) << 52)
}

/// Shifts an `f32` so that its last mantissa bits hold an integer (valid for |k| < 2^22).
pub(crate) const ROUND_SHIFT_F32: f32 = 12_582_912.0; // 1.5 * 2^23

/// `2^k` for an integer-valued `k` in [-126, 127], built from its bits.
#[inline(always)]
pub fn pow2_f32(k: f32) -> f32 {
    let k_int = (k + ROUND_SHIFT_F32)
        .to_bits()
        .wrapping_sub(ROUND_SHIFT_F32.to_bits());
    f32::from_bits(k_int.wrapping_add(127) << 23)
}

/// One plain `f64`: the lane that [`Portable`] groups.
impl Arith for f64 {
    type Elem = f64;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        f64::mul_add(self, a, b)
    }
    #[inline(always)]
    fn clamp(self, lo: f64, hi: f64) -> Self {
        f64::clamp(self, lo, hi)
    }
    #[inline(always)]
    fn mul_pow2(self, k: Self) -> Self {
        self * pow2(k)
    }
}

impl Vector for f64 {
    type Row = f64;
    const INTERLEAVE: bool = false;
    /// Plain lanes are left to the compiler: it gets rows four at a time at any lane count.
    const SUM_REGISTERS: usize = 64;

    #[inline(always)]
    fn load(row: &f64) -> Self {
        *row
    }
    #[inline(always)]
    fn store(self, row: &mut f64) {
        *row = self;
    }
    #[inline(always)]
    fn rows(flat: &[f64]) -> &[f64] {
        flat
    }
    #[inline(always)]
    fn rows_mut(flat: &mut [f64]) -> &mut [f64] {
        flat
    }
}

impl Elem for f64 {
    #[inline(always)]
    fn from_f64(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self
    }
    #[inline(always)]
    fn finite(self) -> bool {
        self.is_finite()
    }
    const SINGLE: bool = false;
    #[cfg(target_arch = "x86_64")]
    type Avx512Block = Group<Avx512, 2>;
    #[cfg(target_arch = "x86_64")]
    type Avx2Block = Group<Avx2, 4>;
    #[cfg(target_arch = "aarch64")]
    type NeonBlock = Group<Neon, 8>;
}

/// One plain `f32`: the lane that [`Portable`] groups in single precision.
impl Arith for f32 {
    type Elem = f32;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        x as f32
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        f32::mul_add(self, a, b)
    }
    #[inline(always)]
    fn clamp(self, lo: f64, hi: f64) -> Self {
        f32::clamp(self, lo as f32, hi as f32)
    }
    #[inline(always)]
    fn mul_pow2(self, k: Self) -> Self {
        self * pow2_f32(k)
    }
}

impl Vector for f32 {
    type Row = f32;
    const INTERLEAVE: bool = false;
    /// Plain lanes are left to the compiler, as for `f64`.
    const SUM_REGISTERS: usize = 64;

    #[inline(always)]
    fn load(row: &f32) -> Self {
        *row
    }
    #[inline(always)]
    fn store(self, row: &mut f32) {
        *row = self;
    }
    #[inline(always)]
    fn rows(flat: &[f32]) -> &[f32] {
        flat
    }
    #[inline(always)]
    fn rows_mut(flat: &mut [f32]) -> &mut [f32] {
        flat
    }
}

impl Elem for f32 {
    #[inline(always)]
    fn from_f64(x: f64) -> Self {
        x as f32
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self as f64
    }
    #[inline(always)]
    fn finite(self) -> bool {
        self.is_finite()
    }
    const SINGLE: bool = true;
    #[cfg(target_arch = "x86_64")]
    type Avx512Block = Group<Avx512F32, 1>;
    #[cfg(target_arch = "x86_64")]
    type Avx2Block = Group<Avx2F32, 2>;
    #[cfg(target_arch = "aarch64")]
    type NeonBlock = Group<NeonF32, 4>;
}

/// `L` plain `f64`s (or `f32`s), computed on one by one (the compiler may still vectorise
/// them); its rows are `[f64; L]` (or `[f32; L]`).
pub type Portable<const L: usize, E = f64> = Group<E, L>;
