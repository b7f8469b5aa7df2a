//! The step check's task: a built-in task paired with a copy of itself integrated
//! [`STEP_CHECK_FINER`](ctrnn::validation::STEP_CHECK_FINER) times finer, which validates would-be champions a second time
//! ([`ctrnn::GaConfig::champion_step_check`]).
//!
//! Training, success and the run's validation all use the task at the run's step; only
//! [`Task::validate_finer`] uses the finer copy, on the same validation set (the same seed, so
//! the same conditions).
//!
//! # Example
//! ```
//! let config = tasks::RunConfig::from_json(
//!     r#"{"task": "sequence", "champion_step_check": true, "task_params": {"targets": ["0"]}}"#,
//! )?;
//! let task = config.build_task()?;
//! let net = ctrnn::Network::new(vec![1.0; 5], vec![0.0; 5], vec![0.0; 25], vec![0.0; 10], None)?;
//! assert!(task.validate_finer(&[net], 0, None)?.is_some());
//! # Ok::<(), ctrnn::Error>(())
//! ```

use std::sync::atomic::AtomicBool;

use ctrnn::{Layout, Network, Result, Task, Validation};

/// A task at the run's step (`run`) with its finer copy (`finer`).
pub struct StepChecked {
    run: Box<dyn Task>,
    finer: Box<dyn Task>,
}

impl StepChecked {
    /// Pairs `run` with `finer`, the same task built with its integrator made
    /// [`STEP_CHECK_FINER`](ctrnn::validation::STEP_CHECK_FINER) times finer.
    pub fn new(run: Box<dyn Task>, finer: Box<dyn Task>) -> Self {
        StepChecked { run, finer }
    }
}

impl Task for StepChecked {
    fn layout(&self) -> Layout {
        self.run.layout()
    }

    fn evaluate(
        &self,
        networks: &[Network],
        generation: u64,
        seed: u64,
        cancel: Option<&AtomicBool>,
    ) -> Result<Vec<f64>> {
        self.run.evaluate(networks, generation, seed, cancel)
    }

    fn succeeds(&self, net: &Network, seed: u64) -> Result<Option<bool>> {
        self.run.succeeds(net, seed)
    }

    fn validate(
        &self,
        networks: &[Network],
        seed: u64,
        cancel: Option<&AtomicBool>,
    ) -> Result<Option<Vec<Validation>>> {
        self.run.validate(networks, seed, cancel)
    }

    fn validate_finer(
        &self,
        networks: &[Network],
        seed: u64,
        cancel: Option<&AtomicBool>,
    ) -> Result<Option<Vec<Validation>>> {
        self.finer.validate(networks, seed, cancel)
    }
}
