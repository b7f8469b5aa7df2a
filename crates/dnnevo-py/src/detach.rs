//! Runs long computations with the GIL released, and lets Ctrl-C stop them.
//!
//! The work runs on a scoped worker thread while the calling thread, which is Python's main thread
//! in the usual case, waits with the GIL released and looks at pending signals every
//! [`SIGNAL_POLL`]. On Ctrl-C it raises the cancel flag that the work checks between steps, waits
//! for the work to stop, and re-raises `KeyboardInterrupt`. Short calls skip the thread.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::Duration;

use pyo3::prelude::*;

use crate::errors::to_py;

/// How often the waiting thread looks for Ctrl-C.
const SIGNAL_POLL: Duration = Duration::from_millis(50);
/// Work estimated below this many neuron-steps runs inline: it ends before a signal could matter.
const INLINE_WORK: f64 = 2e6;

/// Runs `work` without the GIL. `cost` is a rough size (for example P * T * N * substeps).
pub fn detached<T, F>(py: Python<'_>, cost: f64, work: F) -> PyResult<T>
where
    T: Send,
    F: FnOnce(&AtomicBool) -> ctrnn::Result<T> + Send,
{
    let cancel = AtomicBool::new(false);
    if cost < INLINE_WORK {
        return py.detach(|| work(&cancel)).map_err(to_py);
    }
    let mut interrupt: Option<PyErr> = None;
    let result = py.detach(|| {
        std::thread::scope(|scope| {
            let (done_tx, done_rx) = mpsc::channel::<()>();
            let cancel = &cancel;
            let handle = scope.spawn(move || {
                let r = work(cancel);
                let _ = done_tx.send(());
                r
            });
            while let Err(mpsc::RecvTimeoutError::Timeout) = done_rx.recv_timeout(SIGNAL_POLL) {
                if interrupt.is_none() {
                    if let Err(e) = Python::attach(|py| py.check_signals()) {
                        interrupt = Some(e);
                        cancel.store(true, Ordering::Relaxed);
                    }
                }
            }
            handle.join()
        })
    });
    match (interrupt, result) {
        (Some(e), _) => Err(e),
        (None, Ok(r)) => r.map_err(to_py),
        (None, Err(panic)) => std::panic::resume_unwind(panic),
    }
}
