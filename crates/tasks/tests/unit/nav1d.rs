use ctrnn::{Layout, Network, Precision, Task};

use tasks::nav1d::*;
use tasks::testing;
use tasks::Aggregate;

/// A network with zero weights whose neuron `i` fires at the constant rate `f(-theta[i])`.
fn constant(theta: &[f64], m: usize) -> Network {
    let n = theta.len();
    Network::new(
        vec![1.0; n],
        theta.to_vec(),
        vec![0.0; n * n],
        vec![0.0; n * m],
        None,
    )
    .unwrap()
}

/// Right motor on, left off: moves right at `f(8) - f(-8)` per time step.
fn rightward(m: usize) -> Network {
    constant(&[8.0, -8.0, 0.0, 0.0, 0.0], m)
}

fn task(config: Nav1dConfig) -> Nav1dTask {
    Nav1dTask::new(config).unwrap()
}

fn goal_task(envs: &[Environment]) -> Nav1dTask {
    task(Nav1dConfig {
        environments: envs.to_vec(),
        ..Nav1dConfig::default()
    })
}

fn random_networks(count: usize, size: usize, m: usize, seed: u64) -> Vec<Network> {
    testing::random_networks(Layout { size, n_inputs: m }, count, seed)
}

#[test]
fn landmark_contact_includes_both_edges() {
    let config = Nav1dConfig::default();
    for (env, goal, centre) in [
        (Environment::Near, Side::Right, 10.0),
        (Environment::Near, Side::Left, -10.0),
        (Environment::Far, Side::Right, -10.0),
        (Environment::Far, Side::Left, 10.0),
    ] {
        let c = Condition::exact(&config, env, goal);
        assert_eq!(c.landmark, centre);
        for (x, on) in [
            (centre - 2.0, 1.0),
            (centre + 2.0, 1.0),
            (centre, 1.0),
            (centre - 2.0 - 1e-9, 0.0),
            (centre + 2.0 + 1e-9, 0.0),
            (0.0, 0.0),
        ] {
            assert_eq!(c.landmark_input(x, 4.0), on, "{env:?} {goal:?} x = {x}");
        }
    }
}

#[test]
fn velocity_sign_follows_the_stronger_motor() {
    let t = goal_task(&[Environment::Far]);
    let chain = [Condition::exact(t.config(), Environment::Far, Side::Right)];
    let right = t.record(&rightward(2), &chain, true).unwrap();
    let v = 8f64.exp() / (1.0 + 8f64.exp()) - 1.0 / (1.0 + 8f64.exp());
    assert!((right.x[0] - v).abs() < 1e-12, "{}", right.x[0]);
    assert!(right.x.windows(2).take(10).all(|w| w[1] > w[0]));
    let left = t
        .record(&constant(&[-8.0, 8.0, 0.0, 0.0, 0.0], 2), &chain, true)
        .unwrap();
    assert!((left.x[0] + v).abs() < 1e-12);
    let still = t.record(&constant(&[0.0; 5], 2), &chain, true).unwrap();
    assert!(still.x.iter().all(|&x| x == 0.0));
}

#[test]
fn a_trial_ends_at_either_end_or_at_the_time_limit() {
    let t = goal_task(&[Environment::Far]);
    let right = Condition::exact(t.config(), Environment::Far, Side::Right);
    let left = Condition::exact(t.config(), Environment::Far, Side::Left);
    let net = rightward(2);
    // 20 / 0.99933 = 20.013...: the agent crosses x = 20 on its 21st time step.
    for (cond, reached) in [(right, true), (left, false)] {
        let rec = t.record(&net, &[cond], true).unwrap();
        let moving = rec.moving.iter().filter(|&&m| m).count();
        assert_eq!(moving, 21);
        assert!(rec.x[20] >= 20.0 && rec.x[19] < 20.0);
        assert_eq!(rec.reached, vec![reached]);
        assert_eq!(rec.x.len(), 21 + 50);
        // The agent stays where the trial ended.
        assert!(rec.x[21..].iter().all(|&x| x == rec.x[20]));
    }
    // Standing still: the trial runs to max_steps, then the reinforcement period.
    let short = task(Nav1dConfig {
        max_steps: 30,
        ..Nav1dConfig::default()
    });
    let rec = short
        .record(&constant(&[0.0; 5], 2), &[right], true)
        .unwrap();
    assert_eq!(rec.x.len(), 30 + 50);
    assert_eq!(rec.reached, vec![false]);
}

#[test]
fn reinforcement_follows_a_reached_goal_for_its_period() {
    let t = task(Nav1dConfig {
        reinforcement_steps: 7,
        ..Nav1dConfig::default()
    });
    let net = rightward(2);
    let right = Condition::exact(t.config(), Environment::Near, Side::Right);
    let rec = t.record(&net, &[right], true).unwrap();
    let expected: Vec<f64> = [vec![0.0; 21], vec![1.0; 7]].concat();
    assert_eq!(rec.reinforcement, expected);
    // Landmark input while moving over [8, 12]; none during the reinforcement period.
    let on: Vec<usize> = (0..rec.x.len())
        .filter(|&k| rec.landmark[k] == 1.0)
        .collect();
    assert!(!on.is_empty());
    for &k in &on {
        let x_before = if k == 0 { 0.0 } else { rec.x[k - 1] };
        assert!((8.0..=12.0).contains(&x_before), "step {k}: x = {x_before}");
    }
    let left = Condition::exact(t.config(), Environment::Near, Side::Left);
    let rec = t.record(&net, &[left], true).unwrap();
    assert!(rec.reinforcement.iter().all(|&r| r == 0.0));
    assert_eq!(rec.reinforcement.len(), 21 + 7);
}

#[test]
fn the_rightward_network_reaches_exactly_the_goal_right_trials() {
    for reinforcement_input in [false, true] {
        let m = 1 + usize::from(reinforcement_input);
        let t = task(Nav1dConfig {
            reinforcement_input,
            ..Nav1dConfig::default()
        });
        let chains = t.chains(3, 0);
        assert_eq!(chains.len(), 4);
        let eps = t.episodes(&rightward(m), &chains).unwrap();
        for ep in &eps {
            assert_eq!(ep.reached, vec![ep.conditions[0].goal == Side::Right]);
        }
        assert_eq!(t.evaluate(&[rightward(m)], 0, 3, None).unwrap(), vec![0.5]);
        let far = goal_task(&[Environment::Far]);
        if m == 2 {
            assert_eq!(
                far.evaluate(&[rightward(m)], 0, 3, None).unwrap(),
                vec![0.5]
            );
        }
    }
}

#[test]
fn batched_evaluation_equals_the_record_and_ignores_threads() {
    let cases = [Objective::Goal, Objective::Classify, Objective::Single]
        .into_iter()
        .flat_map(|o| [World::Continuous, World::Stepped].map(|w| (o, w)))
        .flat_map(|c| [Precision::F64, Precision::F32].map(|p| (c, p)));
    for ((objective, world), precision) in cases {
        let t = task(Nav1dConfig {
            precision,
            ..jittered(objective, world)
        });
        let nets = random_networks(19, 5, 2, 11);
        let fitness = t.evaluate(&nets, 4, 9, None).unwrap();
        let chains = t.chains(9, 4);
        for (p, net) in nets.iter().enumerate() {
            let (mut sum, mut count) = (0.0, 0);
            for chain in &chains {
                let rec = t.record(net, chain, true).unwrap();
                let single = rec.outputs.iter().flatten().all(|&y| y as f32 as f64 == y);
                assert_eq!(
                    single,
                    precision == Precision::F32,
                    "{objective:?} {world:?} {p}"
                );
                for (k, c) in chain.iter().enumerate() {
                    if let Some((s, _)) = t.judge(k, c, rec.reached[k], rec.classification[k]) {
                        sum += s;
                        count += 1;
                    }
                }
            }
            assert_eq!(
                fitness[p].to_bits(),
                (sum / count as f64).to_bits(),
                "{objective:?} {world:?} {precision:?} {p}"
            );
        }
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let single = one.install(|| t.evaluate(&nets, 4, 9, None).unwrap());
        assert_eq!(single, fitness);
    }
}

#[test]
fn sharing_divides_each_trial_by_the_populations_mean_score() {
    // Recomputed from records in chain order: each scored trial's score over the mean of all
    // networks' scores on it, then the mean (or the worst type's mean) of those.
    for objective in [Objective::Goal, Objective::Single, Objective::Classify] {
        let plain = jittered(objective, World::Continuous);
        let base = task(plain.clone());
        let nets = random_networks(19, 5, 2, 12);
        let chains = base.chains(9, 4);
        let mut scores = vec![vec![]; nets.len()];
        let mut of_type = vec![];
        for chain in &chains {
            let near = usize::from(chain[0].environment == Environment::Near);
            for (p, net) in nets.iter().enumerate() {
                let rec = base.record(net, chain, true).unwrap();
                for (k, c) in chain.iter().enumerate() {
                    if let Some((s, _)) = base.judge(k, c, rec.reached[k], rec.classification[k]) {
                        scores[p].push(s);
                        of_type.extend((p == 0).then_some(near));
                    }
                }
            }
        }
        for k in 0..of_type.len() {
            let mean = scores.iter().fold(0.0, |sum, s| sum + s[k]) / nets.len() as f64;
            for s in scores.iter_mut() {
                s[k] = if mean > 0.0 { s[k] / mean } else { 0.0 };
            }
        }
        let means = base.evaluate(&nets, 4, 9, None).unwrap();
        let mut differs = false;
        for aggregate in [Aggregate::Mean, Aggregate::Min] {
            let shared = Nav1dConfig {
                sharing: true,
                aggregate,
                ..plain.clone()
            };
            let fitness = task(shared).evaluate(&nets, 4, 9, None).unwrap();
            for (p, s) in scores.iter().enumerate() {
                let mean = s.iter().fold(0.0, |sum, x| sum + x) / s.len() as f64;
                let mut by_type = [(0.0, 0usize); 2];
                for (&x, &i) in s.iter().zip(&of_type) {
                    by_type[i].0 += x;
                    by_type[i].1 += 1;
                }
                let worst = by_type
                    .iter()
                    .map(|&(sum, n)| sum / n as f64)
                    .fold(f64::INFINITY, f64::min);
                let want = if aggregate == Aggregate::Mean {
                    mean
                } else {
                    worst
                };
                assert_eq!(fitness[p].to_bits(), want.to_bits(), "{objective:?} {p}");
                differs |= fitness[p] != means[p];
            }
        }
        assert!(differs, "{objective:?}: sharing changed no fitness");
    }
}

#[test]
fn sharing_among_equals_leaves_goal_scores_as_they_are() {
    // Every network of the population alike: a trial is either scored by all (shared score 1)
    // or by none (0), as without sharing.
    let plain = jittered(Objective::Single, World::Continuous);
    let nets = vec![random_networks(1, 5, 2, 3).remove(0); 5];
    let want = task(plain.clone()).evaluate(&nets, 2, 7, None).unwrap();
    let shared = Nav1dConfig {
        sharing: true,
        ..plain
    };
    assert_eq!(task(shared).evaluate(&nets, 2, 7, None).unwrap(), want);
}

#[test]
fn classify_weight_blends_the_goal_with_the_classifier_on_scored_trials() {
    // Recomputed from records: the mean over trials 2..k of (1 - w) * goal + w * the classifier's
    // right-hand output (f(v_C) near, 1 - f(v_C) far) at the end of the trial.
    let plain = jittered(Objective::Single, World::Continuous);
    let base = task(plain.clone());
    let nets = random_networks(11, 5, 2, 21);
    let chains = base.chains(5, 3);
    let w = 0.375;
    let shaped = task(Nav1dConfig {
        classify_weight: w,
        ..plain
    });
    let fitness = shaped.evaluate(&nets, 3, 5, None).unwrap();
    let mut differs = false;
    for (p, net) in nets.iter().enumerate() {
        let (mut total, mut scored) = (0.0, 0);
        for chain in &chains {
            let rec = base.record(net, chain, true).unwrap();
            for k in 1..chain.len() {
                let c = rec.classification[k];
                let right = match chain[k].environment {
                    Environment::Near => c,
                    Environment::Far => 1.0 - c,
                };
                total += (1.0 - w) * f64::from(u8::from(rec.reached[k])) + w * right;
                scored += 1;
            }
        }
        let want = total / scored as f64;
        assert!(
            (fitness[p] - want).abs() < 1e-12,
            "{p}: {} vs {want}",
            fitness[p]
        );
        differs |= fitness[p] != base.evaluate(&nets[p..=p], 3, 5, None).unwrap()[0];
    }
    assert!(differs, "classify_weight changed no fitness");
    // Done right still means the goal reached: the rate and the success rule ignore the weight.
    for net in &nets[..3] {
        let (a, b) = (
            base.assess(net, 6, 2).unwrap(),
            shaped.assess(net, 6, 2).unwrap(),
        );
        assert_eq!(a.rate, b.rate);
    }
    for (params, needle) in [
        (
            serde_json::json!({"objective": "single", "classify_weight": 1.5}),
            "[0, 1]",
        ),
        (
            serde_json::json!({"objective": "single", "classify_weight": -0.1}),
            "[0, 1]",
        ),
        (
            serde_json::json!({"objective": "goal", "classify_weight": 0.5}),
            "\"single\"",
        ),
    ] {
        let e = Nav1dTask::from_params(&params).unwrap_err().to_string();
        assert!(e.contains("classify_weight") && e.contains(needle), "{e}");
    }
}

#[test]
fn near_first_weight_adds_the_landmark_near_first_trials_reached() {
    // Recomputed from records: the unshaped fitness plus w times the fraction of landmark-near
    // chains whose first trial reaches the goal; landmark-far first trials count nothing.
    let plain = jittered(Objective::Single, World::Continuous);
    let base = task(plain.clone());
    let nets = random_networks(23, 5, 2, 8);
    let chains = base.chains(9, 4);
    let w = 0.625;
    let shaped = task(Nav1dConfig {
        near_first_weight: w,
        ..plain
    });
    let (fitness, unshaped) = (
        shaped.evaluate(&nets, 4, 9, None).unwrap(),
        base.evaluate(&nets, 4, 9, None).unwrap(),
    );
    let near: Vec<_> = chains
        .iter()
        .filter(|c| c[0].environment == Environment::Near)
        .collect();
    assert!(!near.is_empty());
    let mut gained = 0;
    for (p, net) in nets.iter().enumerate() {
        let reached = near
            .iter()
            .filter(|chain| base.record(net, chain, true).unwrap().reached[0])
            .count();
        let want = unshaped[p] + w * reached as f64 / near.len() as f64;
        assert!(
            (fitness[p] - want).abs() < 1e-12,
            "{p}: {} vs {want}",
            fitness[p]
        );
        gained += usize::from(reached > 0);
    }
    assert!(gained > 0, "no network reached a landmark-near first goal");
    for net in &nets[..3] {
        assert_eq!(
            base.assess(net, 6, 2).unwrap().rate,
            shaped.assess(net, 6, 2).unwrap().rate
        );
    }
    for (params, needle) in [
        (
            serde_json::json!({"objective": "single", "near_first_weight": -0.5}),
            ">= 0",
        ),
        (
            serde_json::json!({"objective": "classify", "near_first_weight": 0.5}),
            "\"single\"",
        ),
    ] {
        let e = Nav1dTask::from_params(&params).unwrap_err().to_string();
        assert!(e.contains("near_first_weight") && e.contains(needle), "{e}");
    }
}

#[test]
fn min_aggregates_score_the_worst_environment_type() {
    // Per type, the mean over that type's scored trials, recomputed from records in chain order.
    for objective in [Objective::Goal, Objective::Single] {
        let mut config = jittered(objective, World::Continuous);
        let base = task(config.clone());
        let nets = random_networks(19, 5, 2, 12);
        let chains = base.chains(9, 4);
        let means = base.evaluate(&nets, 4, 9, None).unwrap();
        let mut saw_a_gap = false;
        for aggregate in [Aggregate::Min, Aggregate::MeanMin] {
            config.aggregate = aggregate;
            let fitness = task(config.clone()).evaluate(&nets, 4, 9, None).unwrap();
            for (p, net) in nets.iter().enumerate() {
                let mut by_type = [(0.0, 0usize); 2];
                for chain in &chains {
                    let i = usize::from(chain[0].environment == Environment::Near);
                    let rec = base.record(net, chain, true).unwrap();
                    for (k, c) in chain.iter().enumerate() {
                        if let Some((s, _)) =
                            base.judge(k, c, rec.reached[k], rec.classification[k])
                        {
                            by_type[i].0 += s;
                            by_type[i].1 += 1;
                        }
                    }
                }
                let worst = by_type
                    .iter()
                    .map(|&(sum, n)| sum / n as f64)
                    .fold(f64::INFINITY, f64::min);
                let want = match aggregate {
                    Aggregate::Min => worst,
                    _ => 0.5 * (means[p] + worst),
                };
                assert_eq!(fitness[p].to_bits(), want.to_bits(), "{objective:?} {p}");
                assert!(fitness[p] <= means[p]);
                saw_a_gap |= fitness[p] < means[p];
            }
        }
        assert!(
            saw_a_gap,
            "{objective:?}: no network did better in one type than the other"
        );
    }
    let e = Nav1dTask::from_params(&serde_json::json!({"aggregate": "median"})).unwrap_err();
    assert!(e.to_string().contains("aggregate"), "{e}");
}

#[test]
fn classifier_score_is_f_on_near_and_one_minus_f_on_far() {
    let t = task(Nav1dConfig {
        objective: Objective::Classify,
        ..Nav1dConfig::default()
    });
    // Classifier neuron 2 fires at f(-theta) = c whatever happens; motors off.
    let theta_c = -1.5f64;
    let c = 1.0 / (1.0 + theta_c.exp());
    let net = constant(&[0.0, 0.0, theta_c, 0.0, 0.0], 2);
    let fitness = t.evaluate(std::slice::from_ref(&net), 0, 0, None).unwrap()[0];
    assert!((fitness - 0.5 * (c + (1.0 - c))).abs() < 1e-15);
    let near = Condition::exact(t.config(), Environment::Near, Side::Left);
    let far = Condition::exact(t.config(), Environment::Far, Side::Left);
    assert_eq!(t.judge(0, &near, false, 0.8), Some((0.8, true)));
    assert_eq!(t.judge(0, &far, false, 0.8), Some((1.0 - 0.8, false)));
    assert_eq!(t.judge(0, &far, true, 0.2), Some((0.8, true)));
    let a = t.assess(&net, 40, 1).unwrap();
    // c > 0.5: every near trial right, every far trial wrong.
    let near_share = a
        .episodes
        .iter()
        .filter(|e| e.environment == Environment::Near)
        .count() as f64
        / 40.0;
    assert_eq!(a.rate, near_share);
    assert!(!a.success);
}

#[test]
fn single_scores_trials_after_the_first_and_keeps_state() {
    let t = task(Nav1dConfig {
        objective: Objective::Single,
        trials_per_environment: 4,
        ..Nav1dConfig::default()
    });
    let chains = t.chains(5, 2);
    assert_eq!(chains.len(), 4);
    assert!(chains.iter().all(|c| c.len() == 4));
    let environments: Vec<Environment> = chains.iter().map(|c| c[0].environment).collect();
    use Environment::{Far, Near};
    assert_eq!(environments, vec![Far, Far, Near, Near]);
    let net = rightward(2);
    let expected: f64 = chains
        .iter()
        .flat_map(|c| c[1..].iter())
        .filter(|c| c.goal == Side::Right)
        .count() as f64
        / 12.0;
    assert_eq!(t.evaluate(&[net], 2, 5, None).unwrap(), vec![expected]);
    // A recorded chain without reset continues from the state the network carries.
    let nets = random_networks(1, 5, 2, 3);
    let whole = t.record(&nets[0], &chains[0], true).unwrap();
    let head = t.record(&nets[0], &chains[0][..1], true).unwrap();
    let mut cont = nets[0].clone();
    cont.set_state(Some(&head.final_state)).unwrap();
    let tail = t.record(&cont, &chains[0][1..], false).unwrap();
    assert_eq!(whole.reached, [head.reached, tail.reached].concat());
    assert_eq!(whole.final_state, tail.final_state);
}

#[test]
fn fresh_chains_are_keyed_by_seed_and_cover_the_environments() {
    let t = task(Nav1dConfig {
        landmark_jitter: 0.5,
        ..Nav1dConfig::default()
    });
    let a = t.fresh_chains(200, 3, 1);
    assert_eq!(a, t.fresh_chains(200, 3, 1));
    assert_ne!(a, t.fresh_chains(200, 3, 2));
    let near = a
        .iter()
        .filter(|c| c[0].environment == Environment::Near)
        .count();
    assert!((70..130).contains(&near), "{near}");
    for chain in &a {
        for c in chain {
            assert_eq!(c.environment, chain[0].environment);
            let side = if c.landmark > 0.0 {
                Side::Right
            } else {
                Side::Left
            };
            let expect = match c.environment {
                Environment::Near => c.goal,
                Environment::Far => c.goal.opposite(),
            };
            assert_eq!(side, expect);
            assert!((c.landmark.abs() - 10.0).abs() <= 0.5);
        }
    }
}

#[test]
fn the_system_picks_a_network_by_the_classification() {
    let base = Nav1dConfig::default();
    let classify = Nav1dTask::new(Nav1dConfig {
        objective: Objective::Classify,
        ..base.clone()
    })
    .unwrap();
    let goal = Nav1dTask::new(base).unwrap();
    let leftward = constant(&[-8.0, 8.0, 0.0, 0.0, 0.0], 2);
    let part = |task: &Nav1dTask, network: &Network| Part {
        task: task.clone(),
        network: network.clone(),
    };
    // The classifier stands still and says "near" (f(v_C) = f(2) > 0.5): the near network, which
    // always goes right, drives trials 2.., and the far network (always left) never does.
    let says_near = constant(&[0.0, 0.0, -2.0, 0.0, 0.0], 2);
    let system = System::new(
        part(&classify, &says_near),
        part(&goal, &leftward),
        part(&goal, &rightward(2)),
    )
    .unwrap();
    let report = system.assess(30, 4, 8).unwrap();
    for ep in &report.episodes {
        assert_eq!(ep.chosen, Environment::Near);
        assert!(!ep.reached[0]);
        for (c, &r) in ep.conditions[1..].iter().zip(&ep.reached[1..]) {
            assert_eq!(r, c.goal == Side::Right);
        }
    }
    let near = report
        .episodes
        .iter()
        .filter(|e| e.environment == Environment::Near)
        .count();
    assert_eq!(report.classification_rate, near as f64 / 30.0);
    let (a, b, chosen) = system.record(&report.episodes[0].conditions).unwrap();
    assert_eq!(chosen, Environment::Near);
    assert_eq!(a.reached.len(), 1);
    assert_eq!(b.reached, report.episodes[0].reached[1..]);
    // Parts must share a world.
    let other = Nav1dTask::new(Nav1dConfig {
        half_length: 30.0,
        ..Nav1dConfig::default()
    })
    .unwrap();
    let e = System::new(
        part(&classify, &says_near),
        part(&other, &leftward),
        part(&goal, &leftward),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("far network's half_length is 30"), "{e}");
    let stepped = Nav1dTask::new(Nav1dConfig {
        world: World::Stepped,
        ..Nav1dConfig::default()
    })
    .unwrap();
    let e = System::new(
        part(&classify, &says_near),
        part(&goal, &leftward),
        part(&stepped, &leftward),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("near network's world is \"stepped\""), "{e}");
    // Each part must have its role.
    let e = System::new(
        part(&goal, &says_near),
        part(&goal, &leftward),
        part(&goal, &leftward),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("classifier network's task has objective \"goal\""),
        "{e}"
    );
    let far_only = Nav1dTask::new(Nav1dConfig {
        environments: vec![Environment::Far],
        ..Nav1dConfig::default()
    })
    .unwrap();
    let e = System::new(
        part(&classify, &says_near),
        part(&goal, &leftward),
        part(&far_only, &leftward),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("near network's task"), "{e}");
}

#[test]
fn config_errors_name_the_field() {
    let err = |p: serde_json::Value| Nav1dTask::from_params(&p).unwrap_err().to_string();
    use serde_json::json;
    assert!(err(json!({"environments": []})).contains("environments is empty"));
    assert!(err(json!({"environments": ["far", "far"]})).contains("repeats"));
    assert!(err(json!({"environments": ["middle"]}))
        .contains("nav1d: environments[0]: unknown variant `middle`"));
    let e = err(json!({"objective": "both"}));
    assert!(
        e.contains("nav1d: objective: unknown variant `both`"),
        "{e}"
    );
    assert!(err(json!({"left_motor": 7})).contains("left_motor is 7"));
    assert!(
        err(json!({"left_motor": 1})).contains("left_motor is 1, the same neuron as")
            || err(json!({"left_motor": 1})).contains("right_motor is 1, the same neuron as")
    );
    assert!(err(json!({"objective": "classify", "classifier": 1}))
        .contains("classifier is 1, the same neuron as right_motor"));
    assert!(
        err(json!({"objective": "single", "trials_per_environment": 1}))
            .contains("trials_per_environment is 1")
    );
    assert!(err(json!({"half_length": -1.0})).contains("half_length is -1"));
    assert!(err(json!({"landmark_offset": 19.0})).contains("landmark_offset is 19"));
    assert!(err(json!({"start": 25.0})).contains("start is 25"));
    assert!(err(json!({"max_steps": 0})).contains("max_steps is 0"));
    assert!(err(json!({"landmark_jitter": -1.0})).contains("landmark_jitter is -1"));
    assert!(
        err(json!({"integrator": {"method": "euler", "dt": 0.0, "substeps": 1}}))
            .contains("integrator")
    );
    assert!(err(json!({"landmarks": 1})).contains("unknown field `landmarks`"));
    let e = err(json!({"world": "smooth"}));
    assert!(
        e.contains("world: unknown variant `smooth`, expected `continuous` or `stepped`"),
        "{e}"
    );
    let e = err(
        json!({"max_steps": usize::MAX / 2, "integrator": {"method": "euler", "dt": 0.1, "substeps": 10}}),
    );
    assert!(e.contains("max_steps is"), "{e}");
    // Each setting within its limit, their product not: 2^20 steps of 2^13 substeps.
    let e = err(
        json!({"max_steps": 1 << 20, "integrator": {"method": "euler", "dt": 0.1, "substeps": 1 << 13}}),
    );
    assert!(
        e.contains(
            "(max_steps + reinforcement_steps, times 8192 substeps); the limit is 4294967296"
        ),
        "{e}"
    );
    // A goal task needs no classifier neuron; a 2-neuron network is enough.
    let t = Nav1dTask::from_params(&json!({"size": 2, "classifier": 9})).unwrap();
    assert_eq!(t.layout().size, 2);
}

#[test]
fn recorded_conditions_are_checked() {
    let t = goal_task(&[Environment::Far]);
    let mut c = Condition::exact(t.config(), Environment::Far, Side::Left);
    c.start = 25.0;
    let e = t.record(&rightward(2), &[c], true).unwrap_err().to_string();
    assert!(e.contains("conditions[0] has start 25"), "{e}");
    let empty = t.record(&rightward(2), &[], true).unwrap();
    assert!(empty.x.is_empty() && empty.reached.is_empty());
}

#[test]
fn wrong_networks_are_errors() {
    let t = task(Nav1dConfig {
        objective: Objective::Classify,
        ..Nav1dConfig::default()
    });
    let e = t
        .evaluate(&[constant(&[0.0; 5], 1)], 0, 0, None)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("M = 1") && e.contains("landmark, reinforcement"),
        "{e}"
    );
    let e = t
        .evaluate(&[constant(&[0.0; 2], 2)], 0, 0, None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("N must be at least 3"), "{e}");
}

#[test]
fn layout_follows_the_sensors() {
    let t = task(Nav1dConfig {
        reinforcement_input: false,
        size: 6,
        ..Nav1dConfig::default()
    });
    assert_eq!((t.layout().size, t.layout().n_inputs), (6, 1));
}

#[test]
fn chained_goal_trials_run_both_orders_without_reset() {
    let t = task(Nav1dConfig {
        chained: true,
        trials_per_environment: 3,
        ..Nav1dConfig::default()
    });
    let chains = t.chains(0, 0);
    let goals: Vec<Vec<Side>> = chains
        .iter()
        .map(|c| c.iter().map(|x| x.goal).collect())
        .collect();
    use Side::{Left, Right};
    assert_eq!(
        goals,
        vec![
            vec![Left, Right],
            vec![Right, Left],
            vec![Left, Right],
            vec![Right, Left]
        ]
    );
    assert_eq!(t.chain_len(), 3);
    assert_eq!(t.evaluate(&[rightward(2)], 0, 0, None).unwrap(), vec![0.5]);
    let e = Nav1dTask::from_params(&serde_json::json!({"objective": "classify", "chained": true}))
        .unwrap_err()
        .to_string();
    assert!(e.contains("chained is true"), "{e}");
}

/// A config of `world`, with the given objective and jitter.
fn jittered(objective: Objective, world: World) -> Nav1dConfig {
    Nav1dConfig {
        objective,
        landmark_jitter: 1.0,
        start_jitter: 0.5,
        trials_per_environment: 3,
        world,
        ..Nav1dConfig::default()
    }
}

#[test]
fn the_stepped_world_reproduces_the_old_results_bit_for_bit() {
    // Computed by dnnevo before the continuous world (commit 269d343), when every world was
    // stepped: the classify fitness of 19 random networks, and a recorded chain of "single".
    let fitness: [u64; 19] = [
        0x3fdffffffea50b73,
        0x3fdfffffdf25db00,
        0x3fdffffffffffed0,
        0x3fe0000000000000,
        0x3fe0000000000000,
        0x3fdfffffff71fb14,
        0x3fe00000000070d8,
        0x3fdfffffffff1fd7,
        0x3fe00000140cd984,
        0x3fe0000000000000,
        0x3fe0000000000000,
        0x3fe0000000bd6365,
        0x3fdffff14a1e0012,
        0x3fe330ce2d20d230,
        0x3fdffffffffa4154,
        0x3fe0000000000000,
        0x3fdfffffffb3e296,
        0x3fdffffffff82d28,
        0x3fe000ac654c02f7,
    ];
    let nets = random_networks(19, 5, 2, 11);
    let t = task(jittered(Objective::Classify, World::Stepped));
    let got: Vec<u64> = t
        .evaluate(&nets, 4, 9, None)
        .unwrap()
        .iter()
        .map(|f| f.to_bits())
        .collect();
    assert_eq!(got, fitness);
    let t = task(jittered(Objective::Single, World::Stepped));
    let rec = t.record(&nets[3], &t.chains(9, 4)[0], true).unwrap();
    assert_eq!(
        (rec.x.len(), rec.reached.clone()),
        (282, vec![false, false, true])
    );
    assert_eq!(rec.x.last().unwrap().to_bits(), 0xc0341c928e7cbb89);
    let state: Vec<u64> = rec.final_state.iter().map(|v| v.to_bits()).collect();
    assert_eq!(
        state,
        [
            0xbff2e770e4edfd8c,
            0xc024a8b698219621,
            0x403aa12f880078ec,
            0xc01f75005a706055,
            0x3ff8bdb83a8a6ab1
        ]
    );
    // The continuous world is another world: the same networks score differently.
    let t = task(jittered(Objective::Classify, World::Continuous));
    let continuous: Vec<u64> = t
        .evaluate(&nets, 4, 9, None)
        .unwrap()
        .iter()
        .map(|f| f.to_bits())
        .collect();
    assert_ne!(continuous, fitness);
}

/// `config` with `substeps` Euler steps of `1 / substeps` per time step.
fn at_dt(config: &Nav1dConfig, substeps: usize) -> Nav1dTask {
    task(Nav1dConfig {
        integrator: ctrnn::Integrator {
            method: config.integrator.method,
            dt: 1.0 / substeps as f64,
            substeps,
        },
        ..config.clone()
    })
}

/// A network with tau 1 whose weights and sensor weights are the given `(i, j, w)` entries.
fn wired(
    theta: [f64; 5],
    weights: &[(usize, usize, f64)],
    sensors: &[(usize, usize, f64)],
) -> Network {
    let (mut w, mut s) = (vec![0.0; 25], vec![0.0; 10]);
    for &(i, j, x) in weights {
        w[i * 5 + j] = x;
    }
    for &(i, k, x) in sensors {
        s[i * 2 + k] = x;
    }
    Network::new(vec![1.0; 5], theta.to_vec(), w, s, None).unwrap()
}

/// Moves right until it meets the landmark, then left for good: neuron 3 latches on (self-weight
/// 10, threshold 5) once the landmark is sensed, and turns the right motor off and the left on.
/// It reaches the goal in every landmark-far trial and in no landmark-near one.
fn far_seeker() -> Network {
    wired(
        [8.0, -8.0, 0.0, 5.0, 0.0],
        &[(3, 3, 10.0), (1, 3, -16.0), (0, 3, 16.0)],
        &[(3, 0, 10.0)],
    )
}

/// Always moves right. Neuron 3 latches on at the landmark; the classifier (neuron 2, threshold
/// 7.5) fires only with both the latch and the reinforcement, that is in a landmark-near trial
/// with the goal on the right.
fn landmark_and_reward() -> Network {
    wired(
        [8.0, -8.0, 7.5, 5.0, 0.0],
        &[(3, 3, 10.0), (2, 3, 5.0)],
        &[(3, 0, 10.0), (2, 1, 5.0)],
    )
}

#[test]
fn the_agent_converges_with_first_order_in_dt() {
    // No sensors reach the network: the right motor fires at f(-1) and the left motor's state
    // rises smoothly to 2 f(-1), so the agent drifts left at a smoothly changing speed, and
    // stays clear of the landmark (|x| < 5) for the 10 time steps of the trial.
    let net = wired([0.0, 1.0, 0.0, 0.0, 0.0], &[(0, 1, 2.0), (0, 0, 0.5)], &[]);
    for method in [ctrnn::Method::Euler, ctrnn::Method::Rk4] {
        let mut base = Nav1dConfig {
            max_steps: 10,
            reinforcement_steps: 0,
            ..Nav1dConfig::default()
        };
        base.integrator.method = method;
        let chain = [Condition::exact(&base, Environment::Far, Side::Right)];
        let end = |config: &Nav1dConfig, substeps: usize| {
            let rec = at_dt(config, substeps).record(&net, &chain, true).unwrap();
            assert_eq!(rec.x.len(), 10);
            assert!(rec.landmark.iter().all(|&s| s == 0.0));
            rec.x[9]
        };
        let fine = end(&base, 1000);
        assert!((-5.0..-3.0).contains(&fine), "{fine}");
        let [coarse, medium] = [10, 100].map(|s| (end(&base, s) - fine).abs());
        // First order: ten times the step, about ten times the error (11 against the finest).
        let ratio = coarse / medium;
        assert!(
            (8.0..14.0).contains(&ratio),
            "{method:?}: {coarse} / {medium} = {ratio}"
        );
        assert!(medium < 1e-2, "{medium}");
        // The stepped world moves once per time step, whatever dt: a finer dt hardly helps it,
        // and it is off by several times the continuous world's error at dt = 0.1.
        let stepped = Nav1dConfig {
            world: World::Stepped,
            ..base.clone()
        };
        let errors = [10, 100].map(|s| (end(&stepped, s) - fine).abs());
        assert!(errors[1] > 0.8 * errors[0], "{errors:?}");
        assert!(errors[1] > 4.0 * coarse, "{errors:?} vs {coarse}");
    }
}

#[test]
fn hand_built_networks_keep_their_outcomes_at_a_finer_dt() {
    let jitter = Nav1dConfig {
        start_jitter: 1.5,
        landmark_jitter: 2.0,
        objective: Objective::Classify,
        ..Nav1dConfig::default()
    };
    let mut conditions: Vec<Condition> = [Environment::Far, Environment::Near]
        .into_iter()
        .flat_map(|e| [Side::Left, Side::Right].map(|g| Condition::exact(&jitter, e, g)))
        .collect();
    conditions.extend(
        task(jitter.clone())
            .fresh_chains(12, 1, 3)
            .into_iter()
            .flatten(),
    );
    let chains: Vec<Vec<Condition>> = conditions.iter().map(|c| vec![*c]).collect();
    let outcomes = |net: &Network, substeps: usize| -> Vec<(bool, bool)> {
        at_dt(&jitter, substeps)
            .episodes(net, &chains)
            .unwrap()
            .iter()
            .map(|e| (e.reached[0], e.classification[0] >= 0.5))
            .collect()
    };
    let far = outcomes(&far_seeker(), 10);
    for (c, (reached, _)) in conditions.iter().zip(&far) {
        assert_eq!(*reached, c.environment == Environment::Far, "{c:?}");
    }
    assert_eq!(outcomes(&far_seeker(), 100), far);
    let classified = outcomes(&landmark_and_reward(), 10);
    for (c, &(reached, near)) in conditions.iter().zip(&classified) {
        assert_eq!(reached, c.goal == Side::Right, "{c:?}");
        let saw = c.environment == Environment::Near && c.goal == Side::Right;
        assert_eq!(near, saw, "{c:?}");
    }
    assert_eq!(outcomes(&landmark_and_reward(), 100), classified);
}

#[test]
fn the_record_samples_the_continuous_world_once_per_time_step() {
    // The rightward agent crosses x = 20 after 20.013 time steps: the trial moves for 201 ticks
    // of dt = 0.1, recorded as 20 whole time steps and the partial 21st, then 50 of reinforcement.
    let t = goal_task(&[Environment::Near]);
    let chain = [Condition::exact(t.config(), Environment::Near, Side::Right)];
    let rec = t.record(&rightward(2), &chain, true).unwrap();
    assert_eq!(rec.moving.iter().filter(|&&m| m).count(), 21);
    assert_eq!(rec.x.len(), 21 + 50);
    assert!(rec.x[20] >= 20.0 && rec.x[20] < 20.0 + 0.1 && rec.x[19] < 20.0);
    let speed = rec.x[0];
    assert!((rec.x[19] - 20.0 * speed).abs() < 1e-9, "{}", rec.x[19]);
    // The landmark [8, 12] is entered and left inside time steps 9 and 13: the landmark input
    // is the fraction of each time step's ticks that read 1.
    let expect = |k: usize| {
        let reads = (0..10)
            .filter(|&i| (8.0..=12.0).contains(&((10 * k + i) as f64 * 0.1 * speed)))
            .count();
        reads as f64 / 10.0
    };
    for k in 0..20 {
        assert_eq!(rec.landmark[k], expect(k), "time step {k}");
    }
    let partial: Vec<f64> = rec.landmark[..21]
        .iter()
        .copied()
        .filter(|&s| s > 0.0 && s < 1.0)
        .collect();
    assert_eq!(partial.len(), 2, "{:?}", &rec.landmark[..21]);
    assert_eq!(rec.reached, vec![true]);
    assert!(rec.reinforcement[21..].iter().all(|&r| r == 1.0));
    // The stepped world reads the sensor once per time step.
    let stepped = task(Nav1dConfig {
        world: World::Stepped,
        environments: vec![Environment::Near],
        ..Nav1dConfig::default()
    });
    let rec = stepped.record(&rightward(2), &chain, true).unwrap();
    assert!(rec.landmark.iter().all(|&s| s == 0.0 || s == 1.0));
}
