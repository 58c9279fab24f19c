//! FMI 2.0 import (co-simulation, and model exchange driven by [`crate::me`]): the same
//! layering as [`crate::fmi3`]: [`ffi`] is the raw C ABI, [`Fmi2Library`] resolves it from
//! one binary, [`Instance`] is the only safe entry point.

pub mod ffi;
mod instance;
mod library;
mod log;

pub use instance::Instance;
pub use library::Fmi2Library;
