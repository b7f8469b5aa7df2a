//! The landmark-recognition task: robot trials in the two worlds, the fitness of a generation,
//! a recorded trial for figures, and the (robot-like) assessment with its confusion matrix.

use std::sync::atomic::AtomicBool;

use ctrnn::{
    Elem, Error, Lanes, Layout, Network, Purpose, Result, Stream, Task, Validation, LANES,
};
use rayon::prelude::*;
use serde::Serialize;
use sim2d::{Echo, Sim, SimSpec, World, WorldSpec};

use super::config::{config_error, LandmarkConfig};
use crate::common::{check_inputs, config_from_params, in_precision, interrupted, Diverged, Memo};
use crate::lanes::{by_block, by_pair, pairs};

/// The fraction of fresh trials a network must classify right to have solved the task.
pub const SUCCESS_RATE: f64 = 0.95;

/// Fresh trials per landmark a run uses to check whether its champion has succeeded yet.
pub const SUCCESS_TRIALS: usize = 20;

/// The landmark-recognition task: a validated [`LandmarkConfig`].
#[derive(Clone, Debug, PartialEq)]
pub struct LandmarkTask {
    config: LandmarkConfig,
    /// The validation set of the last seed asked for: the same in every generation of a run.
    validation_set: Memo<u64, Vec<Sensing>>,
}

/// What the robot sensed in one trial. The wall follower drives the robot, not the network, so
/// this does not depend on the network and is computed once per trial for a whole generation.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Sensing {
    /// The landmark, 1 or 2.
    pub landmark: u8,
    /// The world of the trial (jittered under robot-like conditions).
    pub world: WorldSpec,
    /// The network's input at each step, `min(1, d0 / range)`.
    pub input: Vec<f64>,
    /// The sonar's range at each step, in metres.
    pub range: Vec<f64>,
    /// The robot's pose `[x, y, heading]` at each step, before it moves.
    pub poses: Vec<[f64; 3]>,
    /// Where the echo came from at each step (`None`: nothing within range).
    pub echoes: Vec<Option<[f64; 2]>>,
}

/// A network's run through one trial.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Record {
    /// The trial.
    pub sensing: Sensing,
    /// Every neuron's firing rate after each step (T x N).
    pub outputs: Vec<Vec<f64>>,
    /// The classifier's output at the end: `< 0.5` means landmark 1.
    pub classification: f64,
}

/// A network judged on fresh trials.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Assessment {
    /// Whether the trials were robot-like.
    pub robot_like: bool,
    /// `confusion[true landmark - 1][answer - 1]`: counts of trials.
    pub confusion: [[usize; 2]; 2],
    /// Each trial's landmark and final classifier output.
    pub trials: Vec<(u8, f64)>,
    /// The fraction classified right.
    pub rate: f64,
    /// The rate success needs, [`SUCCESS_RATE`].
    pub required: f64,
    /// Whether `rate >= required`.
    pub success: bool,
}

/// The answer a final output gives: landmark 1 below 0.5, else 2.
pub fn answer(output: f64) -> u8 {
    if output < 0.5 {
        1
    } else {
        2
    }
}

/// A trial's score: `1 - f` on landmark 1, `f` on landmark 2.
pub fn score(landmark: u8, output: f64) -> f64 {
    if landmark == 1 {
        1.0 - output
    } else {
        output
    }
}

impl LandmarkTask {
    /// The task for `config`, which is validated.
    pub fn new(config: LandmarkConfig) -> Result<Self> {
        config.validate()?;
        Ok(LandmarkTask {
            config,
            validation_set: Memo::default(),
        })
    }

    /// The task from a JSON object of [`LandmarkConfig`] fields (`null` means all defaults).
    pub fn from_params(params: &serde_json::Value) -> Result<Self> {
        LandmarkTask::new(config_from_params("landmark", params)?)
    }

    /// The config.
    pub fn config(&self) -> &LandmarkConfig {
        &self.config
    }

    /// Runs the robot through one trial with landmark `landmark`, drawing (in this order) the
    /// world's jitter if `robot_like`, the start pose, then the sonar noise from `stream`.
    pub fn sense(&self, landmark: u8, mut stream: Stream, robot_like: bool) -> Result<Sensing> {
        if landmark != 1 && landmark != 2 {
            return Err(Error::InvalidArgument(format!(
                "landmark is {landmark}; it must be 1 or 2"
            )));
        }
        let c = &self.config;
        let rl = &c.robot_like;
        let spec = c.world(landmark);
        let world_spec = if robot_like {
            spec.jittered(&mut stream, rl.box_shift, rl.room_scale)
                .map_err(config_error)?
        } else {
            spec.clone()
        };
        let mut sim_spec = c.sim.clone();
        if robot_like {
            sim_spec.sonars[0].noise_sd = rl.noise_sd;
            sim_spec.sonars[0].specular_max_incidence_deg = Some(rl.specular_max_incidence_deg);
        }
        self.sense_in(landmark, world_spec, &sim_spec, c.steps(), stream)
    }

    /// Runs the robot through `steps` steps in `world_spec` with `sim_spec`, drawing the start
    /// pose, then the sonar noise from `stream`.
    pub(crate) fn sense_in(
        &self,
        landmark: u8,
        world_spec: WorldSpec,
        sim_spec: &SimSpec,
        steps: usize,
        mut stream: Stream,
    ) -> Result<Sensing> {
        let world = World::new(&world_spec).map_err(config_error)?;
        let mut sim = Sim::random_start(&world, sim_spec, &mut stream).map_err(config_error)?;
        let d0 = self.config.d0;
        let mut echoes = vec![Echo::default(); sim_spec.sonars.len()];
        let mut sensing = Sensing {
            landmark,
            world: world_spec,
            input: Vec::with_capacity(steps),
            range: Vec::with_capacity(steps),
            poses: Vec::with_capacity(steps),
            echoes: Vec::with_capacity(steps),
        };
        for _ in 0..steps {
            let p = sim.pose();
            sim.step(&mut stream, &mut echoes).map_err(config_error)?;
            sensing.poses.push([p.x, p.y, p.heading]);
            sensing.range.push(echoes[0].range);
            sensing.echoes.push(echoes[0].point);
            sensing.input.push(sim2d::input(echoes[0].range, d0));
        }
        Ok(sensing)
    }

    /// The trials every individual of `generation` runs: `trials_per_landmark` with landmark 1,
    /// then as many with landmark 2; trial `t` draws from
    /// `Stream::new(seed, generation, Purpose::Trial, 0, t)`, robot-like if `train_robot_like`,
    /// varied as [`LandmarkConfig::training`] says (`training.rs`).
    pub fn trials(&self, seed: u64, generation: u64) -> Result<Vec<Sensing>> {
        let k = self.config.trials_per_landmark;
        (0..2 * k)
            .into_par_iter()
            .map(|t| self.training_trial(seed, generation, t))
            .collect()
    }

    /// `per_landmark` fresh trials per landmark (landmark 1 first), trial `t` drawn from
    /// `Stream::new(seed, 0, Purpose::Evaluate, 0, t)`.
    pub fn fresh_trials(
        &self,
        per_landmark: usize,
        seed: u64,
        robot_like: bool,
    ) -> Result<Vec<Sensing>> {
        self.trials_from(Purpose::Evaluate, per_landmark, seed, robot_like)
    }

    /// [`fresh_trials`](Self::fresh_trials) drawn from `purpose`'s streams.
    pub fn trials_from(
        &self,
        purpose: Purpose,
        per_landmark: usize,
        seed: u64,
        robot_like: bool,
    ) -> Result<Vec<Sensing>> {
        self.sensed(purpose, per_landmark, seed, robot_like, None)
    }

    /// [`trials_from`](Self::trials_from) that stops with [`Error::Interrupted`] soon after
    /// `cancel` is set: sensing many robot-like trials takes seconds.
    fn sensed(
        &self,
        purpose: Purpose,
        per_landmark: usize,
        seed: u64,
        robot_like: bool,
        cancel: Option<&AtomicBool>,
    ) -> Result<Vec<Sensing>> {
        (0..2 * per_landmark)
            .into_par_iter()
            .map(|t| {
                if interrupted(cancel) {
                    return Err(Error::Interrupted);
                }
                let stream = Stream::new(seed, 0, purpose, 0, t as u64);
                let landmark = if t < per_landmark { 1 } else { 2 };
                self.sense(landmark, stream, robot_like)
            })
            .collect()
    }

    /// Feeds `inputs[l]` to lane `l` (all of the same length) from a reset state; `observe` sees
    /// the network after each step. Returns the classifier's final output on every lane (widened to
    /// `f64`, exactly).
    fn run_lanes<const L: usize, E: Elem>(
        &self,
        lanes: &mut Lanes<L, E>,
        inputs: [&[f64]; L],
        mut observe: impl FnMut(&Lanes<L, E>),
    ) -> std::result::Result<[f64; L], Diverged> {
        lanes.reset();
        for t in 0..inputs[0].len() {
            // The network reads the sonar in its own precision.
            lanes.step_row(
                &[inputs.map(|x| E::from_f64(x[t]))],
                &self.config.integrator,
            );
            observe(lanes);
        }
        Diverged::find(lanes)?;
        Ok(lanes.output(self.config.classifier).map(E::to_f64))
    }

    /// Each network's final classifier output on each trial: `out[p][t]`.
    pub fn outputs(
        &self,
        networks: &[Network],
        trials: &[Sensing],
        cancel: Option<&AtomicBool>,
    ) -> Result<Vec<Vec<f64>>> {
        self.check(networks)?;
        in_precision!(self.config.precision, E => by_block::<E, _, _>(
            networks,
            trials.len(),
            cancel,
            |len| vec![vec![0.0; trials.len()]; len],
            |out, _, block, t| {
                let f = self.run_lanes(block, [trials[t].input.as_slice(); LANES], |_| {})?;
                for (l, row) in out.iter_mut().enumerate() {
                    row[t] = f[l];
                }
                Ok(())
            },
            |out| out,
        ))
    }

    /// Each network's final classifier output on each trial (`out[p][t]`), with (network,
    /// trial) pairs [`LANES`] at a time in parallel: for a few networks and many trials, where
    /// [`outputs`](Self::outputs) would leave lanes and cores idle. Lanes share a time axis, so a
    /// group holds only trials of one length (varied trials differ in length). A lane's result
    /// does not depend on its neighbours, so both give the same bits.
    fn outputs_by_pair(
        &self,
        networks: &[Network],
        trials: &[Sensing],
        cancel: Option<&AtomicBool>,
    ) -> Result<Vec<Vec<f64>>> {
        self.check(networks)?;
        let mut pairs = pairs(networks.len(), trials.len());
        // A stable sort: pairs of one length keep their order, so unvaried sets group as before.
        pairs.sort_by_key(|&(_, t)| trials[t].input.len());
        let mut groups: Vec<&[(usize, usize)]> = vec![];
        let mut rest = pairs.as_slice();
        while let Some(&(_, t0)) = rest.first() {
            let len = trials[t0].input.len();
            let n = rest
                .iter()
                .take(LANES)
                .take_while(|&&(_, t)| trials[t].input.len() == len)
                .count();
            let (group, tail) = rest.split_at(n);
            groups.push(group);
            rest = tail;
        }
        let refs: Vec<&Network> = networks.iter().collect();
        let results = in_precision!(self.config.precision, E => by_pair::<E, _>(&refs, &groups, cancel, |lanes, lane_pairs, len| {
            let inputs = lane_pairs.map(|(_, t)| trials[t].input.as_slice());
            let f = self.run_lanes(lanes, inputs, |_| {})?;
            Ok(f[..len].to_vec())
        }))?;
        let mut out = vec![vec![0.0; trials.len()]; networks.len()];
        for (&(p, t), y) in pairs.iter().zip(results) {
            out[p][t] = y;
        }
        Ok(out)
    }

    /// The fitness of every network in `generation`: the mean trial score over
    /// [`trials`](Self::trials).
    pub fn scores(
        &self,
        networks: &[Network],
        generation: u64,
        seed: u64,
        cancel: Option<&AtomicBool>,
    ) -> Result<Vec<f64>> {
        let trials = self.trials(seed, generation)?;
        let outputs = self.outputs(networks, &trials, cancel)?;
        Ok(outputs
            .iter()
            .map(|f| {
                let total: f64 = trials
                    .iter()
                    .zip(f)
                    .map(|(s, &o)| score(s.landmark, o))
                    .sum();
                total / trials.len() as f64
            })
            .collect())
    }

    /// Runs `net` through one trial, recorded step by step. Bit-identical to the evaluation.
    pub fn record(&self, net: &Network, sensing: Sensing) -> Result<Record> {
        self.check(std::slice::from_ref(net))?;
        let n = net.size();
        let mut outputs = Vec::with_capacity(sensing.input.len());
        let f = in_precision!(self.config.precision, E => {
            let mut lanes = Lanes::<1, E>::new(&[net])?;
            self.run_lanes(&mut lanes, [sensing.input.as_slice()], |lanes| {
                outputs.push((0..n).map(|i| lanes.output(i)[0].to_f64()).collect());
            })
        })
        .map_err(|d| d.error(|_| 0))?;
        Ok(Record {
            sensing,
            outputs,
            classification: f[0],
        })
    }

    /// Judges `net` on `per_landmark` fresh trials per landmark ([`fresh_trials`](Self::fresh_trials)),
    /// robot-like or not: it succeeds when at least [`SUCCESS_RATE`] of them are classified right.
    pub fn assess(
        &self,
        net: &Network,
        per_landmark: usize,
        seed: u64,
        robot_like: bool,
    ) -> Result<Assessment> {
        self.assess_cancellable(net, per_landmark, seed, robot_like, None)
    }

    /// [`assess`](Self::assess) that stops with [`Error::Interrupted`] soon after `cancel` is set.
    pub fn assess_cancellable(
        &self,
        net: &Network,
        per_landmark: usize,
        seed: u64,
        robot_like: bool,
        cancel: Option<&AtomicBool>,
    ) -> Result<Assessment> {
        if per_landmark == 0 {
            return Err(Error::InvalidArgument(
                "trials per landmark is 0; assessing needs at least 1".into(),
            ));
        }
        let trials = self.sensed(Purpose::Evaluate, per_landmark, seed, robot_like, cancel)?;
        let outputs = self.outputs_by_pair(std::slice::from_ref(net), &trials, cancel)?;
        let mut confusion = [[0usize; 2]; 2];
        let mut list = vec![];
        for (s, &f) in trials.iter().zip(&outputs[0]) {
            confusion[usize::from(s.landmark - 1)][usize::from(answer(f) - 1)] += 1;
            list.push((s.landmark, f));
        }
        let rate = (confusion[0][0] + confusion[1][1]) as f64 / trials.len() as f64;
        Ok(Assessment {
            robot_like,
            confusion,
            trials: list,
            rate,
            required: SUCCESS_RATE,
            success: rate >= SUCCESS_RATE,
        })
    }

    fn check(&self, networks: &[Network]) -> Result<()> {
        check_inputs(networks, 1, "the left sonar")?;
        let c = self.config.classifier;
        if let Some(p) = networks.iter().position(|net| net.size() <= c) {
            return Err(Error::InvalidArgument(format!(
                "network {p} has N = {}; the classifier is neuron {c}, so N must be at least {}",
                networks[p].size(),
                c + 1
            )));
        }
        Ok(())
    }
}

impl Task for LandmarkTask {
    fn layout(&self) -> Layout {
        Layout {
            size: self.config.size,
            n_inputs: 1,
        }
    }

    /// The fitness of [`LandmarkTask::scores`].
    fn evaluate(
        &self,
        networks: &[Network],
        generation: u64,
        seed: u64,
        cancel: Option<&AtomicBool>,
    ) -> Result<Vec<f64>> {
        self.scores(networks, generation, seed, cancel)
    }

    /// [`LandmarkTask::assess`] with [`SUCCESS_TRIALS`] trials per landmark, in the training
    /// conditions.
    fn succeeds(&self, net: &Network, seed: u64) -> Result<Option<bool>> {
        let robot_like = self.config.train_robot_like;
        Ok(Some(
            self.assess(net, SUCCESS_TRIALS, seed, robot_like)?.success,
        ))
    }

    /// Each network on `validation_trials` trials per landmark in the training conditions
    /// without `training`'s variations (the ideal world, or robot-like with `train_robot_like`),
    /// drawn as in [`fresh_trials`](LandmarkTask::fresh_trials) from [`Purpose::Validate`]; when
    /// `training` varies, on as many varied trials per landmark besides (`training.rs`). Gives
    /// the fraction classified right and the mean trial score. The trials are sensed once per
    /// seed.
    fn validate(
        &self,
        networks: &[Network],
        seed: u64,
        cancel: Option<&AtomicBool>,
    ) -> Result<Option<Vec<Validation>>> {
        let c = &self.config;
        let trials = self.validation_set.get_or_try(&seed, || {
            self.varied_validation_trials(seed).unwrap_or_else(|| {
                self.trials_from(
                    Purpose::Validate,
                    c.validation_trials,
                    seed,
                    c.train_robot_like,
                )
            })
        })?;
        let outputs = self.outputs_by_pair(networks, &trials, cancel)?;
        let n = trials.len() as f64;
        Ok(Some(
            outputs
                .iter()
                .map(|f| {
                    let right = trials
                        .iter()
                        .zip(f)
                        .filter(|(s, &o)| answer(o) == s.landmark)
                        .count();
                    let total: f64 = trials
                        .iter()
                        .zip(f)
                        .map(|(s, &o)| score(s.landmark, o))
                        .sum();
                    Validation {
                        rate: right as f64 / n,
                        score: total / n,
                    }
                })
                .collect(),
        ))
    }
}
