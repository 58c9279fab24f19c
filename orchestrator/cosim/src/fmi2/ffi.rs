//! The FMI 2.0 C ABI as Rust function-pointer types (from the standard's fmi2FunctionTypes.h).
//!
//! `fmi2Boolean` is C `int`, `fmi2Status` and `fmi2Type` are C enums (`c_int`),
//! `fmi2ValueReference` is `unsigned int`. The logger callback is variadic C, so it lives in
//! `logger.c` (formatted there, then handed to the instance's log sink).

use std::ffi::{c_char, c_int, c_uint, c_void};

pub type Fmi2Component = *mut c_void;
pub type Fmi2FmuState = *mut c_void;
pub type Fmi2Status = c_int;
pub type Fmi2Boolean = c_int;
pub type Vr = c_uint;

/// `fmi2Type`.
pub const MODEL_EXCHANGE: c_int = 0;
pub const CO_SIMULATION: c_int = 1;

/// `fmi2CallbackLogger`: `(componentEnvironment, instanceName, status, category, message, ...)`.
pub type Logger = unsafe extern "C" fn(*mut c_void, *const c_char, Fmi2Status, *const c_char, *const c_char, ...);

/// `fmi2CallbackFunctions`. The FMU keeps the pointer: it must outlive the instance.
#[repr(C)]
pub struct CallbackFunctions {
    pub logger: Option<Logger>,
    pub allocate_memory: Option<unsafe extern "C" fn(nobj: usize, size: usize) -> *mut c_void>,
    pub free_memory: Option<unsafe extern "C" fn(obj: *mut c_void)>,
    pub step_finished: Option<unsafe extern "C" fn(env: *mut c_void, status: Fmi2Status)>,
    pub component_environment: *mut c_void,
}

/// `fmi2EventInfo`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct EventInfo {
    pub new_discrete_states_needed: Fmi2Boolean,
    pub terminate_simulation: Fmi2Boolean,
    pub nominals_of_continuous_states_changed: Fmi2Boolean,
    pub values_of_continuous_states_changed: Fmi2Boolean,
    pub next_event_time_defined: Fmi2Boolean,
    pub next_event_time: f64,
}

pub type GetString = unsafe extern "C" fn() -> *const c_char;
pub type Instantiate = unsafe extern "C" fn(
    instance_name: *const c_char,
    fmu_type: c_int,
    guid: *const c_char,
    resource_location: *const c_char,
    functions: *const CallbackFunctions,
    visible: Fmi2Boolean,
    logging_on: Fmi2Boolean,
) -> Fmi2Component;
pub type FreeInstance = unsafe extern "C" fn(c: Fmi2Component);
pub type SetDebugLogging = unsafe extern "C" fn(
    c: Fmi2Component,
    logging_on: Fmi2Boolean,
    n_categories: usize,
    categories: *const *const c_char,
) -> Fmi2Status;
pub type SetupExperiment = unsafe extern "C" fn(
    c: Fmi2Component,
    tolerance_defined: Fmi2Boolean,
    tolerance: f64,
    start_time: f64,
    stop_time_defined: Fmi2Boolean,
    stop_time: f64,
) -> Fmi2Status;
/// EnterInitializationMode, ExitInitializationMode, Terminate, Reset, EnterEventMode,
/// EnterContinuousTimeMode.
pub type ComponentOnly = unsafe extern "C" fn(c: Fmi2Component) -> Fmi2Status;
pub type Getter<T> = unsafe extern "C" fn(c: Fmi2Component, vr: *const Vr, nvr: usize, value: *mut T) -> Fmi2Status;
pub type Setter<T> = unsafe extern "C" fn(c: Fmi2Component, vr: *const Vr, nvr: usize, value: *const T) -> Fmi2Status;
pub type GetFmuState = unsafe extern "C" fn(c: Fmi2Component, state: *mut Fmi2FmuState) -> Fmi2Status;
pub type SetFmuState = unsafe extern "C" fn(c: Fmi2Component, state: Fmi2FmuState) -> Fmi2Status;
pub type FreeFmuState = unsafe extern "C" fn(c: Fmi2Component, state: *mut Fmi2FmuState) -> Fmi2Status;
pub type SerializedFmuStateSize =
    unsafe extern "C" fn(c: Fmi2Component, state: Fmi2FmuState, size: *mut usize) -> Fmi2Status;
pub type SerializeFmuState =
    unsafe extern "C" fn(c: Fmi2Component, state: Fmi2FmuState, bytes: *mut c_char, size: usize) -> Fmi2Status;
pub type DeSerializeFmuState =
    unsafe extern "C" fn(c: Fmi2Component, bytes: *const c_char, size: usize, state: *mut Fmi2FmuState) -> Fmi2Status;
pub type DoStep = unsafe extern "C" fn(
    c: Fmi2Component,
    current_communication_point: f64,
    communication_step_size: f64,
    no_set_fmu_state_prior_to_current_point: Fmi2Boolean,
) -> Fmi2Status;
pub type GetBooleanStatus = unsafe extern "C" fn(c: Fmi2Component, kind: c_int, value: *mut Fmi2Boolean) -> Fmi2Status;
pub type GetRealStatus = unsafe extern "C" fn(c: Fmi2Component, kind: c_int, value: *mut f64) -> Fmi2Status;
/// `fmi2StatusKind` values.
pub const LAST_SUCCESSFUL_TIME: c_int = 2;
pub const TERMINATED: c_int = 3;

// Model exchange.
pub type NewDiscreteStates = unsafe extern "C" fn(c: Fmi2Component, info: *mut EventInfo) -> Fmi2Status;
pub type CompletedIntegratorStep = unsafe extern "C" fn(
    c: Fmi2Component,
    no_set_fmu_state_prior_to_current_point: Fmi2Boolean,
    enter_event_mode: *mut Fmi2Boolean,
    terminate_simulation: *mut Fmi2Boolean,
) -> Fmi2Status;
pub type SetTime = unsafe extern "C" fn(c: Fmi2Component, time: f64) -> Fmi2Status;
pub type SetVector = unsafe extern "C" fn(c: Fmi2Component, x: *const f64, n: usize) -> Fmi2Status;
pub type GetVector = unsafe extern "C" fn(c: Fmi2Component, x: *mut f64, n: usize) -> Fmi2Status;
