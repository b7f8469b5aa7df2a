use std::sync::atomic::AtomicBool;

use ctrnn::{Error, Integrator, Lanes, Network, LANES};
use tasks::testing::{by_block, by_pair, pairs, Diverged, Kinds};

/// One self-inhibiting neuron driven by its sensor: with a tiny tau, Euler diverges.
fn neuron(tau: f64) -> Network {
    Network::new(vec![tau], vec![0.0], vec![-5.0], vec![1.0], None).unwrap()
}

/// 1000 Euler steps with input 1 (enough for a tiny tau to overflow); each real lane's (network, trial, output).
fn run(
    lanes: &mut Lanes<LANES>,
    lane_pairs: [(usize, usize); LANES],
    len: usize,
) -> std::result::Result<Vec<(usize, usize, f64)>, Diverged> {
    for _ in 0..1000 {
        lanes.step_row(&[[1.0; LANES]], &Integrator::default());
    }
    Diverged::find(lanes)?;
    let out = lanes.output(0);
    Ok((0..len)
        .map(|l| (lane_pairs[l].0, lane_pairs[l].1, out[l]))
        .collect())
}

#[test]
fn pairs_come_back_in_order_and_a_divergence_names_its_network() {
    let (slow, fast) = (neuron(1.0), neuron(0.01));
    let all = pairs(2, 20);
    // Groups of 16, 16 and 8 pairs: the second one holds both networks.
    let groups: Vec<&[(usize, usize)]> = all.chunks(LANES).collect();
    let got = by_pair(&[&slow, &slow], &groups, None, run).unwrap();
    let order: Vec<(usize, usize)> = got.iter().map(|&(n, t, _)| (n, t)).collect();
    assert_eq!(order, all);
    assert!(got.iter().all(|g| g.2 == got[0].2));
    let e = by_pair(&[&slow, &fast], &groups, None, run).unwrap_err();
    assert!(e.to_string().contains("of network 1 became"), "{e}");
    let cancel = AtomicBool::new(true);
    let e = by_pair(&[&slow], &groups[..1], Some(&cancel), run).unwrap_err();
    assert!(matches!(e, Error::Interrupted));
}

#[test]
fn blocks_return_results_in_network_order() {
    let nets: Vec<Network> = (0..40).map(|i| neuron(1.0 + i as f64)).collect();
    let got = by_block::<f64, _, _>(
        &nets,
        3,
        None,
        |len| vec![0usize; len],
        |acc, first, block, _| {
            for (l, a) in acc.iter_mut().enumerate() {
                *a = first + l;
            }
            Diverged::find(block)
        },
        |acc| acc,
    )
    .unwrap();
    assert_eq!(got, (0..40).collect::<Vec<_>>());
    assert!(by_block::<f64, _, _>(
        &[] as &[Network],
        3,
        None,
        |_| 0,
        |_, _, _, _| Ok(()),
        |_| vec![0]
    )
    .unwrap()
    .is_empty());
}

#[test]
fn kinds_tell_copies_apart_bit_for_bit() {
    let (a, b) = (neuron(1.0), neuron(2.0));
    let mut a_moved = a.clone();
    a_moved.set_state(Some(&[0.5])).unwrap();
    // Equal values with other bits are told apart (never wrongly merged).
    let minus_zero = Network::new(vec![1.0], vec![-0.0], vec![-5.0], vec![1.0], None).unwrap();
    let kinds = Kinds::of(&[a.clone(), b.clone(), a.clone(), a_moved, b, minus_zero]);
    assert_eq!(kinds.firsts, vec![0, 1, 3, 5]);
    assert_eq!(kinds.kind, vec![0, 1, 0, 2, 1, 3]);
    assert!(!kinds.all_distinct());
    assert!(Kinds::of(&[a]).all_distinct());
}
