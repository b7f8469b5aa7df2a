//! The vector kernel in use, and how to see and force it from Python.

use pyo3::prelude::*;
use pyo3::types::PyDict;

use ctrnn::simd::{self, Kernel};

use crate::errors::IntoPy;

/// What this build of dnnevo is and runs on: its version, the CPU's architecture and the features
/// the kernels look for, the kernels this CPU can run, and the one in use.
#[pyfunction]
pub fn build_info(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let info = PyDict::new(py);
    info.set_item("version", env!("CARGO_PKG_VERSION"))?;
    info.set_item("commit", env!("DNNEVO_GIT_COMMIT"))?;
    info.set_item("arch", std::env::consts::ARCH)?;
    let features = PyDict::new(py);
    for (name, found) in simd::cpu_features() {
        features.set_item(name, found)?;
    }
    info.set_item("cpu_features", features)?;
    let kernels: Vec<&str> = simd::supported().into_iter().map(Kernel::name).collect();
    info.set_item("kernels", kernels)?;
    info.set_item("kernel", simd::kernel().name())?;
    info.set_item("lanes", ctrnn::LANES)?;
    Ok(info)
}

/// Makes every later integration use the kernel `name` ("avx512", "avx2", "neon" or
/// "portable"). The results do not change, only the speed. Raises `InvalidArgumentError` for an
/// unknown name or a kernel this CPU cannot run.
#[pyfunction]
pub fn use_kernel(name: &str) -> PyResult<()> {
    simd::set_kernel(name.parse::<Kernel>().py_err()?).py_err()
}

/// Applies `DNNEVO_SIMD` if it is set; raises `InvalidArgumentError` naming the variable if its
/// value is unknown or the CPU cannot run that kernel.
#[pyfunction]
pub fn apply_simd_env() -> PyResult<()> {
    if let Some(kernel) = simd::from_env().py_err()? {
        simd::set_kernel(kernel).py_err()?;
    }
    Ok(())
}
