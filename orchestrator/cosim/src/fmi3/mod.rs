//! FMI 3.0 co-simulation import: load an FMU's shared library and drive instances of it safely.
//!
//! Layering: [`ffi`] is the raw C ABI; [`Fmi3Library`] resolves it from one binary;
//! [`Instance`] is the only safe entry point and turns every non-OK status into an
//! [`FmiError`] that names the instance, model, function, variables and the FMU's own log.

mod error;
pub mod ffi;
mod instance;
mod library;
mod log;
mod status;

pub use error::{FmiError, FmiErrorInfo};
pub use instance::{FmuState, Instance, InstanceState};
pub use library::Fmi3Library;
pub use log::LogMessage;
pub use status::{Status, StepResult};
