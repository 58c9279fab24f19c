//! The co-simulation call-sequence state machine shared by the FMI 3.0 and FMI 2.0 layers.
//!
//! Every API function declares the set of modes it may be called in (a [`Mask`]); the entry
//! guard checks the instance's [`Mode`] against it before anything else runs (the
//! Reference-FMUs pattern). Which variables may be *set* in which mode is [`settable`].
//!
//! Policy: every call that returns `Error` puts the instance into [`Mode::Error`]; the FMI
//! standards say the simulation must not continue after an error, so the only ways out are a
//! restored FMU state, `Reset` or `FreeInstance`. `Fatal` is terminal (only `FreeInstance`).

use crate::var::{Causality, Var, Variability};

/// Return status of every FMI function. Values 0..=4 coincide for `fmi3Status` and
/// `fmi2Status` (FMI 2's `fmi2Pending` = 5 is never returned: steps are synchronous).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Status {
    Ok = 0,
    Warning = 1,
    Discard = 2,
    Error = 3,
    Fatal = 4,
}

/// Instance modes of the state machine (FMI 3 names; FMI 2's "slaveInitialized"/"stepComplete"
/// is `StepMode`). Co-simulation instances use `StepMode`, model-exchange instances
/// `EventMode` and `ContinuousTimeMode`; the two sets never mix, so one mask per function
/// serves both. Configuration and intermediate update modes are not supported, so they do
/// not exist here. New modes go at the end: serialized FMU states store the variant index.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Mode {
    Instantiated,
    InitializationMode,
    StepMode,
    Terminated,
    /// After any call returned `Error`.
    Error,
    /// After an unrecoverable failure (a panic while rebuilding the model in `Reset`).
    Fatal,
    /// Model exchange: discrete states are updated at a fixed time.
    EventMode,
    /// Model exchange: the importer integrates the continuous states.
    ContinuousTimeMode,
}

/// A set of modes, one bit per [`Mode`].
pub type Mask = u8;

pub const INSTANTIATED: Mask = 1 << 0;
pub const INITIALIZATION: Mask = 1 << 1;
pub const STEP: Mask = 1 << 2;
pub const TERMINATED: Mask = 1 << 3;
pub const ERROR: Mask = 1 << 4;
pub const FATAL: Mask = 1 << 5;
pub const EVENT: Mask = 1 << 6;
pub const CONTINUOUS_TIME: Mask = 1 << 7;
/// No mode: the function is not supported and always fails.
pub const NEVER: Mask = 0;
/// Every mode in which the instance is usable.
pub const LIVE: Mask = INSTANTIATED | INITIALIZATION | STEP | TERMINATED | EVENT | CONTINUOUS_TIME;
/// The modes after initialization in which the model runs (step, event, continuous time).
pub const RUNNING: Mask = STEP | EVENT | CONTINUOUS_TIME;

impl Mode {
    pub const fn bit(self) -> Mask {
        match self {
            Mode::Instantiated => INSTANTIATED,
            Mode::InitializationMode => INITIALIZATION,
            Mode::StepMode => STEP,
            Mode::Terminated => TERMINATED,
            Mode::Error => ERROR,
            Mode::Fatal => FATAL,
            Mode::EventMode => EVENT,
            Mode::ContinuousTimeMode => CONTINUOUS_TIME,
        }
    }
    pub const fn name(self) -> &'static str {
        match self {
            Mode::Instantiated => "Instantiated",
            Mode::InitializationMode => "Initialization Mode",
            Mode::StepMode => "Step Mode",
            Mode::Terminated => "Terminated",
            Mode::Error => {
                "Error (after a call returned Error; only Reset, FreeInstance or restoring an FMU state help)"
            }
            Mode::Fatal => "Fatal",
            Mode::EventMode => "Event Mode",
            Mode::ContinuousTimeMode => "Continuous-Time Mode",
        }
    }
}

/// Human-readable list of the modes in `mask`, for log messages.
pub fn mask_names(mask: Mask) -> String {
    let all = [
        Mode::Instantiated,
        Mode::InitializationMode,
        Mode::StepMode,
        Mode::EventMode,
        Mode::ContinuousTimeMode,
        Mode::Terminated,
        Mode::Error,
        Mode::Fatal,
    ];
    let names: Vec<&str> = all
        .iter()
        .filter(|m| mask & m.bit() != 0)
        .map(|m| match m {
            Mode::Error => "Error",
            other => other.name(),
        })
        .collect();
    if names.is_empty() {
        "none (not supported by this FMU)".to_string()
    } else {
        names.join(", ")
    }
}

/// Allowed-call masks of the FMI 3.0 functions this layer implements (co-simulation, and
/// model exchange for models with continuous states: FMI 3.0 section 3.2).
pub mod fmi3 {
    use super::*;
    pub const SET_DEBUG_LOGGING: Mask = LIVE | ERROR;
    pub const ENTER_INITIALIZATION_MODE: Mask = INSTANTIATED;
    pub const EXIT_INITIALIZATION_MODE: Mask = INITIALIZATION;
    pub const TERMINATE: Mask = RUNNING;
    pub const RESET: Mask = LIVE | ERROR;
    pub const GET: Mask = INITIALIZATION | RUNNING | TERMINATED;
    pub const SET: Mask = INSTANTIATED | INITIALIZATION | RUNNING;
    pub const GET_FMU_STATE: Mask = LIVE;
    pub const SET_FMU_STATE: Mask = LIVE | ERROR;
    pub const FREE_FMU_STATE: Mask = LIVE | ERROR;
    pub const SERIALIZE_FMU_STATE: Mask = LIVE | ERROR;
    pub const DESERIALIZE_FMU_STATE: Mask = LIVE | ERROR;
    pub const DO_STEP: Mask = STEP;
    // Model exchange.
    pub const ENTER_EVENT_MODE: Mask = CONTINUOUS_TIME;
    pub const UPDATE_DISCRETE_STATES: Mask = EVENT;
    pub const ENTER_CONTINUOUS_TIME_MODE: Mask = EVENT;
    pub const COMPLETED_INTEGRATOR_STEP: Mask = CONTINUOUS_TIME;
    pub const SET_TIME: Mask = EVENT | CONTINUOUS_TIME;
    pub const SET_CONTINUOUS_STATES: Mask = CONTINUOUS_TIME;
    pub const GET_CONTINUOUS: Mask = INITIALIZATION | EVENT | CONTINUOUS_TIME | TERMINATED;
    pub const GET_NOMINALS: Mask = INSTANTIATED | GET_CONTINUOUS;
    pub const GET_NUMBER_OF: Mask = LIVE;
}

/// Allowed-call masks of the FMI 2.0 functions (FMI 2.0.4, sections 3.2.3 and 4.2.4).
/// FMI 2 explicitly allows getters (for debugging) and FMU-state calls in the error state.
pub mod fmi2 {
    use super::*;
    pub const SET_DEBUG_LOGGING: Mask = LIVE | ERROR;
    pub const SETUP_EXPERIMENT: Mask = INSTANTIATED;
    pub const ENTER_INITIALIZATION_MODE: Mask = INSTANTIATED;
    pub const EXIT_INITIALIZATION_MODE: Mask = INITIALIZATION;
    pub const TERMINATE: Mask = RUNNING;
    pub const RESET: Mask = LIVE | ERROR;
    pub const GET: Mask = INITIALIZATION | RUNNING | TERMINATED | ERROR;
    pub const SET: Mask = INSTANTIATED | INITIALIZATION | RUNNING;
    pub const GET_FMU_STATE: Mask = LIVE | ERROR;
    pub const SET_FMU_STATE: Mask = LIVE | ERROR;
    pub const FREE_FMU_STATE: Mask = LIVE | ERROR;
    pub const SERIALIZE_FMU_STATE: Mask = LIVE | ERROR;
    pub const DESERIALIZE_FMU_STATE: Mask = LIVE | ERROR;
    pub const DO_STEP: Mask = STEP;
    pub const GET_STATUS: Mask = STEP | TERMINATED | ERROR;
    // Model exchange.
    pub const ENTER_EVENT_MODE: Mask = EVENT | CONTINUOUS_TIME;
    pub const NEW_DISCRETE_STATES: Mask = EVENT;
    pub const ENTER_CONTINUOUS_TIME_MODE: Mask = EVENT;
    pub const COMPLETED_INTEGRATOR_STEP: Mask = CONTINUOUS_TIME;
    pub const SET_TIME: Mask = EVENT | CONTINUOUS_TIME;
    pub const SET_CONTINUOUS_STATES: Mask = CONTINUOUS_TIME;
    pub const GET_CONTINUOUS: Mask = INITIALIZATION | EVENT | CONTINUOUS_TIME | TERMINATED | ERROR;
    pub const GET_NOMINALS: Mask = INSTANTIATED | GET_CONTINUOUS;
}

/// Whether `var` may be set in `mode`.
///
/// Before initialization ends: parameters and inputs (everything with a start value that is
/// not a constant). In Step Mode and Event Mode: inputs and tunable parameters only; in
/// Continuous-Time Mode: continuous inputs only. Outputs, calculated parameters and locals
/// are computed by the model and never set from outside (continuous states change through
/// SetContinuousStates).
pub fn settable(var: &Var, mode: Mode) -> Result<(), &'static str> {
    match var.causality {
        Causality::Output => return Err("it is an output (computed by the model)"),
        Causality::CalculatedParameter => return Err("it is a calculated parameter (computed by the model)"),
        Causality::Local => return Err("it is a local variable (internal to the model)"),
        Causality::Parameter | Causality::Input => {}
    }
    if var.variability == Variability::Constant {
        return Err("it is a constant");
    }
    match mode {
        Mode::Instantiated | Mode::InitializationMode => Ok(()),
        Mode::StepMode | Mode::EventMode => match (var.causality, var.variability) {
            (Causality::Input, _) => Ok(()),
            (Causality::Parameter, Variability::Tunable) => Ok(()),
            _ => Err("it is a fixed parameter and initialization has ended"),
        },
        Mode::ContinuousTimeMode => match (var.causality, var.variability) {
            (Causality::Input, Variability::Continuous) => Ok(()),
            _ => Err("in Continuous-Time Mode only continuous inputs can be set"),
        },
        _ => Err("variables cannot be set in this mode"),
    }
}
