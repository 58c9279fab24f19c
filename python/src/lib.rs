//! `agrisim._agrisim`: the engine and the benchmarks for Python. The Python package around it
//! (python/pkg/agrisim) adds numpy views of messages, gymnasium environments and Ray trials.
//!
//! Every engine error becomes `agrisim.AgrisimError` with the engine's message (which names
//! the file, FMU, variable, topic or message); nothing panics into the interpreter.

mod bench;
mod convert;
mod kinematics;
mod node;
mod paths;
mod simulation;
mod task;

use pyo3::prelude::*;

pyo3::create_exception!(
    agrisim,
    AgrisimError,
    pyo3::exceptions::PyRuntimeError,
    "An error from the agrisim engine; the message names what was wrong."
);

/// An engine error as the Python exception.
pub(crate) fn py_err(e: impl std::fmt::Display) -> PyErr {
    AgrisimError::new_err(e.to_string())
}

/// Lets engine state (FMU instances, sessions: not `Send`) cross into `Python::detach`, which
/// wants `Send`: the closure runs synchronously on this very thread while the interpreter
/// lock is released, and touches no Python object.
pub(crate) struct OnThisThread<T>(pub T);
// SAFETY: `Python::detach` runs its closure on the calling thread before returning; the
// value never reaches another thread.
unsafe impl<T> Send for OnThisThread<T> {}
impl<T> OnThisThread<T> {
    pub fn get(&mut self) -> &mut T {
        &mut self.0
    }
}

#[pymodule]
fn _agrisim(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("AgrisimError", m.py().get_type::<AgrisimError>())?;
    m.add_class::<simulation::Simulation>()?;
    m.add_class::<simulation::Snapshot>()?;
    m.add_class::<task::NavTask>()?;
    m.add_class::<kinematics::ArmModel>()?;
    m.add_class::<node::Node>()?;
    m.add_function(wrap_pyfunction!(convert::decode, m)?)?;
    m.add_function(wrap_pyfunction!(convert::encode, m)?)?;
    m.add_function(wrap_pyfunction!(convert::message_types, m)?)?;
    m.add_function(wrap_pyfunction!(paths::root, m)?)?;
    m.add_function(wrap_pyfunction!(paths::scenario_path, m)?)?;
    m.add_function(wrap_pyfunction!(bench::benchmarks, m)?)?;
    m.add_function(wrap_pyfunction!(bench::bench_run, m)?)?;
    m.add_function(wrap_pyfunction!(bench::run_trial, m)?)?;
    // Not in `__all__` (which `add` extends): the package re-exports it by name.
    m.setattr("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
