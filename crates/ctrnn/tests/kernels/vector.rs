#[cfg(target_arch = "aarch64")]
use ctrnn::testing::vector::neon::Neon;
#[cfg(target_arch = "x86_64")]
use ctrnn::testing::vector::{avx2, avx2::Avx2, avx512, avx512::Avx512};
use ctrnn::testing::vector::{pow2, Arith, Portable, Vector};

#[test]
fn pow2_is_exact_over_the_normal_range() {
    for k in -1022..=1023 {
        assert_eq!(pow2(k as f64), 2f64.powi(k), "k = {k}");
    }
}

#[test]
fn portable_rows_view_flat_storage() {
    let mut flat = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
    assert_eq!(
        Portable::<3>::rows(&flat),
        &[[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]
    );
    let row = &mut Portable::<2>::rows_mut(&mut flat)[1];
    (Portable::<2>::load(row) * Portable::<2>::splat(2.0)).store(row);
    assert_eq!(flat, [1.0, 2.0, 6.0, 8.0, 5.0, 6.0]);
}

/// Runs `f` on backend `V` and on plain `f64`s, `W` inputs at a time, and demands the same
/// bits.
fn same_bits<V: Vector<Row = [f64; W]>, const W: usize>(
    inputs: &[f64],
    f_vec: fn(V) -> V,
    f_ref: fn(f64) -> f64,
) {
    for chunk in inputs.chunks(W) {
        let mut x = [0.0; W];
        x[..chunk.len()].copy_from_slice(chunk);
        let mut got = [0.0; W];
        f_vec(V::load(&x)).store(&mut got);
        for l in 0..W {
            let want = f_ref(x[l]);
            assert!(
                got[l].to_bits() == want.to_bits() || got[l].is_nan() && want.is_nan(),
                "x = {:e}: {:e} (vector) vs {:e} (f64)",
                x[l],
                got[l],
                want
            );
        }
    }
}

/// A dense sweep where networks live, a coarse one far out, and the edge cases.
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

/// `exp`, `sigmoid` and negation on backend `V` against plain `f64`s.
fn backend_matches_f64<V: Vector<Row = [f64; W]>, const W: usize>() {
    use ctrnn::testing::math::{exp_lanes, sigmoid_lanes};
    let x = inputs();
    same_bits::<V, W>(&x, exp_lanes, exp_lanes);
    same_bits::<V, W>(&x, sigmoid_lanes, sigmoid_lanes);
    same_bits::<V, W>(&x, |v| -v, |v| -v);
}

#[test]
fn portable_lanes_match_f64_bit_for_bit() {
    backend_matches_f64::<Portable<4>, 4>();
}

#[test]
#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
fn register_backends_match_f64_bit_for_bit() {
    use ctrnn::simd::Kernel;
    if Kernel::Avx2.is_supported() {
        // SAFETY: the CPU has AVX2 and FMA (checked above).
        unsafe { avx2::enabled(backend_matches_f64::<Avx2, 4>) };
    } else {
        eprintln!("this CPU has no AVX2 + FMA: the avx2 backend was not checked");
    }
    if Kernel::Avx512.is_supported() {
        // SAFETY: the CPU has AVX-512F (checked above).
        unsafe { avx512::enabled(backend_matches_f64::<Avx512, 8>) };
    } else {
        eprintln!("this CPU has no AVX-512F: the avx512 backend was not checked");
    }
}

#[test]
#[cfg(target_arch = "aarch64")]
fn neon_backend_matches_f64_bit_for_bit() {
    backend_matches_f64::<Neon, 2>();
}

#[test]
fn pow2_f32_is_exact_over_the_normal_range() {
    use ctrnn::testing::vector::pow2_f32;
    for k in -126..=127 {
        assert_eq!(pow2_f32(k as f32), 2f32.powi(k), "k = {k}");
    }
}

/// Runs `f` on the `f32` backend `V` and on plain `f32`s, `W` inputs at a time, and demands the
/// same bits.
fn same_bits_f32<V: Vector<Row = [f32; W]>, const W: usize>(
    inputs: &[f32],
    f_vec: fn(V) -> V,
    f_ref: fn(f32) -> f32,
) {
    for chunk in inputs.chunks(W) {
        let mut x = [0.0; W];
        x[..chunk.len()].copy_from_slice(chunk);
        let mut got = [0.0; W];
        f_vec(V::load(&x)).store(&mut got);
        for l in 0..W {
            let want = f_ref(x[l]);
            assert!(
                got[l].to_bits() == want.to_bits() || got[l].is_nan() && want.is_nan(),
                "x = {:e}: {:e} (vector) vs {:e} (f32)",
                x[l],
                got[l],
                want
            );
        }
    }
}

/// [`inputs`] for `f32`: a dense sweep where networks live, a coarse one far out, every `f32`
/// near the ends of `exp_f32`'s range, and the edge cases.
fn inputs_f32() -> Vec<f32> {
    use ctrnn::testing::math::{EXP_F32_MAX, EXP_F32_MIN};
    let mut x: Vec<f32> = inputs().into_iter().map(|x| x as f32).collect();
    for end in [EXP_F32_MIN, -EXP_F32_MIN, EXP_F32_MAX, -EXP_F32_MAX] {
        let b = (end as f32).to_bits();
        x.extend((b - 3000..b + 3000).map(f32::from_bits));
    }
    x.extend([
        f32::MAX,
        f32::MIN,
        f32::MIN_POSITIVE,
        -f32::MIN_POSITIVE,
        f32::from_bits(1),
        100.0,
        -100.0,
    ]);
    x
}

/// `exp`, `sigmoid` and negation on the `f32` backend `V` against plain `f32`s.
fn backend_matches_f32<V: Vector<Row = [f32; W]>, const W: usize>() {
    use ctrnn::testing::math::{exp_lanes, sigmoid_lanes};
    let x = inputs_f32();
    same_bits_f32::<V, W>(&x, exp_lanes, exp_lanes);
    same_bits_f32::<V, W>(&x, sigmoid_lanes, sigmoid_lanes);
    same_bits_f32::<V, W>(&x, |v| -v, |v| -v);
}

#[test]
fn portable_f32_lanes_match_f32_bit_for_bit() {
    backend_matches_f32::<Portable<4, f32>, 4>();
}

#[test]
#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
fn register_f32_backends_match_f32_bit_for_bit() {
    use ctrnn::simd::Kernel;
    use ctrnn::testing::vector::{avx2::Avx2F32, avx512::Avx512F32};
    if Kernel::Avx2.is_supported() {
        // SAFETY: the CPU has AVX2 and FMA (checked above).
        unsafe { avx2::enabled(backend_matches_f32::<Avx2F32, 8>) };
    } else {
        eprintln!("this CPU has no AVX2 + FMA: the f32 avx2 backend was not checked");
    }
    if Kernel::Avx512.is_supported() {
        // SAFETY: the CPU has AVX-512F (checked above).
        unsafe { avx512::enabled(backend_matches_f32::<Avx512F32, 16>) };
    } else {
        eprintln!("this CPU has no AVX-512F: the f32 avx512 backend was not checked");
    }
}

#[test]
#[cfg(target_arch = "aarch64")]
fn neon_f32_backend_matches_f32_bit_for_bit() {
    use ctrnn::testing::vector::neon::NeonF32;
    backend_matches_f32::<NeonF32, 4>();
}
