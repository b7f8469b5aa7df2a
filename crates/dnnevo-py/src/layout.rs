//! The shape of the networks a built-in task drives, as the task objects report it to Python.

/// (size, n_inputs) of the networks `task` drives.
pub(crate) fn layout(task: &dyn ctrnn::Task) -> (usize, usize) {
    let layout = task.layout();
    (layout.size, layout.n_inputs)
}
