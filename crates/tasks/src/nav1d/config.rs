//! The settings of the one-dimensional navigation experiments: the world's geometry and timing,
//! which neurons are motors and classifier, and what an evaluation scores.

use ctrnn::{Error, Integrator, Precision, Result};

use crate::common::TIME_STEP;
use crate::Aggregate;
use serde::{Deserialize, Serialize};

use super::environment::Environment;

/// What an evaluation scores.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Objective {
    /// Goal seeking (the far and near networks, §4.2): one trial per environment and goal side,
    /// each from a reset state; a trial scores 1 when the agent reaches the goal, else 0.
    Goal,
    /// Environment classification (§4.2): one trial per environment and goal side, each from a
    /// reset state; a trial scores `f(v_C)` in a landmark-near environment and `1 - f(v_C)` in a
    /// landmark-far one, read at the end of the trial's reinforcement period.
    Classify,
    /// One network for the whole task (beyond the paper): chains of `trials_per_environment`
    /// trials in one environment without a reset, each trial's goal side drawn at random; the
    /// score is the goal rate over trials 2..k of every chain.
    Single,
}

impl Objective {
    /// The name used in configs: `"goal"`, `"classify"` or `"single"`.
    pub fn name(self) -> &'static str {
        match self {
            Objective::Goal => "goal",
            Objective::Classify => "classify",
            Objective::Single => "single",
        }
    }
}

/// How often the world (the agent's position and what its sensors read) is updated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum World {
    /// At every integration step of the network (default): the paper's `dx/dt = f(v_R) -
    /// f(v_L)` is integrated together with the network, so that a finer `dt` gives the same
    /// behaviour more accurately.
    #[default]
    Continuous,
    /// Once per time step: the sensors are read and held for the time step's `substeps`
    /// integration steps, then the agent moves `dt * substeps * (f(v_R) - f(v_L))` at once. This
    /// was dnnevo's world before the continuous one; a behaviour that needs it is an artefact of
    /// the coarse step.
    Stepped,
}

impl World {
    /// The name used in configs: `"continuous"` or `"stepped"`.
    pub fn name(self) -> &'static str {
        match self {
            World::Continuous => "continuous",
            World::Stepped => "stepped",
        }
    }
}

/// The one-dimensional navigation settings. Every number of the world lives here.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Nav1dConfig {
    /// What an evaluation scores. Default `"goal"`.
    pub objective: Objective,
    /// The environment types evaluations use (`"far"`, `"near"`), without repeats. Default
    /// `["far", "near"]`.
    pub environments: Vec<Environment>,
    /// Neurons per network N. Default 5.
    pub size: usize,
    /// Whether the network has the reinforcement (goal) sensor as input 1, after the landmark
    /// sensor (input 0). The paper's goal-seeking networks have only the landmark sensor; its
    /// classifier has both. Default true.
    pub reinforcement_input: bool,
    /// The left motor neuron. Default 0.
    pub left_motor: usize,
    /// The right motor neuron. Default 1.
    pub right_motor: usize,
    /// The classifier neuron (`f(v_C) >= 0.5` means landmark-near); used by `"classify"` and by
    /// the integrated system. Default 2.
    pub classifier: usize,
    /// The line runs over `[-half_length, half_length]`; its ends are the goal and the wall.
    /// Default 20.
    pub half_length: f64,
    /// Where the agent starts each trial. Default 0 (the centre).
    pub start: f64,
    /// Distance of the landmark's centre from the line's centre. Default 10.
    pub landmark_offset: f64,
    /// Width of the landmark segment; the sensor reads 1 while `|x - centre| <= width / 2`.
    /// Default 4.
    pub landmark_width: f64,
    /// A trial ends after this many time steps if the agent has reached neither end. Default 1000.
    pub max_steps: usize,
    /// Time steps after a trial ends: reinforcement input 1 if the agent reached the goal, no
    /// input otherwise. Default 50.
    pub reinforcement_steps: usize,
    /// With `"goal"`: run each environment's goal-left and goal-right trials as two chains,
    /// left-right and right-left, without a reset in between, so that the network meets a trial
    /// that starts from the state the last one left, as it does in the integrated system. Its
    /// success check then uses chains of `trials_per_environment` trials. Default false (the
    /// paper's trials, each from a reset state).
    pub chained: bool,
    /// Trials per chain with `"single"` (the first trial is for learning, trials 2.. are scored)
    /// and in the success check of a `chained` goal task. Default 5.
    pub trials_per_environment: usize,
    /// Chains per environment type in one `"single"` evaluation. Default 2.
    pub chains_per_environment: usize,
    /// How the environment types' scores make one fitness: `"mean"` over all scored trials
    /// (default), the worst type's mean (`"min"`), or the mean of the two (`"mean-min"`). With
    /// `"min"` a network that solves one type and guesses in the other scores as a guesser.
    pub aggregate: Aggregate,
    /// Implicit fitness sharing (beyond the paper), against a population's collapse onto one
    /// strategy: each scored trial's score is divided by the mean score of every network scored
    /// with it on that trial (a trial nobody scored on counts 0 for all), before `aggregate`
    /// combines them. A network then earns most from the trials few others get right, and a
    /// population of equals scores 1. Fitness so becomes relative to the networks scored
    /// together; the champion's validation and the success rule do not change. Default false.
    pub sharing: bool,
    /// Shaping toward the classifier (beyond the paper), for `"single"` only: each scored trial
    /// scores `(1 - w) * reached + w * c` with `w = classify_weight`, where `c` is the
    /// classifier's output read as `"classify"` reads it (`f(v_C)` in a landmark-near
    /// environment, `1 - f(v_C)` in a landmark-far one) at the end of that trial's reinforcement
    /// period. It rewards a network for holding its environment type through the chain, a
    /// stepping stone the goal alone does not reward. Whether a trial is done right, and so the
    /// rate, the champion's validation and the success rule, still count goals only. In [0, 1];
    /// default 0 (the goal alone).
    pub classify_weight: f64,
    /// Shaping toward the landmark-near default (beyond the paper), for `"single"` only: the
    /// fitness gains `w * k / n` with `w = near_first_weight`, where `k` of the evaluation's `n`
    /// landmark-near chains reach the goal in their first, unscored, trial. A network whose
    /// first trial runs the far seeker's strategy is right in no such trial and gains nothing.
    /// The first trial after a reset is the one trial whose odometer starts from a known state,
    /// and only the near seeker needs an odometer (it turns back where the landmark should have
    /// been); a network that starts near and turns to the far strategy after a trial without
    /// reinforcement can be right in every scored trial. Whether a trial is done right, the
    /// rate, the champion's validation and the success rule do not change. `>= 0`; default 0.
    pub near_first_weight: f64,
    /// Fresh chains (of the success check's length) in a run's validation set, on which the best
    /// candidates of each generation are judged to choose the champion. Default 40.
    pub validation_chains: usize,
    /// Half-width of a uniform random shift of the start position in each trial. Default 0 (the
    /// paper's fixed start).
    pub start_jitter: f64,
    /// Half-width of a uniform random shift of the landmark's centre in each trial. Default 0.
    pub landmark_jitter: f64,
    /// How one time step is integrated: `substeps` steps of `dt` (one time step is `dt *
    /// substeps` units of simulated time). Default 10 Euler steps of dt = 0.1.
    pub integrator: Integrator,
    /// The floating-point type the networks compute in: `"f64"` (default, the reference) or
    /// `"f32"`, opt-in single precision (see [`ctrnn::Precision`]). The world, the inputs and the
    /// scores stay `f64`; each input is rounded to `f32` as the network reads it.
    pub precision: Precision,
    /// How often the agent moves and its sensors are read: `"continuous"` (default) at every
    /// integration step, `"stepped"` once per time step (see [`World`]). Time limits and
    /// reinforcement periods are in time steps either way.
    pub world: World,
}

impl Default for Nav1dConfig {
    fn default() -> Self {
        Nav1dConfig {
            objective: Objective::Goal,
            environments: vec![Environment::Far, Environment::Near],
            size: 5,
            reinforcement_input: true,
            left_motor: 0,
            right_motor: 1,
            classifier: 2,
            half_length: 20.0,
            start: 0.0,
            landmark_offset: 10.0,
            landmark_width: 4.0,
            max_steps: 1000,
            reinforcement_steps: 50,
            chained: false,
            trials_per_environment: 5,
            chains_per_environment: 2,
            aggregate: Aggregate::Mean,
            sharing: false,
            classify_weight: 0.0,
            near_first_weight: 0.0,
            validation_chains: 40,
            start_jitter: 0.0,
            landmark_jitter: 0.0,
            integrator: TIME_STEP,
            precision: Precision::F64,
            world: World::Continuous,
        }
    }
}

impl Nav1dConfig {
    /// Checks every field; the error names the field and says what is allowed.
    ///
    /// # Example
    /// ```
    /// use tasks::nav1d::Nav1dConfig;
    /// let bad = Nav1dConfig { landmark_offset: 25.0, ..Nav1dConfig::default() };
    /// let e = bad.validate().unwrap_err().to_string();
    /// assert!(e.contains("landmark_offset"), "{e}");
    /// ```
    pub fn validate(&self) -> Result<()> {
        let config = |msg: String| Err(Error::Config(msg));
        if self.environments.is_empty() {
            return config("environments is empty; give \"far\", \"near\" or both".into());
        }
        if self.environments.len() == 2 && self.environments[0] == self.environments[1] {
            return config("environments repeats an environment; list each at most once".into());
        }
        for (name, value) in [
            ("size", self.size),
            ("max_steps", self.max_steps),
            ("trials_per_environment", self.trials_per_environment),
            ("chains_per_environment", self.chains_per_environment),
            ("validation_chains", self.validation_chains),
        ] {
            crate::common::check_count(name, value)?;
        }
        let mut neurons = vec![
            ("left_motor", self.left_motor),
            ("right_motor", self.right_motor),
        ];
        if self.objective != Objective::Goal {
            neurons.push(("classifier", self.classifier));
        }
        for (k, &(name, i)) in neurons.iter().enumerate() {
            if i >= self.size {
                return config(format!(
                    "{name} is {i}; it must be a neuron index below size ({})",
                    self.size
                ));
            }
            if let Some((other, _)) = neurons[..k].iter().find(|(_, j)| *j == i) {
                return config(format!(
                    "{name} is {i}, the same neuron as {other}; they must differ"
                ));
            }
        }
        if self.chained && self.objective != Objective::Goal {
            return config("chained is true; it applies to the \"goal\" objective only".into());
        }
        let w = self.classify_weight;
        if !(0.0..=1.0).contains(&w) {
            return config(format!("classify_weight is {w}; it must lie in [0, 1]"));
        }
        if w != 0.0 && self.objective != Objective::Single {
            return config(format!(
                "classify_weight is {w}; it applies to the \"single\" objective only"
            ));
        }
        let w = self.near_first_weight;
        if !(w >= 0.0 && w.is_finite()) {
            return config(format!(
                "near_first_weight is {w}; it must be a finite number >= 0"
            ));
        }
        if w != 0.0 && self.objective != Objective::Single {
            return config(format!(
                "near_first_weight is {w}; it applies to the \"single\" objective only"
            ));
        }
        if self.objective == Objective::Single && self.trials_per_environment < 2 {
            return config(format!(
                "trials_per_environment is {}; \"single\" scores trials 2..k, so it must be >= 2",
                self.trials_per_environment
            ));
        }
        for (name, value) in [
            ("half_length", self.half_length),
            ("start", self.start),
            ("landmark_offset", self.landmark_offset),
            ("landmark_width", self.landmark_width),
            ("start_jitter", self.start_jitter),
            ("landmark_jitter", self.landmark_jitter),
        ] {
            if !value.is_finite() {
                return config(format!("{name} is {value}; it must be finite"));
            }
        }
        let h = self.half_length;
        if h <= 0.0 {
            return config(format!("half_length is {h}; it must be > 0"));
        }
        if self.landmark_width <= 0.0 {
            return config(format!(
                "landmark_width is {}; it must be > 0",
                self.landmark_width
            ));
        }
        if self.start_jitter < 0.0 || self.landmark_jitter < 0.0 {
            return config(format!(
                "start_jitter is {} and landmark_jitter is {}; both must be >= 0",
                self.start_jitter, self.landmark_jitter
            ));
        }
        if self.start.abs() + self.start_jitter >= h {
            return config(format!(
                "start is {} with start_jitter {}; the agent must start strictly inside \
                 (-half_length, half_length) = (-{h}, {h})",
                self.start, self.start_jitter
            ));
        }
        let reach = self.landmark_offset.abs() + self.landmark_jitter + self.landmark_width / 2.0;
        if self.landmark_offset <= 0.0 || reach >= h {
            return config(format!(
                "landmark_offset is {} (width {}, jitter {}); the landmark must lie inside \
                 (0, half_length = {h}) on its side",
                self.landmark_offset, self.landmark_width, self.landmark_jitter
            ));
        }
        self.integrator.validate().map_err(|e| match e {
            Error::InvalidArgument(msg) => Error::Config(format!("integrator: {msg}")),
            other => other,
        })?;
        crate::common::check_trial_steps(
            "max_steps + reinforcement_steps",
            self.max_steps as u128 + self.reinforcement_steps as u128,
            self.integrator.substeps,
        )
    }

    /// Sensors per network: 2 with the reinforcement input, else 1.
    pub fn n_inputs(&self) -> usize {
        if self.reinforcement_input {
            2
        } else {
            1
        }
    }

    /// Simulated time of one time step, `dt * substeps`.
    pub fn step_time(&self) -> f64 {
        self.integrator.dt * self.integrator.substeps as f64
    }

    /// What one update of the world integrates, and how many of them make a time step: one
    /// step of `dt` and `substeps` per time step in the continuous world, one whole time step
    /// in the stepped world.
    pub fn tick(&self) -> (Integrator, usize) {
        match self.world {
            World::Continuous => (
                Integrator {
                    substeps: 1,
                    ..self.integrator
                },
                self.integrator.substeps,
            ),
            World::Stepped => (self.integrator, 1),
        }
    }
}
