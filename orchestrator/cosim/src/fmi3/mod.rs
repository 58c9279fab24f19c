//! FMI 3.0 co-simulation import: load an FMU's shared library and drive instances of it safely.
//!
//! Layering: [`ffi`] is the raw C ABI; [`Fmi3Library`] resolves it from one binary;
//! [`Instance`] is the only safe entry point and turns every non-OK status into an
//! [`FmiError`] that names the instance, model, function, variables and the FMU's own log.

pub mod ffi;
mod instance;
mod library;

pub use crate::fmu::{FmiError, FmiErrorInfo, LogMessage, Status, StepResult};
pub use crate::fmu::{FmuState, InstanceState};
pub use instance::Instance;
pub use library::Fmi3Library;
