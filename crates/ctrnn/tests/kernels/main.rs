//! ctrnn's tests that compile SIMD kernels of their own: the vector backends against plain `f64`,
//! and the integrator at a width no crate uses and with the tests' own closures.
//!
//! Each of them instantiates the kernel again for every backend, in the test crate: they were
//! half of tests/unit's code. As a binary of their own, they compile beside tests/unit on a
//! second core instead of after it.

mod lanes;
mod vector;
