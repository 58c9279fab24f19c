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

/// A continuous state of a model-exchange model: which variables hold it and its derivative.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContinuousState {
    /// Index in the variable table of the state (a continuous Float64 output or local).
    pub state: usize,
    /// Index of its time derivative (a continuous Float64 local or output, computed by
    /// [`Model::evaluate`]).
    pub derivative: usize,
    /// Its typical magnitude (GetNominalsOfContinuousStates), for the importer's error control.
    pub nominal: f64,
}

/// A model, exported as a co-simulation FMU or, when it declares
/// [`CONTINUOUS_STATES`](Model::CONTINUOUS_STATES), as a model-exchange FMU. Implementors are
/// plain Rust; see `export_fmu!` for the C API.
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

    // ---- Model exchange (optional) ------------------------------------------------------
    //
    // A model opts in by listing its continuous states. It is then exported as a
    // model-exchange FMU *only*: no <CoSimulation> element, fmi*InstantiateCoSimulation /
    // fmi2Instantiate(fmi2CoSimulation) refuse. Why not both, with a built-in fixed-step
    // integrator for co-simulation: importers (agrisim's engine among them) pick
    // co-simulation whenever an FMU offers it, so the model-exchange path would go
    // unexercised, and a fixed-step integrator inside the FMU would only duplicate, without
    // error control, what the importer's solver does.
    //
    // The state vector lives in the variable store (the state variables' values), so FMU
    // states, serialization and getters need nothing extra. The layer writes the states on
    // SetContinuousStates and calls `evaluate` before anything reads derived values.
    // Event indicators (state events) are not supported: numberOfEventIndicators is 0. Time
    // events are: see `next_event_time`.

    /// The continuous states, in state-vector order; empty (the default): co-simulation.
    const CONTINUOUS_STATES: &'static [ContinuousState] = &[];

    /// Model exchange: computes every derivative variable and every output from the time
    /// `t`, the states and the inputs in `io`. Called after `initialize` and whenever time,
    /// states or inputs changed before a value is read; it must not change the states.
    fn evaluate(&mut self, _io: &mut Store, _t: f64) -> Result<(), ModelError> {
        Err("this model has no continuous states (it is not a model-exchange model)".into())
    }

    /// Model exchange: handles the events due at time `t` in Event Mode (one pass; the
    /// layer never asks for another). Returns whether it changed continuous state values.
    fn update_discrete_states(&mut self, _io: &mut Store, _t: f64, _log: &mut dyn Log) -> Result<bool, ModelError> {
        Ok(false)
    }

    /// Model exchange: the next time event strictly after the events handled at `t`
    /// (announced as nextEventTime when Event Mode ends); `None`: no time event ahead.
    fn next_event_time(&self, _io: &Store, _t: f64) -> Option<f64> {
        None
    }
}

/// Whether `M` is exported as a model-exchange FMU (it declares continuous states).
pub const fn is_model_exchange<M: Model>() -> bool {
    !M::CONTINUOUS_STATES.is_empty()
}
