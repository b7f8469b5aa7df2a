use ctrnn::genome::*;
use ctrnn::rng::Purpose;
use ctrnn::testing::genome::reflect;
use ctrnn::{Error, Network, Stream};
use proptest::prelude::*;

fn stream(k: u64) -> Stream {
    Stream::new(k, 0, Purpose::Init, 0, 0)
}

#[test]
fn layout_sizes_and_block_order() {
    let l = Layout {
        size: 2,
        n_inputs: 3,
    };
    assert_eq!((l.genes_per_neuron(), l.len()), (7, 14));
    let net = Network::new(
        vec![1.0, 2.0],
        vec![3.0, 4.0],
        vec![11.0, 12.0, 21.0, 22.0],
        vec![5.0, 6.0, 7.0, 8.0, 9.0, 10.0],
        None,
    )
    .unwrap();
    assert_eq!(
        encode(&net),
        vec![
            1.0, 3.0, 5.0, 6.0, 7.0, 11.0, 12.0, // neuron 0
            2.0, 4.0, 8.0, 9.0, 10.0, 21.0, 22.0, // neuron 1
        ]
    );
    assert_eq!(l.gene_name(0), "gene 0 (neuron 0, tau[0])");
    assert_eq!(l.gene_name(8), "gene 8 (neuron 1, theta[1])");
    assert_eq!(l.gene_name(10), "gene 10 (neuron 1, sensor_weights[1][1])");
    assert_eq!(l.gene_name(13), "gene 13 (neuron 1, weights[1][1])");
}

#[test]
fn decode_errors_name_the_gene() {
    let l = Layout {
        size: 2,
        n_inputs: 1,
    };
    let e = decode(l, &[1.0; 9]).unwrap_err().to_string();
    assert!(e.contains("9 genes") && e.contains("= 10"), "{e}");
    let mut g = vec![1.0; 10];
    g[5] = -1.0;
    let e = decode(l, &g).unwrap_err().to_string();
    assert!(
        e.contains("gene 5 (neuron 1, tau[1])") && e.contains("> 0"),
        "{e}"
    );
    g[5] = 1.0;
    g[9] = f64::NAN;
    let e = decode(l, &g).unwrap_err().to_string();
    assert!(
        e.contains("gene 9 (neuron 1, weights[1][1])") && e.contains("finite"),
        "{e}"
    );
    let e = decode(
        Layout {
            size: 0,
            n_inputs: 1,
        },
        &[],
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("at least 1 neuron"), "{e}");
}

#[test]
fn ranges_validate_names_the_field() {
    assert!(Ranges::default().validate().is_ok());
    let cases = [
        (
            Ranges {
                tau: (0.0, 1.0),
                ..Ranges::default()
            },
            "ranges.tau",
        ),
        (
            Ranges {
                weights: (2.0, 2.0),
                ..Ranges::default()
            },
            "ranges.weights",
        ),
        (
            Ranges {
                sensor_weights: (0.0, f64::INFINITY),
                ..Ranges::default()
            },
            "ranges.sensor_weights",
        ),
        (
            Ranges {
                theta: (f64::NAN, 1.0),
                ..Ranges::default()
            },
            "ranges.theta",
        ),
        (
            Ranges {
                weights: (-1e308, 1e308),
                ..Ranges::default()
            },
            "ranges.weights is (-1e308, 1e308); its width overflows",
        ),
    ];
    for (r, field) in cases {
        let e = r.validate().unwrap_err();
        assert!(matches!(e, Error::Config(_)));
        assert!(e.to_string().contains(field), "{e}");
    }
}

#[test]
fn random_and_mutated_genes_stay_in_range() {
    let l = Layout {
        size: 4,
        n_inputs: 2,
    };
    let r = Ranges {
        tau: (1.0, 2.0),
        theta: (-3.0, -2.0),
        weights: (5.0, 6.0),
        sensor_weights: (-8.0, -7.0),
    };
    let in_range = |genes: &[f64]| {
        genes.iter().enumerate().all(|(g, &v)| {
            let (lo, hi) = gene_range(l, &r, g);
            lo <= v && v < hi
        })
    };
    let mut s = stream(5);
    for _ in 0..50 {
        let mut genes = random(l, &r, &mut s);
        assert!(in_range(&genes));
        assert!(decode(l, &genes).is_ok());
        assert_eq!(
            mutate(l, &r, &mut genes, 1.0, Mutation::Uniform, &mut s),
            l.len()
        );
        assert!(in_range(&genes));
    }
    let mut genes = random(l, &r, &mut s);
    let before = genes.clone();
    assert_eq!(mutate(l, &r, &mut genes, 0.0, Mutation::Uniform, &mut s), 0);
    assert_eq!(genes, before);
}

#[test]
fn mutation_resamples_with_the_configured_frequency() {
    let l = Layout {
        size: 10,
        n_inputs: 3,
    };
    let r = Ranges::default();
    let mut s = stream(8);
    let rate = 0.05;
    let rounds = 1000;
    let mut genes = random(l, &r, &mut s);
    let (mut reported, mut differing) = (0usize, 0usize);
    for _ in 0..rounds {
        let before = genes.clone();
        reported += mutate(l, &r, &mut genes, rate, Mutation::Uniform, &mut s);
        differing += genes.iter().zip(&before).filter(|(a, b)| a != b).count();
    }
    let n = (rounds * l.len()) as f64; // 150_000 genes
    let sd = (n * rate * (1.0 - rate)).sqrt(); // ~ 84
    assert_eq!(reported, differing);
    assert!(
        (reported as f64 - n * rate).abs() < 5.0 * sd,
        "{reported} of {n}"
    );
}

#[test]
fn creep_steps_have_unit_spread_and_stay_in_range() {
    let mut s = stream(9);
    let steps: Vec<f64> = (0..100_000).map(|_| creep_step(&mut s)).collect();
    let n = steps.len() as f64;
    let mean = steps.iter().sum::<f64>() / n;
    let var = steps.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n;
    assert!(
        mean.abs() < 0.02 && (var - 1.0).abs() < 0.02,
        "{mean} {var}"
    );
    assert!(steps.iter().all(|x| x.abs() <= 6.0));

    let l = Layout {
        size: 3,
        n_inputs: 2,
    };
    let r = Ranges::default();
    let creep = Mutation::Creep { scale: 0.05 };
    let mut genes = random(l, &r, &mut s);
    let before = genes.clone();
    assert_eq!(mutate(l, &r, &mut genes, 1.0, creep, &mut s), l.len());
    for (g, (a, b)) in genes.iter().zip(&before).enumerate() {
        let (lo, hi) = gene_range(l, &r, g);
        assert!(lo <= *a && *a <= hi, "gene {g} = {a}");
        // at most 6 standard deviations, i.e. 0.3 of the range's width
        assert!(
            (a - b).abs() <= 0.3 * (hi - lo) + 1e-12,
            "gene {g}: {b} -> {a}"
        );
    }
    // a gene near an end is reflected back in, never stuck at the end
    let mut genes = vec![r.tau.1; l.len()];
    mutate(
        l,
        &r,
        &mut genes,
        1.0,
        Mutation::Creep { scale: 1.0 },
        &mut s,
    );
    for (g, a) in genes.iter().enumerate() {
        let (lo, hi) = gene_range(l, &r, g);
        assert!(lo <= *a && *a <= hi, "gene {g} = {a}");
    }
}

#[test]
fn reflection_folds_into_the_range() {
    assert_eq!(reflect(11.0, 0.0, 10.0), 9.0);
    assert_eq!(reflect(-3.0, 0.0, 10.0), 3.0);
    assert_eq!(reflect(25.0, 0.0, 10.0), 5.0);
    assert_eq!(reflect(-15.0, 0.0, 10.0), 5.0);
    assert_eq!(reflect(4.0, 0.0, 10.0), 4.0);
}

fn layout_and_genes() -> impl Strategy<Value = (Layout, Vec<f64>)> {
    (1usize..6, 0usize..4).prop_flat_map(|(size, n_inputs)| {
        let l = Layout { size, n_inputs };
        let per = l.genes_per_neuron();
        prop::collection::vec(-1e6..1e6f64, l.len()).prop_map(move |mut g| {
            for i in 0..size {
                g[i * per] = g[i * per].abs() + 1e-3; // tau > 0
            }
            (l, g)
        })
    })
}

proptest! {
    #[test]
    fn round_trip_is_exact((l, genes) in layout_and_genes()) {
        let net = decode(l, &genes).unwrap();
        prop_assert_eq!(Layout::of(&net), l);
        prop_assert_eq!(encode(&net), genes.clone());
        prop_assert_eq!(decode(l, &encode(&net)).unwrap(), net);
    }
}
