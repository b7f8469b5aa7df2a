use ctrnn::integrate::{Integrator, Method, Precision};
use ctrnn::population::*;
use ctrnn::{Network, Params};
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
    (1usize..7, 0usize..3, 1usize..20, 0usize..12, any::<bool>()).prop_flat_map(
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
    fn population_equals_single_bit_for_bit((nets, inputs, steps, rk4) in arb_population(), f32 in any::<bool>()) {
        // In either precision: a network run alone keeps its population's bits.
        let precision = if f32 { Precision::F32 } else { Precision::F64 };
        let integ = Integrator {
            method: if rk4 { Method::Rk4 } else { Method::Euler },
            dt: 0.1,
            substeps: 3,
        };
        let (n, m, p_len) = (nets[0].size(), nets[0].n_inputs(), nets.len());
        let mut pop = Population::with_precision(&nets, precision).unwrap();
        let all = pop.run(Inputs::PerNetwork(&inputs), steps, &integ, true, None).unwrap();
        for (p, net) in nets.iter().enumerate() {
            let mut single = net.clone();
            let own = &inputs[p * steps * m..(p + 1) * steps * m];
            let s = single.run_in(own, steps, &integ, precision, None).unwrap();
            let mine = &all[p * steps * n..(p + 1) * steps * n];
            prop_assert!(s.iter().zip(mine).all(|(a, b)| a.to_bits() == b.to_bits()));
        }
        let finals = pop.states();
        prop_assert_eq!(finals.len(), p_len * n);
        // Shared inputs: the first network's series for everyone.
        let shared = &inputs[..steps * m];
        let mut pop = Population::with_precision(&nets, precision).unwrap();
        let last = pop.run(Inputs::Shared(shared), steps, &integ, false, None).unwrap();
        for (p, net) in nets.iter().enumerate() {
            let mut single = net.clone();
            single.run_in(shared, steps, &integ, precision, None).unwrap();
            let mine = &last[p * n..(p + 1) * n];
            prop_assert!(single.state().iter().zip(mine).all(|(a, b)| a.to_bits() == b.to_bits()));
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]
    #[test]
    fn a_population_of_borrowed_parameters_is_the_population_of_its_networks(
        (nets, inputs, steps, rk4) in arb_population(),
        f32 in any::<bool>(),
    ) {
        let precision = if f32 { Precision::F32 } else { Precision::F64 };
        let integ = Integrator { method: if rk4 { Method::Rk4 } else { Method::Euler }, ..Integrator::default() };
        let params: Vec<Params> = nets.iter().map(Network::params).collect();
        let run = |mut pop: Population| pop.run(Inputs::PerNetwork(&inputs), steps, &integ, true, None).unwrap();
        let owned = run(Population::with_precision(&nets, precision).unwrap());
        let borrowed = run(Population::from_params(&params, precision).unwrap());
        prop_assert_eq!(
            owned.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
            borrowed.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
        );
    }
}

#[test]
fn an_invalid_member_of_borrowed_parameters_is_named_with_its_index() {
    let ok = Network::new(vec![1.0], vec![0.0], vec![0.5], vec![], None).unwrap();
    let cases: [(Params, &str); 4] = [
        (
            Params {
                tau: &[-1.0],
                ..ok.params()
            },
            "network 1: tau[0] is -1; every time constant must be > 0",
        ),
        (
            Params {
                weights: &[f64::NAN],
                ..ok.params()
            },
            "network 1: weights[0][0] is NaN",
        ),
        (
            Params {
                theta: &[],
                ..ok.params()
            },
            "network 1: theta has 0 values; expected N = 1",
        ),
        (
            Params {
                tau: &[],
                ..ok.params()
            },
            "network 1: tau is empty; a network needs at least 1 neuron",
        ),
    ];
    for (bad, message) in cases {
        let err = Population::from_params(&[ok.params(), bad], Precision::F64).unwrap_err();
        assert!(err.to_string().contains(message), "{err} lacks {message}");
        // Each message is the one Network::new gives, with the member's index.
        let own = Network::new(
            bad.tau.to_vec(),
            bad.theta.to_vec(),
            bad.weights.to_vec(),
            bad.sensor_weights.to_vec(),
            Some(bad.state.to_vec()),
        )
        .unwrap_err();
        assert_eq!(err.to_string().replace("network 1: ", ""), own.to_string());
    }
    assert!(Population::from_params(&[], Precision::F64).is_err());
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
    // Its first step overflows: 1e308 x 0.5 + 1e308 x 1 is past the largest f64. (A
    // step too long for its time constant is refused before it is taken.)
    let fast = Network::new(vec![1.0], vec![0.0], vec![1e308], vec![1e308], None).unwrap();
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

/// Single precision is what it says: the population run in f32 gives the bits of a plain f32
/// Euler loop (parameters, step size and inputs rounded to f32 once; each sum taken in order
/// with fused multiply-adds; `sigmoid_f32`), widened to f64.
#[test]
fn an_f32_population_is_a_plain_f32_euler_loop() {
    use ctrnn::math::sigmoid_f32;
    let (n, m, steps) = (5, 2, 60);
    let nets = ctrnn::testing::integrate::random_networks(19, n, m, 4);
    let inputs: Vec<f64> = (0..steps * m).map(|k| (k % 7) as f64 * 0.3 - 0.9).collect();
    let integ = Integrator {
        method: Method::Euler,
        dt: 0.1,
        substeps: 1,
    };
    let mut pop = Population::with_precision(&nets, Precision::F32).unwrap();
    assert_eq!(pop.precision(), Precision::F32);
    let got = pop
        .run(Inputs::Shared(&inputs), steps, &integ, true, None)
        .unwrap();
    let f = |x: &[f64]| x.iter().map(|&v| v as f32).collect::<Vec<_>>();
    for (p, net) in nets.iter().enumerate() {
        let (tau, theta, w, s) = (
            f(net.tau()),
            f(net.theta()),
            f(net.weights()),
            f(net.sensor_weights()),
        );
        let mut v = f(net.state());
        let h: Vec<f32> = tau.iter().map(|t| 0.1f32 / t).collect();
        for t in 0..steps {
            let x = f(&inputs[t * m..(t + 1) * m]);
            let out: Vec<f32> = (0..n).map(|j| sigmoid_f32(v[j] - theta[j])).collect();
            let next: Vec<f32> = (0..n)
                .map(|i| {
                    let ext = (0..m).fold(0.0f32, |acc, k| s[i * m + k].mul_add(x[k], acc));
                    let acc = (0..n).fold(ext, |acc, j| w[i * n + j].mul_add(out[j], acc));
                    h[i].mul_add(acc - v[i], v[i])
                })
                .collect();
            v = next;
            let row = &got[(p * steps + t) * n..][..n];
            for i in 0..n {
                assert_eq!(
                    row[i].to_bits(),
                    (v[i] as f64).to_bits(),
                    "network {p}, step {t}, neuron {i}"
                );
            }
        }
    }
}

#[test]
fn precision_names_parse() {
    assert_eq!("f32".parse::<Precision>().unwrap(), Precision::F32);
    assert_eq!("f64".parse::<Precision>().unwrap(), Precision::F64);
    assert_eq!(Precision::default(), Precision::F64);
    let e = "f16".parse::<Precision>().unwrap_err().to_string();
    assert!(e.contains(r#""f64" or "f32""#), "{e}");
}
