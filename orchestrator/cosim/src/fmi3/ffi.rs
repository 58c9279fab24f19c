//! The FMI 3.0 C ABI as Rust function-pointer types (from the standard's fmi3FunctionTypes.h).
//!
//! `fmi3Boolean` is C99 `bool` (Rust `bool`), `fmi3Status` a C enum (`c_int`),
//! `fmi3ValueReference` `uint32_t`, `fmi3Binary` `const uint8_t*`.

use std::ffi::{c_char, c_int, c_void};

pub type Fmi3Instance = *mut c_void;
pub type Fmi3InstanceEnvironment = *mut c_void;
pub type Fmi3FmuState = *mut c_void;
pub type Fmi3Status = c_int;
pub type Vr = u32;

pub type LogMessageCallback = unsafe extern "C" fn(
    env: Fmi3InstanceEnvironment,
    status: Fmi3Status,
    category: *const c_char,
    message: *const c_char,
);

pub type IntermediateUpdateCallback = unsafe extern "C" fn(
    env: Fmi3InstanceEnvironment,
    intermediate_update_time: f64,
    intermediate_variable_set_requested: bool,
    intermediate_variable_get_allowed: bool,
    intermediate_step_finished: bool,
    can_return_early: bool,
    early_return_requested: *mut bool,
    early_return_time: *mut f64,
);

pub type GetVersion = unsafe extern "C" fn() -> *const c_char;

pub type InstantiateCoSimulation = unsafe extern "C" fn(
    instance_name: *const c_char,
    instantiation_token: *const c_char,
    resource_path: *const c_char,
    visible: bool,
    logging_on: bool,
    event_mode_used: bool,
    early_return_allowed: bool,
    required_intermediate_variables: *const Vr,
    n_required_intermediate_variables: usize,
    instance_environment: Fmi3InstanceEnvironment,
    log_message: Option<LogMessageCallback>,
    intermediate_update: Option<IntermediateUpdateCallback>,
) -> Fmi3Instance;

pub type FreeInstance = unsafe extern "C" fn(instance: Fmi3Instance);

pub type SetDebugLogging = unsafe extern "C" fn(
    instance: Fmi3Instance,
    logging_on: bool,
    n_categories: usize,
    categories: *const *const c_char,
) -> Fmi3Status;

pub type EnterInitializationMode = unsafe extern "C" fn(
    instance: Fmi3Instance,
    tolerance_defined: bool,
    tolerance: f64,
    start_time: f64,
    stop_time_defined: bool,
    stop_time: f64,
) -> Fmi3Status;

/// ExitInitializationMode, Terminate, Reset.
pub type InstanceOnly = unsafe extern "C" fn(instance: Fmi3Instance) -> Fmi3Status;

pub type DoStep = unsafe extern "C" fn(
    instance: Fmi3Instance,
    current_communication_point: f64,
    communication_step_size: f64,
    no_set_fmu_state_prior_to_current_point: bool,
    event_handling_needed: *mut bool,
    terminate_simulation: *mut bool,
    early_return: *mut bool,
    last_successful_time: *mut f64,
) -> Fmi3Status;

pub type Getter<T> = unsafe extern "C" fn(
    instance: Fmi3Instance,
    vrs: *const Vr,
    n_vrs: usize,
    values: *mut T,
    n_values: usize,
) -> Fmi3Status;

pub type Setter<T> = unsafe extern "C" fn(
    instance: Fmi3Instance,
    vrs: *const Vr,
    n_vrs: usize,
    values: *const T,
    n_values: usize,
) -> Fmi3Status;

pub type GetBinary = unsafe extern "C" fn(
    instance: Fmi3Instance,
    vrs: *const Vr,
    n_vrs: usize,
    value_sizes: *mut usize,
    values: *mut *const u8,
    n_values: usize,
) -> Fmi3Status;

pub type SetBinary = unsafe extern "C" fn(
    instance: Fmi3Instance,
    vrs: *const Vr,
    n_vrs: usize,
    value_sizes: *const usize,
    values: *const *const u8,
    n_values: usize,
) -> Fmi3Status;

pub type GetFmuState = unsafe extern "C" fn(instance: Fmi3Instance, state: *mut Fmi3FmuState) -> Fmi3Status;
pub type SetFmuState = unsafe extern "C" fn(instance: Fmi3Instance, state: Fmi3FmuState) -> Fmi3Status;
pub type FreeFmuState = unsafe extern "C" fn(instance: Fmi3Instance, state: *mut Fmi3FmuState) -> Fmi3Status;
pub type SerializedFmuStateSize =
    unsafe extern "C" fn(instance: Fmi3Instance, state: Fmi3FmuState, size: *mut usize) -> Fmi3Status;
pub type SerializeFmuState = unsafe extern "C" fn(
    instance: Fmi3Instance,
    state: Fmi3FmuState,
    serialized_state: *mut u8,
    size: usize,
) -> Fmi3Status;
pub type DeserializeFmuState = unsafe extern "C" fn(
    instance: Fmi3Instance,
    serialized_state: *const u8,
    size: usize,
    state: *mut Fmi3FmuState,
) -> Fmi3Status;

// Model exchange.
pub type InstantiateModelExchange = unsafe extern "C" fn(
    instance_name: *const c_char,
    instantiation_token: *const c_char,
    resource_path: *const c_char,
    visible: bool,
    logging_on: bool,
    instance_environment: Fmi3InstanceEnvironment,
    log_message: Option<LogMessageCallback>,
) -> Fmi3Instance;
pub type UpdateDiscreteStates = unsafe extern "C" fn(
    instance: Fmi3Instance,
    discrete_states_need_update: *mut bool,
    terminate_simulation: *mut bool,
    nominals_of_continuous_states_changed: *mut bool,
    values_of_continuous_states_changed: *mut bool,
    next_event_time_defined: *mut bool,
    next_event_time: *mut f64,
) -> Fmi3Status;
pub type CompletedIntegratorStep = unsafe extern "C" fn(
    instance: Fmi3Instance,
    no_set_fmu_state_prior_to_current_point: bool,
    enter_event_mode: *mut bool,
    terminate_simulation: *mut bool,
) -> Fmi3Status;
pub type SetTime = unsafe extern "C" fn(instance: Fmi3Instance, time: f64) -> Fmi3Status;
pub type SetVector = unsafe extern "C" fn(instance: Fmi3Instance, x: *const f64, n: usize) -> Fmi3Status;
pub type GetVector = unsafe extern "C" fn(instance: Fmi3Instance, x: *mut f64, n: usize) -> Fmi3Status;
