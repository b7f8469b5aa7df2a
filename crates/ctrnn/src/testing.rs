//! Internals that ctrnn's own integration tests (`tests/unit`, `tests/kernels`) check directly: the lane vectors
//! and their backends, the sigmoid's kernel, the integrator's weight order, and a few helpers of
//! the analysis. Not public API: hidden from the documentation, and free to change or go at any
//! time. It exists so that the unit tests build as an integration test, against the library
//! that `cargo test` builds anyway, instead of compiling the whole crate a second time as a
//! unit-test harness.

/// The lane vectors (the crate's private `vector` module) and their register backends.
pub mod vector {
    pub use crate::vector::{pow2, pow2_f32, Arith, Elem, Portable, Vector};

    /// Four `f64` (or eight `f32`) lanes in an AVX2 register.
    #[cfg(target_arch = "x86_64")]
    pub mod avx2 {
        pub use crate::vector::avx2::{enabled, Avx2};
        pub use crate::vector::avx2_f32::Avx2F32;
    }

    /// Eight `f64` (or sixteen `f32`) lanes in an AVX-512 register.
    #[cfg(target_arch = "x86_64")]
    pub mod avx512 {
        pub use crate::vector::avx512::{enabled, Avx512};
        pub use crate::vector::avx512_f32::Avx512F32;
    }

    /// Two `f64` (or four `f32`) lanes in a NEON register.
    #[cfg(target_arch = "aarch64")]
    pub mod neon {
        pub use crate::vector::neon::Neon;
        pub use crate::vector::neon_f32::NeonF32;
    }
}

/// [`crate::math`]'s kernels and constants.
pub mod math {
    use crate::vector::Arith;

    /// The lower end of [`crate::math::exp`]'s argument range.
    pub const EXP_MIN: f64 = crate::math::EXP_MIN;
    /// The upper end of [`crate::math::exp`]'s argument range.
    pub const EXP_MAX: f64 = crate::math::EXP_MAX;
    /// The lower end of [`crate::math::exp_f32`]'s argument range.
    pub const EXP_F32_MIN: f64 = crate::math::EXP_F32_MIN;
    /// The upper end of [`crate::math::exp_f32`]'s argument range.
    pub const EXP_F32_MAX: f64 = crate::math::EXP_F32_MAX;

    /// [`crate::math::exp`] in every lane.
    #[inline(always)]
    pub fn exp_lanes<V: Arith>(x: V) -> V {
        crate::math::exp_lanes(x)
    }

    /// [`crate::math::sigmoid`] in every lane.
    #[inline(always)]
    pub fn sigmoid_lanes<V: Arith>(x: V) -> V {
        crate::math::sigmoid_lanes(x)
    }
}

/// [`crate::error`]'s checks.
pub mod error {
    /// Checks that every value is finite; an error names the first one that is not.
    pub fn check_finite(field: &str, values: &[f64], cols: usize) -> crate::Result<()> {
        crate::error::check_finite(field, values, cols)
    }
}

/// [`crate::genome`]'s helpers.
pub mod genome {
    /// Folds `x` into `[lo, hi]` by reflection at its ends.
    pub fn reflect(x: f64, lo: f64, hi: f64) -> f64 {
        crate::genome::reflect(x, lo, hi)
    }
}

/// The aligned rows the integrator stores its parameters in.
pub mod rows {
    pub use crate::rows::Rows;
}

/// The integrator's internals.
pub mod integrate {
    use crate::integrate::{Integrator, Lanes};
    use crate::simd::Kernel;
    use crate::{Network, Purpose, Stream};

    pub use crate::integrate::kernel::weight_order;

    /// `count` random networks of `n` neurons and `m` sensors from stream `seed`: time
    /// constants in [0.5, 10], thresholds and weights in [-16, 16], states in [-5, 5].
    pub fn random_networks(count: usize, n: usize, m: usize, seed: u64) -> Vec<Network> {
        let mut rng = Stream::new(seed, 0, Purpose::Init, 0, 0);
        let mut draw = |count: usize, lo: f64, hi: f64| -> Vec<f64> {
            (0..count).map(|_| rng.range(lo, hi)).collect()
        };
        (0..count)
            .map(|_| {
                let (tau, theta) = (draw(n, 0.5, 10.0), draw(n, -16.0, 16.0));
                let (w, s, v) = (
                    draw(n * n, -16.0, 16.0),
                    draw(n * m, -16.0, 16.0),
                    draw(n, -5.0, 5.0),
                );
                Network::new(tau, theta, w, s, Some(v)).expect("the ranges are valid")
            })
            .collect()
    }

    /// [`Lanes::step_row`] on a given kernel, which the CPU must support.
    pub fn step_row_on<const L: usize, E: crate::vector::Elem>(
        lanes: &mut Lanes<L, E>,
        kernel: Kernel,
        inputs: &[[E; L]],
        integ: &Integrator,
    ) {
        lanes.step_row_on(kernel, inputs, integ);
    }
}

/// The analysis's internals.
pub mod analysis {
    pub use crate::analysis::branches::{continues, locate, orbit_gap, Here};
    pub use crate::analysis::events::At;
    pub use crate::analysis::stability::eigenvalues;

    /// The uniform values in [0, 1) that the equilibrium search draws its starts from for
    /// `seed`, one per call.
    pub fn draws(seed: u64) -> impl FnMut() -> f64 {
        let mut draws = crate::analysis::equilibria::Draws::new(seed);
        move || draws.next()
    }
}

/// The spinning helpers that share a batch's small steps.
pub mod spin {
    pub use crate::spin::helpers;
}
