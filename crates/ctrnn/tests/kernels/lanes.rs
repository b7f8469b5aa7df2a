//! The integrator at a width no crate uses and with closures of the tests' own: each compiles
//! the kernel again, for every backend, so they live in this binary rather than in tests/unit.

use ctrnn::integrate::*;
use ctrnn::simd::{self, Kernel};
use ctrnn::testing::integrate::{random_networks, step_row_on};
use ctrnn::testing::vector::Elem;
use ctrnn::Network;

/// Steps one block of `L` networks on `kernel` and on the portable kernel: same bits.
fn kernels_agree<const L: usize>(kernel: Kernel) {
    kernels_agree_in::<L, f64>(kernel);
}

/// [`kernels_agree`] computing in `E` (`f64` or `f32`).
fn kernels_agree_in<const L: usize, E: Elem>(kernel: Kernel) {
    for (n, m) in [
        (1, 0),
        (3, 1),
        (4, 2),
        (5, 2),
        (7, 3),
        (10, 2),
        (13, 1),
        (30, 2),
    ] {
        let nets = random_networks(L, n, m, (n * 10 + m) as u64);
        let refs: Vec<&Network> = nets.iter().collect();
        for method in [Method::Euler, Method::Rk4] {
            let integ = Integrator {
                method,
                dt: 0.05,
                substeps: 3,
            };
            let mut fast = Lanes::<L, E>::new(&refs).unwrap();
            let mut portable = fast.clone();
            for t in 0..20 {
                let inputs: Vec<[E; L]> = (0..m)
                    .map(|k| {
                        std::array::from_fn(|l| E::from_f64(((t * 7 + k * 3 + l) % 5) as f64 - 2.0))
                    })
                    .collect();
                step_row_on(&mut fast, kernel, &inputs, &integ);
                step_row_on(&mut portable, Kernel::Portable, &inputs, &integ);
            }
            for i in 0..n {
                let (a, b) = (fast.state(i), portable.state(i));
                assert!(
                    a.iter()
                        .zip(b)
                        .all(|(x, y)| x.to_f64().to_bits() == y.to_f64().to_bits()),
                    "{kernel}, L = {L}, N = {n}, M = {m}, {method:?}, neuron {i}: {a:?} vs {b:?}"
                );
            }
        }
    }
}

#[test]
fn every_kernel_matches_the_portable_kernel_bit_for_bit() {
    for kernel in simd::supported() {
        // A single network, an odd width (plain lanes both) and a block (registers).
        kernels_agree::<1>(kernel);
        kernels_agree::<3>(kernel);
        kernels_agree::<LANES>(kernel);
    }
    for kernel in Kernel::ALL.into_iter().filter(|k| !k.is_supported()) {
        eprintln!("this CPU cannot run the {kernel} kernel: not checked");
    }
}

#[test]
fn every_kernel_matches_the_portable_kernel_bit_for_bit_in_f32() {
    for kernel in simd::supported() {
        kernels_agree_in::<1, f32>(kernel);
        kernels_agree_in::<3, f32>(kernel);
        kernels_agree_in::<LANES, f32>(kernel);
    }
}

#[test]
fn reading_the_outputs_between_steps_changes_nothing() {
    let nets = random_networks(LANES, 5, 2, 3);
    let refs: Vec<&Network> = nets.iter().collect();
    for method in [Method::Euler, Method::Rk4] {
        let integ = Integrator {
            method,
            dt: 0.1,
            substeps: 3,
        };
        let mut plain = Lanes::<LANES>::new(&refs).unwrap();
        let mut read = plain.clone();
        let same = |a: &Lanes<LANES>, b: &Lanes<LANES>| {
            (0..5).all(|i| {
                let (x, y) = (a.state(i), b.state(i));
                x.iter().zip(y).all(|(x, y)| x.to_bits() == y.to_bits())
            })
        };
        for t in 0..30 {
            // Rates read after row 9 and row 19 must not survive the reset and the new state.
            if t == 10 {
                plain.reset();
                read.reset();
            }
            if t == 20 {
                plain.set_lane_state(3, &[1.0; 5]);
                read.set_lane_state(3, &[1.0; 5]);
            }
            let inputs = [[(t % 3) as f64; LANES], [1.0 - (t % 2) as f64; LANES]];
            plain.step_row(&inputs, &integ);
            read.step_row(&inputs, &integ);
            assert!(same(&plain, &read), "{method:?}, row {t}");
            if t % 4 != 2 {
                let out: Vec<[f64; LANES]> = read.outputs().to_vec();
                for (i, row) in out.iter().enumerate() {
                    let want = read.output(i);
                    assert!(row
                        .iter()
                        .zip(&want)
                        .all(|(a, b)| a.to_bits() == b.to_bits()));
                }
            }
        }
        let mut rows = read.clone();
        let _ = rows.outputs();
        // One pair of closures for both calls, so the kernel is compiled once for them.
        let (row, record) = (
            |_: usize, r: &mut [[f64; LANES]]| r[0][0] = 1.0,
            |_: usize, _: &[[f64; LANES]]| {},
        );
        rows.run_rows(5, &integ, None, row, record).unwrap();
        plain.run_rows(5, &integ, None, row, record).unwrap();
        assert!(same(&plain, &rows), "{method:?}, run_rows");
    }
}
