use std::sync::atomic::AtomicBool;

use ctrnn::evolve::*;
use ctrnn::ga::{self, GaConfig};
use ctrnn::genome::{self, Layout};
use ctrnn::{Network, Purpose, Result, Stream, Validation};

#[test]
fn huge_layouts_and_populations_are_errors_not_aborts() {
    let config = GaConfig::default();
    for (size, n_inputs) in [
        (1_000_000, 1),
        (usize::MAX / 2, usize::MAX / 2),
        (3, usize::MAX),
    ] {
        let e = Evolution::new(
            Layout { size, n_inputs },
            config.clone(),
            0,
            &[],
            Fill::Mutants,
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("the limit is"), "{e}");
    }
    let big = GaConfig {
        population: 1_000_000_000_000,
        ..GaConfig::default()
    };
    let e = Evolution::new(
        Layout {
            size: 5,
            n_inputs: 2,
        },
        big,
        0,
        &[],
        Fill::Mutants,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("TiB") && e.contains("the limit is"), "{e}");
}

/// Fitness: how close neuron 0's firing rate is to 1 after a short run from rest.
struct Excite;
impl Task for Excite {
    fn layout(&self) -> Layout {
        Layout {
            size: 2,
            n_inputs: 1,
        }
    }
    fn evaluate(
        &self,
        networks: &[Network],
        _generation: u64,
        _seed: u64,
        _cancel: Option<&AtomicBool>,
    ) -> Result<Vec<f64>> {
        networks
            .iter()
            .map(|n| {
                let mut n = n.clone();
                n.run(&[1.0; 5], 5, &ctrnn::Integrator::default())?;
                Ok(n.outputs()[0])
            })
            .collect()
    }
}

fn excite(net: &Network) -> f64 {
    let mut n = net.clone();
    n.run(&[1.0; 5], 5, &ctrnn::Integrator::default()).unwrap();
    n.outputs()[0]
}

/// Training fitness is half luck: a bonus drawn per (generation, genome), so the fittest
/// individual of a generation is often a lucky one. Validation sees the true quality,
/// Excite's score, and counts the networks it validated.
#[derive(Default)]
struct Lucky {
    validated: std::sync::atomic::AtomicUsize,
}
impl Task for Lucky {
    fn layout(&self) -> Layout {
        Excite.layout()
    }
    fn evaluate(
        &self,
        networks: &[Network],
        generation: u64,
        seed: u64,
        _cancel: Option<&AtomicBool>,
    ) -> Result<Vec<f64>> {
        Ok(networks
            .iter()
            .map(|n| {
                let bits = genome::encode(n).iter().fold(0u64, |h, g| h ^ g.to_bits());
                let luck = Stream::new(seed, generation, Purpose::Trial, bits, 0).uniform();
                0.5 * excite(n) + 0.5 * luck
            })
            .collect())
    }
    fn validate(
        &self,
        networks: &[Network],
        _seed: u64,
        _cancel: Option<&AtomicBool>,
    ) -> Result<Option<Vec<Validation>>> {
        self.validated
            .fetch_add(networks.len(), std::sync::atomic::Ordering::Relaxed);
        Ok(Some(
            networks
                .iter()
                .map(|n| Validation {
                    rate: excite(n),
                    score: 0.0,
                })
                .collect(),
        ))
    }
}

fn config() -> GaConfig {
    GaConfig {
        population: 40,
        ..GaConfig::default()
    }
}

#[test]
fn validation_picks_the_champion_and_leaves_evolution_unchanged() {
    let task = Lucky::default();
    let plain = GaConfig {
        validation_candidates: 0,
        ..config()
    };
    let mut a = Evolution::new(task.layout(), config(), 3, &[], Fill::Mutants).unwrap();
    let mut b = Evolution::new(task.layout(), plain, 3, &[], Fill::Mutants).unwrap();
    let mut best_seen = f64::NEG_INFINITY;
    for _ in 0..15 {
        a.step(&task, None).unwrap();
        b.step(&task, None).unwrap();
        assert_eq!(
            a.population, b.population,
            "validation must not change evolution"
        );
        let champ = a.champion.as_ref().unwrap();
        let v = champ.validation.expect("chosen by validation");
        assert!(
            v.rate >= best_seen,
            "the champion's validation never gets worse"
        );
        best_seen = v.rate;
        assert_eq!(v.rate, excite(&a.champion_network().unwrap().unwrap()));
    }
    let by_fitness = b.champion.as_ref().unwrap();
    assert!(by_fitness.validation.is_none());
    let (va, vb) = (
        excite(&a.champion_network().unwrap().unwrap()),
        excite(&b.champion_network().unwrap().unwrap()),
    );
    assert!(
        va > vb,
        "validated champion {va} should beat the lucky one {vb}"
    );
}

#[test]
fn validated_runs_resume_identically_and_elites_are_validated_once() {
    let task = Lucky::default();
    let elitist = GaConfig {
        elitism: 5,
        ..config()
    };
    let mut a = Evolution::new(task.layout(), elitist, 8, &[], Fill::Mutants).unwrap();
    for _ in 0..4 {
        a.step(&task, None).unwrap();
    }
    let mut b = Evolution::from_json(&a.to_json()).unwrap();
    let counted = task.validated.load(std::sync::atomic::Ordering::Relaxed);
    assert!(
        counted < 4 * 10,
        "elites carried over are not validated again: {counted}"
    );
    for _ in 0..4 {
        a.step(&task, None).unwrap();
        b.step(&task, None).unwrap();
    }
    assert_eq!(a.champion, b.champion);
    assert_eq!(a.population, b.population);
    assert_eq!(a.to_json(), b.to_json());
}

#[test]
fn fitness_told_from_outside_is_validated_as_a_task_validates_it() {
    // tell_validating with Lucky's own validation runs the same generations, champions and
    // validations as step with Lucky, elites validated once.
    let task = Lucky::default();
    let elitist = GaConfig {
        elitism: 5,
        ..config()
    };
    let mut a = Evolution::new(task.layout(), elitist.clone(), 4, &[], Fill::Mutants).unwrap();
    let mut b = Evolution::new(task.layout(), elitist, 4, &[], Fill::Mutants).unwrap();
    let mut told = 0;
    for _ in 0..6 {
        a.step(&task, None).unwrap();
        let nets = b.networks().unwrap();
        let fitness = task.evaluate(&nets, b.generation, 4, None).unwrap();
        b.tell_validating(&fitness, |batch| {
            told += batch.len();
            Ok(task.validate(batch, 4, None)?.unwrap())
        })
        .unwrap();
        assert_eq!(a.champion, b.champion);
        assert_eq!(a.population, b.population);
    }
    assert!(
        told < 6 * 10,
        "elites carried over are validated once: {told}"
    );
}

#[test]
fn copies_among_the_candidates_are_validated_once() {
    // Ten copies of one network lead the population: the validation sees it once, and every
    // copy gets its validation.
    let evo = |seeds: &[Network]| {
        Evolution::new(Excite.layout(), config(), 3, seeds, Fill::Random).unwrap()
    };
    let one = evo(&[]).networks().unwrap().remove(7);
    let mut copies = evo(&vec![one.clone(); 10]);
    let mut fitness = vec![0.1; 40];
    fitness[..10].fill(0.9);
    let mut batches = vec![];
    let rate = |net: &Network| net.tau()[0] / 100.0;
    copies
        .tell_validating(&fitness, |batch| {
            batches.push(batch.len());
            Ok(batch
                .iter()
                .map(|n| Validation {
                    rate: rate(n),
                    score: 0.0,
                })
                .collect())
        })
        .unwrap();
    assert_eq!(batches, vec![1]);
    let champion = copies.champion.unwrap();
    assert_eq!(champion.genes, genome::encode(&one));
    assert_eq!(champion.validation.unwrap().rate, rate(&one));
}

/// Excite, validated with one fixed (rate, score), whatever it is.
struct Validated(f64, f64);
impl Task for Validated {
    fn layout(&self) -> Layout {
        Excite.layout()
    }
    fn evaluate(
        &self,
        networks: &[Network],
        generation: u64,
        seed: u64,
        cancel: Option<&AtomicBool>,
    ) -> Result<Vec<f64>> {
        Excite.evaluate(networks, generation, seed, cancel)
    }
    fn validate(
        &self,
        networks: &[Network],
        _seed: u64,
        _cancel: Option<&AtomicBool>,
    ) -> Result<Option<Vec<Validation>>> {
        let v = Validation {
            rate: self.0,
            score: self.1,
        };
        Ok(Some(vec![v; networks.len()]))
    }
}

#[test]
fn a_task_s_own_validation_is_checked_before_the_run_keeps_it() {
    // Kept, it would make a checkpoint that from_json refuses (NaN is written as null).
    for (rate, score) in [(1.5, 0.0), (f64::NAN, 0.0), (0.5, f64::INFINITY)] {
        let mut evo = Evolution::new(Excite.layout(), config(), 2, &[], Fill::Mutants).unwrap();
        let e = evo
            .step(&Validated(rate, score), None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("a validation gave rate"), "{e}");
        assert!(Evolution::from_json(&evo.to_json()).is_ok());
    }
    let mut evo = Evolution::new(Excite.layout(), config(), 2, &[], Fill::Mutants).unwrap();
    evo.step(&Validated(0.5, -3.0), None).unwrap();
    assert!(Evolution::from_json(&evo.to_json()).is_ok());
}

#[test]
fn a_validation_told_from_outside_is_checked() {
    let mut evo = Evolution::new(Excite.layout(), config(), 2, &[], Fill::Mutants).unwrap();
    let fitness = vec![0.5; 40];
    for (rate, score) in [(1.5, 0.0), (f64::NAN, 0.0), (0.5, f64::INFINITY)] {
        let e = evo
            .tell_validating(&fitness, |batch| {
                Ok(vec![Validation { rate, score }; batch.len()])
            })
            .unwrap_err()
            .to_string();
        assert!(e.contains("a validation gave rate"), "{e}");
    }
    let e = evo
        .tell_validating(&fitness, |_| Ok(vec![]))
        .unwrap_err()
        .to_string();
    assert!(e.contains("validated 0 networks; it was given 10"), "{e}");
    assert_eq!(
        evo.generation, 0,
        "a refused tell leaves the generation as it was"
    );
    evo.tell_validating(&fitness, |batch| {
        Ok(vec![
            Validation {
                rate: 0.5,
                score: -3.0
            };
            batch.len()
        ])
    })
    .unwrap();
    assert_eq!(evo.champion.unwrap().validation.unwrap().score, -3.0);
}

#[test]
fn tasks_without_validation_and_old_checkpoints_choose_by_fitness() {
    let mut evo = Evolution::new(Excite.layout(), config(), 2, &[], Fill::Mutants).unwrap();
    evo.step(&Excite, None).unwrap();
    let champ = evo.champion.clone().unwrap();
    assert!(champ.validation.is_none());
    let old: serde_json::Value = serde_json::json!({"population": 10});
    let read: GaConfig = serde_json::from_value(old).unwrap();
    assert_eq!(read.validation_candidates, 0);
    assert_eq!(
        GaConfig::default().validation_candidates,
        ga::VALIDATION_CANDIDATES
    );
}

#[test]
fn fitness_improves_and_champion_is_kept() {
    let mut evo = Evolution::new(Excite.layout(), config(), 5, &[], Fill::Mutants).unwrap();
    let first = evo.step(&Excite, None).unwrap().0;
    for _ in 0..10 {
        evo.step(&Excite, None).unwrap();
    }
    let champ = evo.champion.clone().unwrap();
    assert!(champ.fitness >= first.best);
    assert_eq!(evo.generation, 11);
}

#[test]
fn checkpoint_resume_is_identical() {
    let mut a = Evolution::new(Excite.layout(), config(), 9, &[], Fill::Mutants).unwrap();
    for _ in 0..3 {
        a.step(&Excite, None).unwrap();
    }
    let mut b = Evolution::from_json(&a.to_json()).unwrap();
    for _ in 0..3 {
        a.step(&Excite, None).unwrap();
        b.step(&Excite, None).unwrap();
    }
    assert_eq!(a, b);
    for (x, y) in a.population.iter().zip(&b.population) {
        assert_eq!(x.to_bits(), y.to_bits());
    }
}

#[test]
fn seeding_places_seeds_and_fills() {
    let layout = Excite.layout();
    let net = Network::new(
        vec![1.0, 2.0],
        vec![0.0; 2],
        vec![0.0; 4],
        vec![1.0, 1.0],
        None,
    )
    .unwrap();
    let g = layout.len();
    let evo = Evolution::new(
        layout,
        config(),
        1,
        std::slice::from_ref(&net),
        Fill::Mutants,
    )
    .unwrap();
    assert_eq!(&evo.population[..g], genome::encode(&net).as_slice());
    let close = evo.population[g..]
        .chunks(g)
        .filter(|c| *c == genome::encode(&net).as_slice())
        .count();
    assert!(
        close > 0,
        "with mutation 0.025 some mutants are exact copies"
    );
    let evo = Evolution::new(
        layout,
        config(),
        1,
        std::slice::from_ref(&net),
        Fill::Random,
    )
    .unwrap();
    assert!(evo.population[g..]
        .chunks(g)
        .all(|c| c != genome::encode(&net).as_slice()));
    let wrong = Network::new(vec![1.0], vec![0.0], vec![0.0], vec![0.0], None).unwrap();
    assert!(Evolution::new(layout, config(), 1, &[wrong], Fill::Mutants).is_err());
}

#[test]
fn tell_rejects_nan_and_wrong_length() {
    let mut evo = Evolution::new(Excite.layout(), config(), 1, &[], Fill::Mutants).unwrap();
    let mut f = vec![0.5; 40];
    f[7] = f64::NAN;
    assert!(evo
        .tell(&f)
        .unwrap_err()
        .to_string()
        .contains("individual 7"));
    assert!(evo.tell(&[0.5; 3]).is_err());
    assert_eq!(evo.generation, 0);
}

/// Lucky, with a step check: at the finer step, a network whose first gene's lowest mantissa
/// bit is set keeps only a tenth of its rate (a "step artefact"); the others keep it all.
#[derive(Default)]
struct Jumpy {
    lucky: Lucky,
    checked: std::sync::atomic::AtomicUsize,
}
fn artefact(net: &Network) -> bool {
    genome::encode(net)[0].to_bits() & 1 == 1
}
fn at_finer_step(net: &Network) -> Validation {
    let rate = excite(net) * if artefact(net) { 0.1 } else { 1.0 };
    Validation { rate, score: 0.0 }
}
impl Task for Jumpy {
    fn layout(&self) -> Layout {
        self.lucky.layout()
    }
    fn evaluate(
        &self,
        networks: &[Network],
        generation: u64,
        seed: u64,
        cancel: Option<&AtomicBool>,
    ) -> Result<Vec<f64>> {
        self.lucky.evaluate(networks, generation, seed, cancel)
    }
    fn validate(
        &self,
        networks: &[Network],
        seed: u64,
        cancel: Option<&AtomicBool>,
    ) -> Result<Option<Vec<Validation>>> {
        self.lucky.validate(networks, seed, cancel)
    }
    fn validate_finer(
        &self,
        networks: &[Network],
        _seed: u64,
        _cancel: Option<&AtomicBool>,
    ) -> Result<Option<Vec<Validation>>> {
        self.checked
            .fetch_add(networks.len(), std::sync::atomic::Ordering::Relaxed);
        Ok(Some(networks.iter().map(at_finer_step).collect()))
    }
}

fn step_checked() -> GaConfig {
    GaConfig {
        champion_step_check: true,
        elitism: 3,
        ..config()
    }
}

#[test]
fn the_step_check_keeps_artefacts_from_the_championship_and_leaves_evolution_unchanged() {
    let task = Jumpy::default();
    let plain = GaConfig {
        champion_step_check: false,
        ..step_checked()
    };
    let mut a = Evolution::new(task.layout(), step_checked(), 4, &[], Fill::Mutants).unwrap();
    let mut b = Evolution::new(task.layout(), plain, 4, &[], Fill::Mutants).unwrap();
    let (mut differed, mut last) = (false, f64::NEG_INFINITY);
    for _ in 0..20 {
        a.step(&task, None).unwrap();
        b.step(&task, None).unwrap();
        assert_eq!(
            a.population, b.population,
            "the check must not change evolution"
        );
        let champ = a.champion_network().unwrap().unwrap();
        let held = a.champion.as_ref().unwrap().validation.unwrap();
        let coarse = Validation {
            rate: excite(&champ),
            score: 0.0,
        };
        assert_eq!(held, coarse.worse(&at_finer_step(&champ)));
        assert!(
            held.rate >= last,
            "the champion's validation never gets worse"
        );
        last = held.rate;
        differed |= a.champion != b.champion;
        let unchecked = b.champion_network().unwrap().unwrap();
        if artefact(&unchecked) {
            assert!(a.champion != b.champion);
        }
    }
    assert!(
        differed,
        "some generation's unchecked champion is a step artefact"
    );
    let checked = task.checked.load(std::sync::atomic::Ordering::Relaxed);
    assert!(
        (1..20 * 10).contains(&checked),
        "only would-be champions are checked: {checked}"
    );
}

#[test]
fn copies_among_the_would_be_champions_are_step_checked_once() {
    // A population of copies of one step artefact: every candidate's validation at the run's
    // step beats the worse of its two, so each copy would be checked in turn; one check does.
    let task = Jumpy::default();
    let first = Evolution::new(task.layout(), step_checked(), 5, &[], Fill::Mutants).unwrap();
    let mut genes = genome::encode(&first.networks().unwrap()[0]);
    genes[0] = f64::from_bits(genes[0].to_bits() | 1);
    let one = genome::decode(task.layout(), &genes).unwrap();
    assert!(artefact(&one));
    let mut copies = Evolution::new(
        task.layout(),
        step_checked(),
        5,
        &vec![one.clone(); 40],
        Fill::Mutants,
    )
    .unwrap();
    copies.step(&task, None).unwrap();
    assert_eq!(task.checked.load(std::sync::atomic::Ordering::Relaxed), 1);
    // The champion holds the worse of its two validations: the finer step's.
    let held = copies.champion.as_ref().unwrap().validation.unwrap();
    assert_eq!(held, at_finer_step(&one));
}

#[test]
fn step_checked_runs_resume_identically_and_old_checkpoints_read_unchanged() {
    let task = Jumpy::default();
    let mut a = Evolution::new(task.layout(), step_checked(), 6, &[], Fill::Mutants).unwrap();
    for _ in 0..3 {
        a.step(&task, None).unwrap();
    }
    let text = a.to_json();
    assert!(text.contains("\"champion_step_check\":true"));
    let mut b = Evolution::from_json(&text).unwrap();
    for _ in 0..3 {
        a.step(&task, None).unwrap();
        b.step(&task, None).unwrap();
    }
    assert_eq!(a.to_json(), b.to_json());
    let off = Evolution::new(task.layout(), config(), 6, &[], Fill::Mutants).unwrap();
    assert!(!off.to_json().contains("champion_step_check"));
}

#[test]
fn the_step_check_needs_candidates_and_a_task_that_can_check() {
    let none = GaConfig {
        validation_candidates: 0,
        ..step_checked()
    };
    let e = none.validate().unwrap_err().to_string();
    assert!(
        e.contains("champion_step_check") && e.contains("validation_candidates"),
        "{e}"
    );
    let mut evo = Evolution::new(Excite.layout(), step_checked(), 1, &[], Fill::Mutants).unwrap();
    let lucky = Lucky::default();
    let e = evo.step(&lucky, None).unwrap_err().to_string();
    assert!(e.contains("champion_step_check is on"), "{e}");
    let mut plain = Evolution::new(Excite.layout(), step_checked(), 1, &[], Fill::Mutants).unwrap();
    plain.step(&Excite, None).unwrap();
    assert!(
        plain.champion.unwrap().validation.is_none(),
        "no validation set, nothing to check"
    );
}

/// The state's fields are public: a caller who changes them gets an error from the next tell,
/// naming what is wrong, not a panic or a checkpoint that cannot be read back.
#[test]
fn a_state_changed_by_hand_is_an_error_at_the_next_tell() {
    let fresh = || Evolution::new(Excite.layout(), config(), 2, &[], Fill::Mutants).unwrap();
    let p = config().population;

    let mut evo = fresh();
    evo.config.population = 0;
    let e = evo.tell(&[]).unwrap_err().to_string();
    assert!(e.contains("population is 0"), "{e}");

    let mut evo = fresh();
    evo.population[3] = f64::NAN;
    let e = evo.tell(&vec![1.0; p]).unwrap_err().to_string();
    assert!(e.contains("the evolution's population[0]"), "{e}");
    assert_eq!(evo.generation, 0, "a refused tell changes nothing");

    let mut evo = fresh();
    evo.tell(&vec![1.0; p]).unwrap();
    evo.champion.as_mut().unwrap().fitness = f64::NAN;
    let e = evo.tell(&vec![1.0; p]).unwrap_err().to_string();
    assert!(
        e.contains("the evolution's champion has fitness NaN"),
        "{e}"
    );

    let mut evo = fresh();
    evo.population.pop();
    let e = evo.tell(&vec![1.0; p]).unwrap_err().to_string();
    assert!(e.contains("the evolution's population has"), "{e}");
}
