//! Network-steps per second of the population integrator (no Python): `cargo run --release
//! --example throughput -- N [P] [T]`. The benchmark with a NumPy reference is `bench/integrate.py`.
use ctrnn::{Inputs, Integrator, Network, Population};
use std::time::Instant;

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().unwrap())
        .collect();
    let n = args.first().copied().unwrap_or(5);
    let p = args.get(1).copied().unwrap_or(1000);
    let t = args.get(2).copied().unwrap_or(1000);
    let m = 2;
    // A cheap deterministic filler; the values only need to be in the usual ranges.
    let mut x = 0.5f64;
    let mut next = |lo: f64, hi: f64| {
        x = (x * 3.9 * (1.0 - x)).clamp(1e-6, 1.0 - 1e-6);
        lo + (hi - lo) * x
    };
    let nets: Vec<Network> = (0..p)
        .map(|_| {
            let tau = (0..n).map(|_| next(0.5, 10.0)).collect();
            let theta = (0..n).map(|_| next(-16.0, 16.0)).collect();
            let w = (0..n * n).map(|_| next(-16.0, 16.0)).collect();
            let s = (0..n * m).map(|_| next(-16.0, 16.0)).collect();
            Network::new(tau, theta, w, s, None).unwrap()
        })
        .collect();
    let inputs: Vec<f64> = (0..t)
        .flat_map(|k| [((k / 20) % 2) as f64, ((k / 50) % 2) as f64])
        .collect();
    let integ = Integrator::default();
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let mut pop = Population::new(&nets).unwrap();
        let start = Instant::now();
        pop.run(Inputs::Shared(&inputs), t, &integ, false, None)
            .unwrap();
        best = best.min(start.elapsed().as_secs_f64());
    }
    println!(
        "N = {n}: {:.1} M network-steps/s",
        (p * t) as f64 / best / 1e6
    );
}
