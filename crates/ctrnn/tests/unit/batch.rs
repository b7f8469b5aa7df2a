use std::sync::atomic::AtomicBool;

use ctrnn::integrate::{Integrator, Method, Precision};
use ctrnn::math::{sigmoid, sigmoid_f32};
use ctrnn::testing::integrate::random_networks;
use ctrnn::{Batch, Error, Network};
use proptest::prelude::*;

fn integrator(rk4: bool, substeps: usize) -> Integrator {
    Integrator {
        method: if rk4 { Method::Rk4 } else { Method::Euler },
        dt: 0.1,
        substeps,
    }
}

fn precision(f32: bool) -> Precision {
    if f32 {
        Precision::F32
    } else {
        Precision::F64
    }
}

/// A batch of every replica of `nets`, in `precision`.
fn batch_in(nets: &[Network], e: usize, integ: Integrator, precision: Precision) -> Batch {
    Batch::with_rows_in(nets, e, nets.len() * e, integ, precision).unwrap()
}

fn bits(x: &[f64]) -> Vec<u64> {
    x.iter().map(|v| v.to_bits()).collect()
}

/// Each row's inputs at step t: a function of (row, t), so that rows differ.
fn input(row: usize, t: usize, k: usize) -> f64 {
    ((row * 7 + t * 3 + k) % 11) as f64 / 5.0 - 1.0
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    /// Every row, stepped only on its active steps, ends where `Network::run` on those steps'
    /// inputs ends, bit for bit, and the rates of a row stepped last are `f(v - theta)` of its
    /// state: in either precision.
    #[test]
    fn rows_equal_network_run_bit_for_bit(
        n in 1usize..7, m in 0usize..3, p in 1usize..20, e in 1usize..4,
        steps in 1usize..8, rk4 in any::<bool>(), seed in 0u64..1000, sub in 1usize..4,
        f32 in any::<bool>(),
    ) {
        let nets = random_networks(p, n, m, seed);
        let integ = integrator(rk4, sub);
        let mut batch = batch_in(&nets, e, integ, precision(f32));
        prop_assert_eq!(batch.precision(), precision(f32));
        let rows = p * e;
        // Row r sits out step t when (r + t) % 3 == 0.
        let on = |r: usize, t: usize| !(r + t).is_multiple_of(3);
        let mut rates = vec![0.0; rows * n];
        for t in 0..steps {
            let x: Vec<f64> = (0..rows * m).map(|k| input(k / m.max(1), t, k % m.max(1))).collect();
            let mask: Vec<bool> = (0..rows).map(|r| on(r, t)).collect();
            batch.step(&x, Some(&mask), &mut rates, None).unwrap();
        }
        let states = batch.states();
        for r in 0..rows {
            let mut single = nets[r / e].clone();
            let own: Vec<f64> = (0..steps)
                .filter(|&t| on(r, t))
                .flat_map(|t| (0..m).map(move |k| input(r, t, k)))
                .collect();
            single.run_in(&own, own.len() / m.max(1), &integ, precision(f32), None).unwrap();
            let mine = &states[r * n..(r + 1) * n];
            if m > 0 {
                prop_assert_eq!(bits(single.state()), bits(mine), "row {}", r);
            }
            if on(r, steps - 1) {
                let theta = nets[r / e].theta();
                let rate = |i: usize| if f32 {
                    sigmoid_f32(mine[i] as f32 - theta[i] as f32) as f64
                } else {
                    sigmoid(mine[i] - theta[i])
                };
                let want: Vec<f64> = (0..n).map(rate).collect();
                prop_assert_eq!(bits(&want), bits(&rates[r * n..(r + 1) * n]));
            }
        }
    }
}

#[test]
fn many_threads_give_the_bits_of_one() {
    // Large enough to run blocks in parallel.
    let nets = random_networks(200, 20, 2, 3);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut batch = Batch::new(&nets, 2, integrator(false, 5)).unwrap();
            let mut rates = vec![0.0; 400 * 20];
            for t in 0..10 {
                let x: Vec<f64> = (0..800).map(|k| input(k / 2, t, k % 2)).collect();
                batch.step(&x, None, &mut rates, None).unwrap();
            }
            bits(&batch.states())
        })
    };
    assert_eq!(run(1), run(2));
}

#[test]
fn reset_and_set_states_touch_only_the_chosen_rows() {
    let nets = random_networks(3, 2, 1, 9);
    let mut batch = Batch::new(&nets, 2, Integrator::default()).unwrap();
    let mut rates = vec![0.0; 12];
    batch.step(&[1.0; 6], None, &mut rates, None).unwrap();
    let before = batch.states();
    let chosen = [false, true, false, false, true, false];
    batch.reset(Some(&chosen)).unwrap();
    let after = batch.states();
    for r in 0..6 {
        let want = if chosen[r] {
            vec![0.0; 2]
        } else {
            before[r * 2..r * 2 + 2].to_vec()
        };
        assert_eq!(after[r * 2..r * 2 + 2], want[..], "row {r}");
    }
    let mut states = vec![0.5; 12];
    states[0] = f64::NAN; // row 0 is not chosen, so never read
    batch
        .set_states(&states, Some(&[false, false, true, false, false, false]))
        .unwrap();
    assert_eq!(batch.states()[4..6], [0.5, 0.5]);
    assert_eq!(batch.states()[0..2], after[0..2]);
    // The rates follow the new states.
    let rates = batch.rates();
    assert_eq!(rates[4], sigmoid(0.5 - nets[1].theta()[0]));
}

#[test]
fn bad_arguments_are_refused_and_leave_the_states_alone() {
    let nets = random_networks(2, 3, 2, 1);
    let mut batch = Batch::new(&nets, 2, Integrator::default()).unwrap();
    let before = batch.states();
    let mut rates = vec![0.0; 12];
    let msg = |e: Error| e.to_string();
    let short = batch.step(&[0.0; 7], None, &mut rates, None).unwrap_err();
    assert!(msg(short).contains("inputs has 7 values; expected B x M = 8"));
    let mut nan = [0.0; 8];
    nan[5] = f64::NAN;
    let err = batch.step(&nan, None, &mut rates, None).unwrap_err();
    assert!(msg(err).contains("inputs[2, 1] is NaN"));
    assert_eq!(bits(&batch.states()), bits(&before));
    // A row left out may hold anything.
    let mask = [true, true, false, true];
    batch.step(&nan, Some(&mask), &mut rates, None).unwrap();
    let before = batch.states();
    let err = batch
        .step(&[0.0; 8], Some(&[true; 3]), &mut rates, None)
        .unwrap_err();
    assert!(msg(err).contains("active has 3 values"));
    let err = batch.set_states(&[f64::INFINITY; 12], None).unwrap_err();
    assert!(msg(err).contains("states[0, 0] is inf"));
    assert_eq!(bits(&batch.states()), bits(&before));
    assert!(Batch::new(&nets, 0, Integrator::default()).is_err());
    assert!(Batch::new::<Network>(&[], 1, Integrator::default()).is_err());
    let mixed = [nets[0].clone(), random_networks(1, 4, 2, 0).remove(0)];
    let err = Batch::new(&mixed, 3, Integrator::default()).unwrap_err();
    assert!(msg(err).contains("network 1 has N = 4"));
}

#[test]
fn a_long_step_stops_when_cancelled_and_a_diverging_one_says_so() {
    let nets = random_networks(1, 2, 1, 1);
    let mut batch = Batch::new(&nets, 1, integrator(false, 1 << 30)).unwrap();
    let cancel = AtomicBool::new(true);
    let mut rates = vec![0.0; 2];
    let err = batch
        .step(&[0.0], None, &mut rates, Some(&cancel))
        .unwrap_err();
    assert!(matches!(err, Error::Interrupted));
    // Past the work one call may take: refused before it starts.
    let mut endless = Batch::new(&nets, 2, integrator(false, 1 << 40)).unwrap();
    let mut rates = vec![0.0; 4];
    let err = endless.step(&[0.0; 2], None, &mut rates, None).unwrap_err();
    assert!(
        err.to_string().contains("the limit is 68719476736"),
        "{err}"
    );
    // A diverging row beside one left out: the error names it, and the other keeps its state.
    // Its first step overflows: 1e308 x 0.5 + 1e308 x 1 is past the largest f64. (A
    // step too long for its time constant is refused before it is taken.)
    let fast = Network::new(vec![1.0], vec![0.0], vec![1e308], vec![1e308], None).unwrap();
    let mut batch = Batch::new(&[fast], 2, integrator(false, 1000)).unwrap();
    batch.set_states(&[0.0, 0.5], None).unwrap();
    let mut rates = vec![0.0; 2];
    let err = batch
        .step(&[1.0, 1.0], Some(&[true, false]), &mut rates, None)
        .unwrap_err();
    assert!(err.to_string().contains("state[0] of row 0"), "{err}");
    assert_eq!(batch.states()[1], 0.5);
}

#[test]
fn rows_left_out_keep_their_states_and_their_rates() {
    let nets = random_networks(40, 3, 1, 4);
    let mut batch = Batch::new(&nets, 1, Integrator::default()).unwrap();
    let mut rates = vec![0.0; 120];
    batch.step(&[1.0; 40], None, &mut rates, None).unwrap();
    let before = batch.states();
    let mut again = vec![-1.0; 120];
    let mut mask = [false; 40];
    mask[7] = true;
    batch
        .step(&[1.0; 40], Some(&mask), &mut again, None)
        .unwrap();
    let after = batch.states();
    for r in 0..40 {
        let (old, new) = (&before[r * 3..r * 3 + 3], &after[r * 3..r * 3 + 3]);
        assert_eq!(old == new, r != 7, "row {r}");
        assert_eq!(again[r * 3] == -1.0, r != 7, "row {r}");
    }
}

/// Episodes that end at different times, and some that start again from zero: the running rows
/// are moved between lanes as the others end, and every row still ends where `Network::run`
/// ends on its own episodes.
#[test]
fn packing_the_running_rows_does_not_change_their_bits() {
    for f32 in [false, true] {
        packing_keeps_the_bits_in(precision(f32));
    }
}

fn packing_keeps_the_bits_in(precision: Precision) {
    let (p, e, n, m, steps) = (40, 3, 4, 2, 40);
    let nets = random_networks(p, n, m, 11);
    let integ = integrator(false, 2);
    let rows = p * e;
    let end = |r: usize| 1 + (r * 37) % 25; // the first episode's last step
    let restart = |r: usize| r.is_multiple_of(5).then_some(30); // a second episode from step 30
    let on = |r: usize, t: usize| t < end(r) || restart(r).is_some_and(|s| t >= s);
    let mut batch = batch_in(&nets, e, integ, precision);
    let mut rates = vec![0.0; rows * n];
    for t in 0..steps {
        let fresh: Vec<bool> = (0..rows).map(|r| restart(r) == Some(t)).collect();
        batch.reset(Some(&fresh)).unwrap();
        let x: Vec<f64> = (0..rows * m).map(|k| input(k / m, t, k % m)).collect();
        let mask: Vec<bool> = (0..rows).map(|r| on(r, t)).collect();
        batch.step(&x, Some(&mask), &mut rates, None).unwrap();
    }
    let states = batch.states();
    for r in 0..rows {
        let mut single = nets[r / e].clone();
        let run = |from: usize, to: usize, single: &mut Network| {
            let own: Vec<f64> = (from..to)
                .flat_map(|t| (0..m).map(move |k| input(r, t, k)))
                .collect();
            single
                .run_in(&own, to - from, &integ, precision, None)
                .unwrap();
        };
        run(0, end(r), &mut single);
        if let Some(s) = restart(r) {
            single.set_state(None).unwrap();
            run(s, steps, &mut single);
        }
        assert_eq!(
            bits(single.state()),
            bits(&states[r * n..(r + 1) * n]),
            "row {r}, {precision:?}"
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    /// A batch of fewer rows whose rows are handed to other networks as it runs: each row ends
    /// where `Network::run` of its last network, on the inputs of the steps it took part in since
    /// the row was handed to it, ends, bit for bit, and rows not handed over keep their state through an `assign`.
    #[test]
    fn assigned_rows_equal_network_run_bit_for_bit(
        n in 1usize..6, m in 1usize..3, p in 1usize..12, e in 1usize..3, fewer in 0usize..20,
        steps in 2usize..8, rk4 in any::<bool>(), seed in 0u64..1000, f32 in any::<bool>(),
    ) {
        let nets = random_networks(p, n, m, seed);
        let integ = integrator(rk4, 2);
        let rows = (p * e).saturating_sub(fewer).max(1);
        let mut batch = Batch::with_rows_in(&nets, e, rows, integ, precision(f32)).unwrap();
        prop_assert_eq!(batch.rows(), rows);
        let mut owner: Vec<usize> = (0..rows).map(|r| r / e).collect();
        let mut since = vec![0usize; rows];
        // Most rows sit out every other step, so that the running rows are packed together
        // (moved between lanes) before some of them are handed over.
        let on = |r: usize, t: usize| r.is_multiple_of(4) || t.is_multiple_of(2);
        let mut rates = vec![0.0; rows * n];
        for t in 0..steps {
            // At each step, every third row from an offset moves to another network.
            let moved: Vec<usize> = (0..rows).filter(|r| (r + t + seed as usize).is_multiple_of(3)).collect();
            let to: Vec<usize> = moved.iter().map(|r| (r * 5 + t) % p).collect();
            batch.assign(&moved, &to).unwrap();
            for (&r, &q) in moved.iter().zip(&to) {
                owner[r] = q;
                since[r] = t;
            }
            prop_assert_eq!(batch.network_of(), &owner[..]);
            let x: Vec<f64> = (0..rows * m).map(|k| input(k / m, t, k % m)).collect();
            let mask: Vec<bool> = (0..rows).map(|r| on(r, t)).collect();
            batch.step(&x, Some(&mask), &mut rates, None).unwrap();
        }
        let states = batch.states();
        for r in 0..rows {
            let mut single = nets[owner[r]].clone();
            let own: Vec<f64> = (since[r]..steps)
                .filter(|&t| on(r, t))
                .flat_map(|t| (0..m).map(move |k| input(r, t, k)))
                .collect();
            single.run_in(&own, own.len() / m, &integ, precision(f32), None).unwrap();
            prop_assert_eq!(bits(single.state()), bits(&states[r * n..(r + 1) * n]), "row {}", r);
        }
    }
}

#[test]
fn fewer_rows_and_bad_assignments_are_refused_and_change_nothing() {
    let nets = random_networks(3, 2, 1, 7);
    let integ = integrator(false, 1);
    for rows in [0, 7] {
        let err = Batch::with_rows(&nets, 2, rows, integ).unwrap_err();
        assert!(
            err.to_string().contains(&format!(
                "rows is {rows}; expected 1 to networks x replicas = 6"
            )),
            "{err}"
        );
    }
    let mut batch = Batch::with_rows(&nets, 2, 4, integ).unwrap();
    assert_eq!(batch.network_of(), &[0, 0, 1, 1]);
    let mut rates = vec![0.0; 4 * 2];
    batch
        .step(&[0.5, -0.5, 1.0, 0.0], None, &mut rates, None)
        .unwrap();
    let before = bits(&batch.states());
    for (rows, to, says) in [
        (
            vec![4],
            vec![0],
            "row 4 is out of range; the batch has 4 rows",
        ),
        (
            vec![0],
            vec![3],
            "network 3 is out of range; the batch has 3 networks",
        ),
        (vec![1, 1], vec![0, 2], "row 1 is named twice"),
        (vec![1], vec![], "1 row and 0 networks"),
    ] {
        let err = batch.assign(&rows, &to).unwrap_err();
        assert!(err.to_string().contains(says), "{err}");
        assert_eq!(bits(&batch.states()), before);
        assert_eq!(batch.network_of(), &[0, 0, 1, 1]);
    }
}

/// Steps small enough for the spinning helpers: `steps` steps of `p` networks x 2 replicas, each
/// row sitting out the steps its random mask says; every row's state and rates.
fn small_steps(nets: &[Network], steps: usize, seed: u64) -> (Vec<u64>, Vec<u64>) {
    let (rows, n, m) = (nets.len() * 2, nets[0].size(), nets[0].n_inputs());
    let mut batch = Batch::new(nets, 2, integrator(true, 2)).unwrap();
    let mut rates = vec![0.0; rows * n];
    let mut state = seed;
    let mut coin = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        state >> 62 != 0 // true three times in four
    };
    for t in 0..steps {
        let x: Vec<f64> = (0..rows * m).map(|k| input(k / m, t, k % m)).collect();
        let mask: Vec<bool> = (0..rows).map(|_| coin()).collect();
        batch.step(&x, Some(&mask), &mut rates, None).unwrap();
    }
    (bits(&batch.states()), bits(&rates))
}

/// The helpers that share small steps change no bit: the same steps, with random rows left out,
/// give the same states and rates as on one thread (a step from a rayon worker runs its blocks
/// in order on that thread), also with two batches stepping at once from two threads.
#[test]
fn small_steps_shared_with_the_helpers_give_the_bits_of_one_thread() {
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    for seed in 0..6 {
        // 200 rows in 13 blocks of N = 5: too small for rayon, large enough for the helpers.
        let nets = random_networks(100, 5, 2, seed);
        let alone = one.install(|| small_steps(&nets, 30, seed));
        assert_eq!(small_steps(&nets, 30, seed), alone, "seed {seed}");
        let (a, b) = std::thread::scope(|s| {
            let a = s.spawn(|| small_steps(&nets, 30, seed));
            let b = s.spawn(|| small_steps(&nets, 30, seed));
            (a.join().unwrap(), b.join().unwrap())
        });
        assert_eq!(a, alone, "seed {seed}, first of two at once");
        assert_eq!(b, alone, "seed {seed}, second of two at once");
    }
    assert!(ctrnn::testing::spin::helpers() < std::thread::available_parallelism().unwrap().get());
}

/// A step shared with the helpers, or with rayon's threads, fails as one thread would: with the
/// lowest diverging row (though another thread may meet a higher one first), and with
/// `Interrupted` when cancelled.
#[test]
fn small_steps_shared_with_the_helpers_fail_as_one_thread() {
    let calm = Network::new(vec![1.0], vec![0.0], vec![0.0], vec![1.0], None).unwrap();
    // Its first step overflows: 1e308 x 0.5 + 1e308 x 1 is past the largest f64. (A
    // step too long for its time constant is refused before it is taken.)
    let fast = Network::new(vec![1.0], vec![0.0], vec![1e308], vec![1e308], None).unwrap();
    // 256 rows in 16 blocks, 500 Euler steps each: rows 50 and 200 (blocks 3 and 12) diverge.
    let nets: Vec<Network> = (0..256)
        .map(|r| {
            if r == 50 || r == 200 {
                fast.clone()
            } else {
                calm.clone()
            }
        })
        .collect();
    // 500 substeps make a step for the helpers; 2000, one big enough for rayon's threads.
    for substeps in [500, 2000] {
        for _ in 0..20 {
            let mut batch = Batch::new(&nets, 1, integrator(false, substeps)).unwrap();
            let mut rates = vec![0.0; 256];
            let err = batch.step(&[1.0; 256], None, &mut rates, None).unwrap_err();
            assert!(err.to_string().contains("of row 50 "), "{substeps}: {err}");
        }
    }
    let mut batch = Batch::new(&nets[..100], 1, integrator(false, 100)).unwrap();
    let mut rates = vec![0.0; 100];
    let cancel = AtomicBool::new(true);
    let err = batch
        .step(&[1.0; 100], None, &mut rates, Some(&cancel))
        .unwrap_err();
    assert!(matches!(err, Error::Interrupted));
}
