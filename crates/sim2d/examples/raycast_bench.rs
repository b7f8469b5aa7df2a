//! Measures the speed of the 2-D world: ray casts per second, and the wall time of one 45 s trial
//! (450 steps of 0.1 s with the wall follower and one 7-ray sonar).
//!
//! Run with `cargo run --release -p sim2d --example raycast_bench`.

use std::hint::black_box;
use std::time::Instant;

use sim2d::{Echo, Sim, SimSpec, World, WorldSpec};
use streams::{Purpose, Stream};

fn main() -> Result<(), sim2d::Error> {
    let world = World::new(&WorldSpec::landmark(2)?)?;

    // Rays from random points in the room in random directions, up to the sonar's 6.5 m.
    let n_rays = 2_000_000u64;
    let mut s = Stream::new(0, 0, Purpose::Evaluate, 0, 0);
    let rays: Vec<([f64; 2], [f64; 2])> = (0..4096)
        .map(|_| {
            let a = s.range(-std::f64::consts::PI, std::f64::consts::PI);
            ([s.range(0.3, 5.7), s.range(0.3, 4.7)], [a.cos(), a.sin()])
        })
        .collect();
    let start = Instant::now();
    let mut hits = 0u64;
    for k in 0..n_rays {
        let (o, d) = rays[(k % 4096) as usize];
        hits += u64::from(black_box(world.cast_ray(o, d, 6.5)).is_some());
    }
    let secs = start.elapsed().as_secs_f64();
    println!(
        "ray casts: {:.2} million rays/s ({} rays in {:.3} s, {} walls and boxes, {} hits)",
        n_rays as f64 / secs / 1e6,
        n_rays,
        secs,
        4 + world.spec().boxes.len(),
        hits
    );

    // Whole trials: random start, wall follower, one default sonar (7 rays), 450 steps.
    let spec = SimSpec::default();
    let trials = 2000u64;
    let start = Instant::now();
    let mut input_sum = 0.0;
    for t in 0..trials {
        let mut s = Stream::new(1, 0, Purpose::Trial, 0, t);
        let mut sim = Sim::random_start(&world, &spec, &mut s)?;
        let mut echo = [Echo::default()];
        for _ in 0..450 {
            sim.step(&mut s, &mut echo)?;
            input_sum += sim2d::input(echo[0].range, sim2d::DEFAULT_D0);
        }
    }
    let secs = start.elapsed().as_secs_f64();
    println!(
        "45 s trial (450 steps, wall follower + one 7-ray sonar): {:.1} us wall time per trial \
         ({:.2} us per step, {} trials in {:.3} s, mean input {:.3})",
        secs / trials as f64 * 1e6,
        secs / (trials * 450) as f64 * 1e6,
        trials,
        secs,
        input_sum / (trials * 450) as f64
    );
    Ok(())
}
