//! The Python binding of dnnevo, built by maturin as `dnnevo._core`.
//!
//! This is the only crate that knows Python. It converts arguments, maps errors to the exception
//! tree of `dnnevo.errors`, and runs long calls with the GIL released (see `detach.rs`).

mod analysis;
mod arrays;
mod batch;
mod detach;
mod dynamics;
mod errors;
mod evolution;
mod json;
mod landmark;
mod layout;
mod nav1d;
mod network;
mod population;
mod pyjson;
mod records;
mod robots;
mod run_config;
mod sequence;
mod simd;
mod streams;

use pyo3::prelude::*;

/// The extension's own Rust allocations (Python's are untouched) go to mimalloc. It keeps freed
/// memory for reuse, where glibc returns it to the OS between calls: packing a population of
/// large networks then page-faulted every fresh page again on every call (3-5x the packing time).
/// `local_dynamic_tls` makes it safe in a library that Python loads with `dlopen`.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// The native core of dnnevo.
#[pymodule]
mod _core {
    #[pymodule_export]
    use super::analysis::{analysis_bifurcation, analysis_cycles, analysis_equilibria};
    #[pymodule_export]
    use super::batch::PyBatch;
    #[pymodule_export]
    use super::dynamics::{
        PyBifurcation, PyCycle, PyCycleBranch, PyCycleEnd, PyEquilibrium, PyEvent,
    };
    #[pymodule_export]
    use super::evolution::process_threads;
    #[pymodule_export]
    use super::evolution::{evaluate, task_names, PyEvolution};
    #[pymodule_export]
    use super::landmark::{
        sim2d_cast_rays, sim2d_landmark_world, PyLandmarkRecord, PyLandmarkTask,
    };
    #[pymodule_export]
    use super::nav1d::{
        nav1d_system_assess, nav1d_system_record, PyNav1dCondition, PyNav1dRecord, PyNav1dTask,
    };
    #[pymodule_export]
    use super::network::{compose, PyNetwork, PyTrace};
    #[pymodule_export]
    use super::population::run_population;
    #[pymodule_export]
    use super::robots::PyFleet;
    #[pymodule_export]
    use super::run_config::PyRunConfig;
    #[pymodule_export]
    use super::sequence::{PySequenceRecord, PySequenceTask};
    #[pymodule_export]
    use super::simd::{apply_simd_env, build_info, use_kernel};
    #[pymodule_export]
    use super::streams::condition_seed;

    use pyo3::prelude::*;

    #[pymodule_init]
    fn init(m: &Bound<'_, PyModule>) -> PyResult<()> {
        m.add("__version__", env!("CARGO_PKG_VERSION"))?;
        m.add("LANES", ctrnn::LANES)?;
        m.add("MAX_COUNT", tasks::MAX_COUNT)?;
        m.add("MUTATION_SCALE", ctrnn::ga::MUTATION_SCALE)?;
        m.add("STEP_CHECK_FINER", ctrnn::validation::STEP_CHECK_FINER)?;
        // Python's config classes take their defaults from these, so the two cannot drift.
        let defaults = serde_json::to_string(&tasks::RunConfig::default());
        m.add("RUN_DEFAULTS", defaults.expect("defaults always serialise"))?;
        m.add("RETRY_STARTS", ctrnn::analysis::RETRY_STARTS)?;
        m.add("STABILITIES", super::dynamics::stabilities())?;
        // Each task's success rule, so that Python judges by the core's numbers, never copies.
        m.add(
            "SEQUENCE_SUCCESS_FRACTION",
            tasks::sequence::SUCCESS_FRACTION,
        )?;
        m.add("NAV1D_SUCCESS_RATE", tasks::nav1d::SUCCESS_RATE)?;
        m.add("LANDMARK_SUCCESS_RATE", tasks::landmark::SUCCESS_RATE)?;
        Ok(())
    }
}
