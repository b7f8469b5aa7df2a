use ctrnn::integrate::{Integrator, Method};
use ctrnn::population::*;
use ctrnn::Network;
use proptest::prelude::*;

fn arb_network(n: usize, m: usize) -> impl Strategy<Value = Network> {
    (
        prop::collection::vec(0.5f64..10.0, n),
        prop::collection::vec(-16f64..16.0, n),
        prop::collection::vec(-16f64..16.0, n * n),
        prop::collection::vec(-16f64..16.0, n * m),
        prop::collection::vec(-5f64..5.0, n),
    )
        .prop_map(|(t, th, w, s, v)| Network::new(t, th, w, s, Some(v)).unwrap())
}

fn arb_population() -> impl Strategy<Value = (Vec<Network>, Vec<f64>, usize, bool)> {
    (1usize..7, 0usize..3, 1usize..20, 1usize..12, any::<bool>()).prop_flat_map(
        |(n, m, p, t, rk4)| {
            (
                prop::collection::vec(arb_network(n, m), p),
                prop::collection::vec(-2f64..2.0, p * t * m),
                Just(t),
                Just(rk4),
            )
        },
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn population_equals_single_bit_for_bit((nets, inputs, steps, rk4) in arb_population()) {
        let integ = Integrator {
            method: if rk4 { Method::Rk4 } else { Method::Euler },
            dt: 0.1,
            substeps: 3,
        };
        let (n, m, p_len) = (nets[0].size(), nets[0].n_inputs(), nets.len());
        let mut pop = Population::new(&nets).unwrap();
        let all = pop.run(Inputs::PerNetwork(&inputs), steps, &integ, true, None).unwrap();
        for (p, net) in nets.iter().enumerate() {
            let mut single = net.clone();
            let own = &inputs[p * steps * m..(p + 1) * steps * m];
            let s = single.run(own, steps, &integ).unwrap();
            let mine = &all[p * steps * n..(p + 1) * steps * n];
            prop_assert!(s.iter().zip(mine).all(|(a, b)| a.to_bits() == b.to_bits()));
        }
        let finals = pop.states();
        prop_assert_eq!(finals.len(), p_len * n);
        // Shared inputs: the first network's series for everyone.
        let shared = &inputs[..steps * m];
        let mut pop = Population::new(&nets).unwrap();
        let last = pop.run(Inputs::Shared(shared), steps, &integ, false, None).unwrap();
        for (p, net) in nets.iter().enumerate() {
            let mut single = net.clone();
            single.run(shared, steps, &integ).unwrap();
            let mine = &last[p * n..(p + 1) * n];
            prop_assert!(single.state().iter().zip(mine).all(|(a, b)| a.to_bits() == b.to_bits()));
        }
    }
}

#[test]
fn mixed_shapes_name_the_network() {
    let a = Network::new(vec![1.0], vec![0.0], vec![0.0], vec![], None).unwrap();
    let b = Network::new(vec![1.0; 2], vec![0.0; 2], vec![0.0; 4], vec![], None).unwrap();
    let mut nets = vec![a; 10];
    nets.push(b);
    let e = Population::new(&nets).unwrap_err().to_string();
    assert!(e.contains("network 10 has N = 2"), "{e}");
    assert!(Population::new::<Network>(&[]).is_err());
}

#[test]
fn input_shape_is_checked() {
    let a = Network::new(vec![1.0], vec![0.0], vec![0.0], vec![1.0], None).unwrap();
    let mut pop = Population::new(&[a.clone(), a]).unwrap();
    let integ = Integrator::default();
    let e = pop
        .run(Inputs::PerNetwork(&[0.0; 3]), 2, &integ, true, None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("P x T x M = 4"), "{e}");
}

/// A population whose networks diverge names the first of them by its index in the population,
/// whatever the threads: not its lane in its block, nor the block a thread met first.
#[test]
fn a_diverging_population_names_its_first_diverging_network() {
    let calm = Network::new(vec![1.0], vec![0.0], vec![0.0], vec![1.0], None).unwrap();
    let fast = Network::new(vec![0.01], vec![0.0], vec![0.0], vec![1.0], None).unwrap();
    // 160 networks in 10 blocks: 70 (block 4) and 85 (block 5) diverge. With two threads, one
    // runs blocks 0-4 in order and the other starts at block 5.
    let nets: Vec<Network> = (0..160)
        .map(|p| {
            if p == 70 || p == 85 {
                fast.clone()
            } else {
                calm.clone()
            }
        })
        .collect();
    for threads in [1, 2, 2, 2, 2] {
        let e = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| {
                let mut pop = Population::new(&nets).unwrap();
                pop.run(
                    Inputs::Shared(&[1.0; 1000]),
                    1000,
                    &Integrator::default(),
                    false,
                    None,
                )
            })
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("state[0] of network 70 became"),
            "{threads} threads: {e}"
        );
    }
}
