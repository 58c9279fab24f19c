//! The one trait a model implements.
//!
//! A model is only physics: it reads its parameters and inputs from a [`Store`], writes its
//! outputs back, and keeps whatever internal state it needs in `Self`. Everything FMI-specific
//! (the C API, the call-sequence state machine, modelDescription.xml) lives in the export
//! layer and is driven by the same [`Var`] table (declared in `var`), so the XML can
//! never drift from the code.

use crate::store::Store;
use crate::token;
use crate::var::Var;

/// What a model returns when it cannot go on; the export layer logs it and returns an error status.
pub type ModelError = String;

/// Log sink handed to a model; messages reach the importer's logger callback. Pass
/// `format_args!(..)`: a message is formatted only if it is going to be delivered (debug
/// messages only while the importer enabled category logModel).
pub trait Log {
    fn info(&mut self, message: std::fmt::Arguments<'_>);
    fn warning(&mut self, message: std::fmt::Arguments<'_>);
}

/// A [`Log`] that drops every message, for driving a model directly (tests, tools).
pub struct Quiet;

impl Log for Quiet {
    fn info(&mut self, _: std::fmt::Arguments<'_>) {}
    fn warning(&mut self, _: std::fmt::Arguments<'_>) {}
}

/// A co-simulation model. Implementors are plain Rust; see `export_fmu!` for the C API.
pub trait Model: Clone + Send + 'static {
    /// modelIdentifier: the FMU's shared-library name and its model name.
    const NAME: &'static str;
    const DESCRIPTION: &'static str;
    /// Variable table, in value-reference order (vr = index + 1).
    const VARIABLES: &'static [Var];
    /// FMI 3 instantiationToken, checked at instantiation: a hash of the interface
    /// ([`token`](crate::token)). Derived; do not override.
    const TOKEN: &'static str = token::as_str(&Self::TOKEN_BYTES);
    /// FMI 2 guid: the same hash over the FMI 2 interface. Derived; do not override.
    const GUID: &'static str = token::as_str(&Self::GUID_BYTES);
    #[doc(hidden)]
    const TOKEN_BYTES: [u8; token::LEN] = token::guid(token::hash("3.0", Self::NAME, Self::VARIABLES));
    #[doc(hidden)]
    const GUID_BYTES: [u8; token::LEN] = token::guid(token::hash("2.0", Self::NAME, Self::VARIABLES));
    /// Default experiment step size [s].
    const STEP_SIZE: f64 = 0.02;

    /// A model in its initial state (before parameters are applied).
    fn new() -> Self;

    /// Called when initialization ends: parameters and inputs are final for t = `start_time`.
    /// Set every output consistent with them.
    fn initialize(&mut self, io: &mut Store, start_time: f64, log: &mut dyn Log) -> Result<(), ModelError>;

    /// Advance from `t` to `t + h` with the inputs in `io`; write outputs for `t + h`.
    fn do_step(&mut self, io: &mut Store, t: f64, h: f64, log: &mut dyn Log) -> Result<(), ModelError>;

    /// Appends what changes over a run to `out` (a serialized FMU state; see [`serial`](crate::serial)).
    /// Leave out what `initialize` derives from the parameters alone: it is rebuilt.
    fn save_state(&self, out: &mut Vec<u8>) -> Result<(), ModelError>;

    /// Overwrites what [`save_state`](Model::save_state) wrote. Called on a model initialized
    /// with the same parameter values, so derived parts are already in place.
    fn load_state(&mut self, bytes: &[u8]) -> Result<(), ModelError>;
}
