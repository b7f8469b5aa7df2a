use ctrnn::ga::*;
use ctrnn::genome::{self, Layout, Mutation, Ranges};
use ctrnn::{Error, Purpose, Stream};

fn layout(size: usize, n_inputs: usize) -> Layout {
    Layout { size, n_inputs }
}

/// Parents whose neuron k of individual p holds the marker `1000 p + k` in every gene.
fn marked_parents(p: usize, l: Layout) -> Vec<f64> {
    let per = l.genes_per_neuron();
    (0..p * l.len())
        .map(|x| {
            let (i, g) = (x / l.len(), x % l.len());
            (1000 * i + g / per) as f64
        })
        .collect()
}

#[test]
fn selection_parses_and_serializes() {
    assert_eq!("rank".parse::<Selection>().unwrap(), Selection::Rank);
    assert_eq!(
        "proportional".parse::<Selection>().unwrap(),
        Selection::Proportional
    );
    let e = "roulette".parse::<Selection>().unwrap_err().to_string();
    assert!(e.contains("\"roulette\"") && e.contains("\"rank\""), "{e}");
    assert_eq!(serde_json::to_string(&Selection::Rank).unwrap(), "\"rank\"");
    let c: GaConfig = serde_json::from_str(r#"{"selection": "rank", "elitism": 2}"#).unwrap();
    assert_eq!(c.selection, Selection::Rank);
    assert_eq!(c.population, 100);
    assert!(serde_json::from_str::<GaConfig>(r#"{"populaton": 5}"#).is_err());
}

#[test]
fn config_validation_messages() {
    assert!(GaConfig::default().validate().is_ok());
    let msg = |c: GaConfig| c.validate().unwrap_err().to_string();
    let d = GaConfig::default;
    assert!(msg(GaConfig {
        population: 1,
        ..d()
    })
    .contains("population is 1"));
    assert!(msg(GaConfig {
        mutation_rate: f64::NAN,
        ..d()
    })
    .contains("mutation_rate is NaN; it must be in [0, 1]"));
    assert!(msg(GaConfig {
        crossover_rate: -0.1,
        ..d()
    })
    .contains("crossover_rate is -0.1"));
    assert!(msg(GaConfig {
        elitism: 100,
        ..d()
    })
    .contains("elitism is 100; it must be below population = 100"));
    let e = GaConfig {
        ranges: Ranges {
            tau: (-1.0, 1.0),
            ..Ranges::default()
        },
        ..d()
    }
    .validate()
    .unwrap_err();
    assert!(matches!(e, Error::Config(_)) && e.to_string().contains("ranges.tau"));
}

#[test]
fn bad_fitness_names_the_individual() {
    let mut f = vec![1.0; 10];
    f[7] = f64::NAN;
    let e = check_fitness(&f, Selection::Rank).unwrap_err();
    assert!(matches!(e, Error::Fitness(_)));
    assert!(
        e.to_string().contains("fitness of individual 7 is NaN"),
        "{e}"
    );
    f[7] = f64::NEG_INFINITY;
    assert!(check_fitness(&f, Selection::Rank)
        .unwrap_err()
        .to_string()
        .contains("individual 7 is -inf"));
    f[7] = -0.5;
    assert!(check_fitness(&f, Selection::Rank).is_ok());
    let e = check_fitness(&f, Selection::Proportional)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("individual 7 is -0.5") && e.contains("\"rank\""),
        "{e}"
    );
    // next_generation reports it too.
    let l = layout(2, 0);
    let config = GaConfig {
        population: 10,
        ..GaConfig::default()
    };
    f[7] = f64::NAN;
    let parents = vec![1.0; 10 * l.len()];
    let e = next_generation(&parents, &f, l, &config, 0, 0).unwrap_err();
    assert!(e.to_string().contains("individual 7 is NaN"), "{e}");
}

#[test]
fn shape_errors() {
    let l = layout(2, 1);
    let config = GaConfig {
        population: 4,
        ..GaConfig::default()
    };
    let e = next_generation(&[0.0; 40], &[1.0; 3], l, &config, 0, 0)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("fitness has 3 values; expected population = 4"),
        "{e}"
    );
    let e = next_generation(&[0.0; 39], &[1.0; 4], l, &config, 0, 0)
        .unwrap_err()
        .to_string();
    assert!(e.contains("4 x 10 = 40"), "{e}");
}

fn frequencies(sel: &Selector, draws: usize, seed: u64) -> Vec<usize> {
    let mut counts = vec![0; sel.probabilities().len()];
    let mut s = Stream::new(seed, 0, Purpose::Evaluate, 0, 0);
    for _ in 0..draws {
        counts[sel.pick(&mut s)] += 1;
    }
    counts
}

/// Chi-square statistic of `counts` against probabilities `probs` (cells with p = 0 must be 0).
fn chi2(counts: &[usize], probs: &[f64]) -> f64 {
    let n: usize = counts.iter().sum();
    counts
        .iter()
        .zip(probs)
        .map(|(&c, &p)| {
            if p == 0.0 {
                assert_eq!(c, 0, "picked an individual with probability 0");
                0.0
            } else {
                let e = p * n as f64;
                (c as f64 - e).powi(2) / e
            }
        })
        .sum()
}

#[test]
fn proportional_selection_follows_fitness() {
    let fitness = [1.0, 2.0, 0.0, 3.0, 4.0, 0.5];
    let sel = Selector::new(&fitness, Selection::Proportional).unwrap();
    let probs = sel.probabilities();
    let expected: Vec<f64> = fitness.iter().map(|f| f / 10.5).collect();
    for (p, e) in probs.iter().zip(&expected) {
        assert!((p - e).abs() < 1e-15);
    }
    let counts = frequencies(&sel, 200_000, 1);
    // 4 degrees of freedom (5 non-zero cells): P(chi2 > 18.47) = 0.001.
    let x = chi2(&counts, &probs);
    assert!(x < 18.47, "chi2 = {x}, counts {counts:?}");
    // A wrong table must fail the same test: compare with uniform over the non-zero cells.
    let wrong = [0.2, 0.2, 0.0, 0.2, 0.2, 0.2];
    assert!(chi2(&counts, &wrong) > 100.0);
}

#[test]
fn all_zero_fitness_selects_uniformly() {
    let sel = Selector::new(&[0.0; 8], Selection::Proportional).unwrap();
    assert_eq!(sel.probabilities(), vec![0.125; 8]);
    let counts = frequencies(&sel, 80_000, 2);
    // 7 degrees of freedom: P(chi2 > 24.32) = 0.001.
    let x = chi2(&counts, &[0.125; 8]);
    assert!(x < 24.32, "chi2 = {x}, counts {counts:?}");
}

#[test]
fn rank_selection_is_linear_in_rank() {
    // Ranks: individual 1 (-1) = 1, 3 (0) = 2, 2 (5, higher index of a tie) = 3, 0 (5) = 4.
    let sel = Selector::new(&[5.0, -1.0, 5.0, 0.0], Selection::Rank).unwrap();
    let probs = sel.probabilities();
    let expected = [0.4, 0.1, 0.3, 0.2];
    for (p, e) in probs.iter().zip(expected) {
        assert!((p - e).abs() < 1e-15, "{probs:?}");
    }
    let counts = frequencies(&sel, 100_000, 3);
    // 3 degrees of freedom: P(chi2 > 16.27) = 0.001.
    let x = chi2(&counts, &expected);
    assert!(x < 16.27, "chi2 = {x}, counts {counts:?}");
}

#[test]
fn selection_edge_cases() {
    // A single positive fitness is always picked, including at the top of the table.
    let sel = Selector::new(&[0.0, 0.0, 3.0, 0.0], Selection::Proportional).unwrap();
    let counts = frequencies(&sel, 1000, 4);
    assert_eq!(counts, vec![0, 0, 1000, 0]);
    assert!(Selector::new(&[], Selection::Rank).is_err());
    let e = Selector::new(&[f64::MAX, f64::MAX], Selection::Proportional).unwrap_err();
    assert!(matches!(e, Error::Fitness(_)));
}

#[test]
fn mutation_changes_each_gene_with_the_configured_frequency() {
    let l = layout(3, 2); // 21 genes
    let p = 2000;
    let rate = 0.05;
    let config = GaConfig {
        population: p,
        crossover_rate: 0.0,
        mutation_rate: rate,
        ..GaConfig::default()
    };
    // Every parent the same genome, so a child's gene differs exactly when it was mutated.
    let mut s = Stream::new(0, 0, Purpose::Init, 0, 0);
    let one = genome::random(l, &config.ranges, &mut s);
    let parents: Vec<f64> = one.iter().copied().cycle().take(p * l.len()).collect();
    let children = next_generation(&parents, &vec![1.0; p], l, &config, 5, 0).unwrap();
    let mut per_gene = vec![0usize; l.len()];
    for child in children.chunks_exact(l.len()) {
        for (g, (a, b)) in child.iter().zip(&one).enumerate() {
            if a != b {
                per_gene[g] += 1;
            }
        }
    }
    let total: usize = per_gene.iter().sum();
    let n = (p * l.len()) as f64;
    let sd = (n * rate * (1.0 - rate)).sqrt(); // ~ 45
    assert!((total as f64 - n * rate).abs() < 5.0 * sd, "{total} of {n}");
    let sd1 = (p as f64 * rate * (1.0 - rate)).sqrt(); // ~ 9.7 per gene
    for (g, &c) in per_gene.iter().enumerate() {
        assert!(
            (c as f64 - p as f64 * rate).abs() < 5.0 * sd1,
            "gene {g} mutated {c} times of {p}"
        );
    }
}

#[test]
fn crossover_cuts_only_at_neuron_boundaries() {
    let l = layout(5, 2);
    let per = l.genes_per_neuron();
    let p = 40;
    let config = GaConfig {
        population: p,
        crossover_rate: 1.0,
        mutation_rate: 0.0,
        ..GaConfig::default()
    };
    let parents = marked_parents(p, l);
    let fitness: Vec<f64> = (0..p).map(|i| 1.0 + i as f64).collect();
    let children = next_generation(&parents, &fitness, l, &config, 9, 3).unwrap();
    let mut cuts_seen = [false; 5];
    for child in children.chunks_exact(l.len()) {
        // Each neuron block wholly from one parent, and that parent's own neuron k.
        let source: Vec<usize> = child
            .chunks_exact(per)
            .enumerate()
            .map(|(k, block)| {
                assert!(
                    block.iter().all(|&v| v == block[0]),
                    "split block {block:?}"
                );
                let m = block[0] as usize;
                assert_eq!(m % 1000, k, "neuron {k} came from another position");
                m / 1000
            })
            .collect();
        // A prefix of parent A then a suffix of parent B, cut somewhere in 1..=N-1.
        let a = source[0];
        let b = source[l.size - 1];
        let x = source.iter().position(|&s| s != a).unwrap_or(l.size);
        assert!(source[x..].iter().all(|&s| s == b), "{source:?}");
        if a != b {
            assert!((1..l.size).contains(&x));
            cuts_seen[x] = true;
        }
    }
    assert_eq!(cuts_seen, [false, true, true, true, true]);

    // Without crossover, every child is a copy of one parent.
    let config0 = GaConfig {
        crossover_rate: 0.0,
        ..config.clone()
    };
    let children = next_generation(&parents, &fitness, l, &config0, 9, 3).unwrap();
    for child in children.chunks_exact(l.len()) {
        let i = child[0] as usize / 1000;
        assert_eq!(child, &parents[i * l.len()..(i + 1) * l.len()]);
    }

    // One neuron: crossover copies the first parent.
    let l1 = layout(1, 1);
    let parents1 = marked_parents(p, l1);
    let children = next_generation(&parents1, &fitness, l1, &config, 9, 3).unwrap();
    for child in children.chunks_exact(l1.len()) {
        assert!(child.iter().all(|&v| v == child[0]));
    }
}

#[test]
fn resampled_genes_stay_in_range() {
    let l = layout(3, 2);
    let ranges = Ranges {
        tau: (1.0, 1.5),
        theta: (2.0, 3.0),
        weights: (-5.0, -4.0),
        sensor_weights: (7.0, 7.25),
    };
    let config = GaConfig {
        population: 50,
        mutation_rate: 1.0,
        ranges,
        ..GaConfig::default()
    };
    let parents = vec![100.0; 50 * l.len()]; // out of every range
    let children = next_generation(&parents, &[1.0; 50], l, &config, 1, 1).unwrap();
    for child in children.chunks_exact(l.len()) {
        for (g, &v) in child.iter().enumerate() {
            let (lo, hi) = genome::gene_range(l, &ranges, g);
            assert!(lo <= v && v < hi, "gene {g} = {v} outside [{lo}, {hi})");
        }
        assert!(genome::decode(l, child).is_ok());
    }
    let init = initial_population(l, &config, 3).unwrap();
    for child in init.chunks_exact(l.len()) {
        for (g, &v) in child.iter().enumerate() {
            let (lo, hi) = genome::gene_range(l, &ranges, g);
            assert!(lo <= v && v < hi);
        }
    }
}

#[test]
fn elitism_copies_the_best_unchanged() {
    let l = layout(2, 1);
    let p = 10;
    let config = GaConfig {
        population: p,
        elitism: 3,
        crossover_rate: 1.0,
        mutation_rate: 1.0,
        ..GaConfig::default()
    };
    let parents = marked_parents(p, l);
    let fitness = [1.0, 9.0, 2.0, 5.0, 9.0, 0.0, 7.0, 3.0, 4.0, 1.0];
    let children = next_generation(&parents, &fitness, l, &config, 2, 0).unwrap();
    let g = l.len();
    // Best: 1 and 4 (tie at 9, lower index first), then 6.
    for (c, best) in [1usize, 4, 6].into_iter().enumerate() {
        assert_eq!(
            &children[c * g..(c + 1) * g],
            &parents[best * g..(best + 1) * g]
        );
    }
    // Everything after the elites was fully mutated.
    let parent_values: Vec<f64> = parents.clone();
    assert!(children[3 * g..].iter().all(|v| !parent_values.contains(v)));
}

#[test]
fn creep_mutation_moves_genes_a_little_and_is_configured_by_name() {
    let l = layout(4, 2);
    let p = 32;
    let config = GaConfig {
        population: p,
        crossover_rate: 0.0,
        mutation_rate: 1.0,
        mutation: MutationKind::Creep,
        mutation_scale: 0.01,
        ..GaConfig::default()
    };
    let parents = initial_population(l, &config, 3).unwrap();
    let fitness = vec![1.0; p];
    let children = next_generation(&parents, &fitness, l, &config, 3, 0).unwrap();
    let g = l.len();
    // Each child is a copy of some parent with every gene moved by at most 6 sd = 6% of
    // its range: find that parent and check the distance.
    for child in children.chunks_exact(g) {
        let near = parents.chunks_exact(g).any(|parent| {
            (0..g).all(|k| {
                let (lo, hi) = genome::gene_range(l, &config.ranges, k);
                let d = (child[k] - parent[k]).abs();
                d > 0.0 && d <= 0.06 * (hi - lo) + 1e-12
            })
        });
        assert!(near, "a creep child is not a small move from any parent");
    }
    let parsed: GaConfig =
        serde_json::from_str(r#"{"population": 4, "mutation": "creep", "mutation_scale": 0.2}"#)
            .unwrap();
    assert_eq!(parsed.mutation(), Mutation::Creep { scale: 0.2 });
    assert_eq!(GaConfig::default().mutation(), Mutation::Uniform);
    for bad in [0.0, -0.1, 1.5, f64::NAN] {
        let e = GaConfig {
            mutation_scale: bad,
            ..GaConfig::default()
        }
        .validate()
        .unwrap_err()
        .to_string();
        assert!(e.contains("mutation_scale is"), "{e}");
    }
    assert!(serde_json::from_str::<GaConfig>(r#"{"mutation": "gauss"}"#).is_err());
}

#[test]
fn result_is_independent_of_thread_count() {
    let l = layout(4, 2);
    let p = 64;
    let config = GaConfig {
        population: p,
        elitism: 2,
        mutation_rate: 0.1,
        ..GaConfig::default()
    };
    let parents = initial_population(l, &config, 11).unwrap();
    let fitness: Vec<f64> = (0..p).map(|i| ((i * 37) % 17) as f64).collect();
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| next_generation(&parents, &fitness, l, &config, 11, 4).unwrap())
    };
    let one = run(1);
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&one), bits(&run(2)));
    assert_eq!(bits(&one), bits(&run(4)));
    // Same inputs, same children; another generation, other children.
    assert_eq!(bits(&one), bits(&run(1)));
    let other = next_generation(&parents, &fitness, l, &config, 11, 5).unwrap();
    assert_ne!(bits(&one), bits(&other));
    // The initial population does not depend on threads either.
    let init = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| initial_population(l, &config, 11).unwrap())
    };
    assert_eq!(bits(&init(1)), bits(&init(3)));
}
