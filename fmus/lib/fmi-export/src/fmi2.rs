//! The FMI 2.0 co-simulation API as generic functions over a [`Model`], on the same
//! instance core and state machine as FMI 3. Only FMI-2-representable variables are
//! visible (same value references as FMI 3); Int32 is FMI 2 Integer.
//!
//! `fmi2Boolean` is C `int`; `fmi2Type` and `fmi2StatusKind` arrive as C `int` and are
//! range-checked. The memory callbacks are not used (canNotUseMemoryManagementFunctions=true).

use std::ffi::{c_char, c_int, c_void, CStr};

use crate::ctype::{self, CType};
use crate::fmi3::set_debug_logging_impl;
use crate::guard::{self, out, slice, slice_mut, with_instance, Failure};
use crate::instance::Instance;
use crate::logger::{Fmi2Logger, Logger};
use crate::model::{is_model_exchange, Model};
use crate::registry::Api;
use crate::state::{fmi2 as mask, Status};

pub use crate::state::Status as Fmi2Status;

/// `fmi2CallbackFunctions`.
#[repr(C)]
pub struct CallbackFunctions {
    pub logger: Option<Fmi2Logger>,
    pub allocate_memory: Option<unsafe extern "C" fn(nobj: usize, size: usize) -> *mut c_void>,
    pub free_memory: Option<unsafe extern "C" fn(obj: *mut c_void)>,
    pub step_finished: Option<unsafe extern "C" fn(env: *mut c_void, status: Status)>,
    pub component_environment: *mut c_void,
}

/// `fmi2EventInfo` (every fmi2Boolean is a C `int`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EventInfo {
    pub new_discrete_states_needed: c_int,
    pub terminate_simulation: c_int,
    pub nominals_of_continuous_states_changed: c_int,
    pub values_of_continuous_states_changed: c_int,
    pub next_event_time_defined: c_int,
    pub next_event_time: f64,
}

/// `fmi2Type` value for model exchange.
pub const FMI2_MODEL_EXCHANGE: c_int = 0;
/// `fmi2Type` value for co-simulation.
pub const FMI2_CO_SIMULATION: c_int = 1;
/// `fmi2StatusKind` values.
pub const FMI2_DO_STEP_STATUS: c_int = 0;
pub const FMI2_PENDING_STATUS: c_int = 1;
pub const FMI2_LAST_SUCCESSFUL_TIME: c_int = 2;
pub const FMI2_TERMINATED: c_int = 3;

const API: Api = Api::Fmi2;

pub fn get_types_platform() -> *const c_char {
    c"default".as_ptr()
}

pub fn get_version() -> *const c_char {
    c"2.0".as_ptr()
}

/// `fmi2Instantiate`: NULL (logged when a logger exists) unless `fmuType` is the model's
/// one interface (fmi2ModelExchange for models with continuous states, else
/// fmi2CoSimulation) and `fmuGUID` equals the model's token.
///
/// # Safety
/// Strings must be NULL or NUL-terminated; `functions` NULL or a valid callback struct.
pub unsafe fn instantiate<M: Model>(
    instance_name: *const c_char,
    fmu_type: c_int,
    fmu_guid: *const c_char,
    _fmu_resource_location: *const c_char,
    functions: *const CallbackFunctions,
    _visible: c_int,
    logging_on: c_int,
) -> *mut c_void {
    const F: &str = "fmi2Instantiate";
    let result = std::panic::catch_unwind(|| {
        let Some(functions) = functions.as_ref() else {
            return std::ptr::null_mut();
        };
        let name = if instance_name.is_null() { "" } else { CStr::from_ptr(instance_name).to_str().unwrap_or("") };
        let env = functions.component_environment;
        let fail = |msg: &str| {
            Logger::fmi2(name, env, functions.logger, true).error(&format!("{F}: {msg}"));
            std::ptr::null_mut()
        };
        if name.is_empty() {
            return fail("instanceName must be a non-empty UTF-8 string");
        }
        if is_model_exchange::<M>() {
            if fmu_type != FMI2_MODEL_EXCHANGE {
                return fail(&format!("fmuType {fmu_type} requested, but this FMU supports Model Exchange (0) only"));
            }
            let problems = crate::xml::check_continuous_states(M::VARIABLES, M::CONTINUOUS_STATES);
            if !problems.is_empty() {
                return fail(&format!("the model's continuous states are declared wrongly: {}", problems.join("; ")));
            }
        } else if fmu_type != FMI2_CO_SIMULATION {
            return fail(&format!("fmuType {fmu_type} requested, but this FMU supports Co-Simulation (1) only"));
        }
        let guid = if fmu_guid.is_null() { None } else { CStr::from_ptr(fmu_guid).to_str().ok() };
        match guid {
            Some(g) if g == M::GUID => {}
            Some(g) => {
                return fail(&format!(
                    "fmuGUID '{g}' does not match this FMU's '{}' (modelDescription.xml and binary differ)",
                    M::GUID
                ))
            }
            None => return fail("fmuGUID is NULL or not UTF-8"),
        }
        let logger = Logger::fmi2(name, env, functions.logger, logging_on != 0);
        match Instance::<M>::new(API, logger) {
            Ok(inst) => guard::publish(inst),
            Err(e) => fail(&e),
        }
    });
    result.unwrap_or(std::ptr::null_mut())
}

/// `fmi2FreeInstance`: NULL and unknown handles are ignored.
///
/// # Safety
/// `c` may be anything (checked against the registry).
pub unsafe fn free_instance<M: Model>(c: *mut c_void) {
    guard::free::<M>(API, c)
}

/// `fmi2SetDebugLogging`.
///
/// # Safety
/// `categories` must hold `n_categories` NULL or NUL-terminated strings.
pub unsafe fn set_debug_logging<M: Model>(
    c: *mut c_void,
    logging_on: c_int,
    n_categories: usize,
    categories: *const *const c_char,
) -> Status {
    with_instance::<M>(API, c, "fmi2SetDebugLogging", mask::SET_DEBUG_LOGGING, |inst| {
        set_debug_logging_impl(&mut inst.logger, "fmi2SetDebugLogging", logging_on != 0, n_categories, categories)
    })
}

/// `fmi2SetupExperiment`: the tolerance is ignored.
///
/// # Safety
/// `c` may be anything (checked against the registry).
pub unsafe fn setup_experiment<M: Model>(
    c: *mut c_void,
    _tolerance_defined: c_int,
    _tolerance: f64,
    start_time: f64,
    stop_time_defined: c_int,
    stop_time: f64,
) -> Status {
    with_instance::<M>(API, c, "fmi2SetupExperiment", mask::SETUP_EXPERIMENT, |inst| {
        inst.setup(start_time, (stop_time_defined != 0).then_some(stop_time))?;
        Ok(Status::Ok)
    })
}

/// `fmi2EnterInitializationMode`.
///
/// # Safety
/// `c` may be anything (checked against the registry).
pub unsafe fn enter_initialization_mode<M: Model>(c: *mut c_void) -> Status {
    with_instance::<M>(API, c, "fmi2EnterInitializationMode", mask::ENTER_INITIALIZATION_MODE, |inst| {
        inst.enter_initialization(inst.start_time, inst.stop_time)?;
        Ok(Status::Ok)
    })
}

/// `fmi2ExitInitializationMode`: runs `Model::initialize`.
///
/// # Safety
/// `c` may be anything (checked against the registry).
pub unsafe fn exit_initialization_mode<M: Model>(c: *mut c_void) -> Status {
    with_instance::<M>(API, c, "fmi2ExitInitializationMode", mask::EXIT_INITIALIZATION_MODE, |inst| {
        inst.exit_initialization()?;
        Ok(Status::Ok)
    })
}

/// `fmi2Terminate`.
///
/// # Safety
/// `c` may be anything (checked against the registry).
pub unsafe fn terminate<M: Model>(c: *mut c_void) -> Status {
    with_instance::<M>(API, c, "fmi2Terminate", mask::TERMINATE, |inst| {
        inst.terminate();
        Ok(Status::Ok)
    })
}

/// `fmi2Reset`.
///
/// # Safety
/// `c` may be anything (checked against the registry).
pub unsafe fn reset<M: Model>(c: *mut c_void) -> Status {
    with_instance::<M>(API, c, "fmi2Reset", mask::RESET, |inst| {
        inst.reset().map_err(Failure::fatal)?;
        Ok(Status::Ok)
    })
}

/// `fmi2Get{Type}` (one value per reference).
///
/// # Safety
/// `vr` must hold `nvr` values and `value` room for `nvr` (or be NULL when 0).
pub unsafe fn get<M: Model, T: CType>(
    c: *mut c_void,
    function: &str,
    vr: *const u32,
    nvr: usize,
    value: *mut T::C,
) -> Status {
    with_instance::<M>(API, c, function, mask::GET, |inst| {
        let vrs = slice(vr, nvr, "vr")?;
        let values = slice_mut(value, nvr, "value")?;
        values.copy_from_slice(&inst.get::<T>(vrs)?);
        Ok(Status::Ok)
    })
}

/// `fmi2Set{Type}` (all-or-nothing).
///
/// # Safety
/// `vr` and `value` must hold `nvr` values (or be NULL when 0).
pub unsafe fn set<M: Model, T: CType>(
    c: *mut c_void,
    function: &str,
    vr: *const u32,
    nvr: usize,
    value: *const T::C,
) -> Status {
    with_instance::<M>(API, c, function, mask::SET, |inst| {
        let vrs = slice(vr, nvr, "vr")?;
        let values = slice(value, nvr, "value")?;
        inst.set::<T>(vrs, values)?;
        Ok(Status::Ok)
    })
}

macro_rules! typed {
    ($get:ident, $set:ident, $marker:ident, $c:ty, $gname:literal, $sname:literal) => {
        #[doc = concat!("`", $gname, "`.")]
        ///
        /// # Safety
        /// As [`get`].
        pub unsafe fn $get<M: Model>(c: *mut c_void, vr: *const u32, nvr: usize, value: *mut $c) -> Status {
            get::<M, ctype::$marker>(c, $gname, vr, nvr, value)
        }
        #[doc = concat!("`", $sname, "`.")]
        ///
        /// # Safety
        /// As [`set`].
        pub unsafe fn $set<M: Model>(c: *mut c_void, vr: *const u32, nvr: usize, value: *const $c) -> Status {
            set::<M, ctype::$marker>(c, $sname, vr, nvr, value)
        }
    };
}

typed!(get_real, set_real, Float64, f64, "fmi2GetReal", "fmi2SetReal");
typed!(get_integer, set_integer, Int32, c_int, "fmi2GetInteger", "fmi2SetInteger");
typed!(get_boolean, set_boolean, Bool2, c_int, "fmi2GetBoolean", "fmi2SetBoolean");
typed!(get_string, set_string, Str, *const c_char, "fmi2GetString", "fmi2SetString");

/// `fmi2GetFMUstate`.
///
/// # Safety
/// `state` must be NULL or point to a writable `fmi2FMUstate`.
pub unsafe fn get_fmu_state<M: Model>(c: *mut c_void, state: *mut *mut c_void) -> Status {
    with_instance::<M>(API, c, "fmi2GetFMUstate", mask::GET_FMU_STATE, |inst| {
        let state = out(state, "FMUstate")?;
        *state = inst.get_state(*state)?;
        Ok(Status::Ok)
    })
}

/// `fmi2SerializedFMUstateSize`.
///
/// # Safety
/// `size` must be NULL or writable.
pub unsafe fn serialized_fmu_state_size<M: Model>(c: *mut c_void, state: *mut c_void, size: *mut usize) -> Status {
    crate::fmi3::serialized_size_impl::<M>(API, c, "fmi2SerializedFMUstateSize", mask::SERIALIZE_FMU_STATE, state, size)
}

/// `fmi2SerializeFMUstate`.
///
/// # Safety
/// `serialized` must be NULL or point to `size` writable bytes.
pub unsafe fn serialize_fmu_state<M: Model>(
    c: *mut c_void,
    state: *mut c_void,
    serialized: *mut c_char,
    size: usize,
) -> Status {
    crate::fmi3::serialize_impl::<M>(
        API,
        c,
        "fmi2SerializeFMUstate",
        mask::SERIALIZE_FMU_STATE,
        state,
        serialized.cast(),
        size,
    )
}

/// `fmi2DeSerializeFMUstate`.
///
/// # Safety
/// `serialized` must be NULL or point to `size` readable bytes; `state` NULL or writable.
pub unsafe fn deserialize_fmu_state<M: Model>(
    c: *mut c_void,
    serialized: *const c_char,
    size: usize,
    state: *mut *mut c_void,
) -> Status {
    crate::fmi3::deserialize_impl::<M>(
        API,
        c,
        "fmi2DeSerializeFMUstate",
        mask::DESERIALIZE_FMU_STATE,
        serialized.cast(),
        size,
        state,
    )
}

/// `fmi2SetFMUstate`.
///
/// # Safety
/// `c` may be anything; `state` is only used if it is a live state of this instance.
pub unsafe fn set_fmu_state<M: Model>(c: *mut c_void, state: *mut c_void) -> Status {
    with_instance::<M>(API, c, "fmi2SetFMUstate", mask::SET_FMU_STATE, |inst| {
        inst.set_state(state)?;
        Ok(Status::Ok)
    })
}

/// `fmi2FreeFMUstate`.
///
/// # Safety
/// `state` must be NULL or point to a writable `fmi2FMUstate`.
pub unsafe fn free_fmu_state<M: Model>(c: *mut c_void, state: *mut *mut c_void) -> Status {
    with_instance::<M>(API, c, "fmi2FreeFMUstate", mask::FREE_FMU_STATE, |inst| {
        if let Some(state) = state.as_mut() {
            inst.free_state(*state)?;
            *state = std::ptr::null_mut();
        }
        Ok(Status::Ok)
    })
}

/// `fmi2DoStep` (synchronous: never Pending).
///
/// # Safety
/// `c` may be anything (checked against the registry).
pub unsafe fn do_step<M: Model>(
    c: *mut c_void,
    current_communication_point: f64,
    communication_step_size: f64,
    _no_set_fmu_state_prior_to_current_point: c_int,
) -> Status {
    with_instance::<M>(API, c, "fmi2DoStep", mask::DO_STEP, |inst| {
        inst.do_step(current_communication_point, communication_step_size)?;
        Ok(Status::Ok)
    })
}

fn no_status(kind: c_int) -> Failure {
    Failure {
        status: Status::Discard,
        message: format!("status kind {kind} is not available (steps are synchronous; no step is pending)"),
    }
}

/// `fmi2GetStatus`: nothing is ever pending, so Discard.
///
/// # Safety
/// `value` must be NULL or writable.
pub unsafe fn get_status<M: Model>(c: *mut c_void, kind: c_int, value: *mut Status) -> Status {
    with_instance::<M>(API, c, "fmi2GetStatus", mask::GET_STATUS, |_| {
        let _ = out(value, "value")?;
        Err(no_status(kind))
    })
}

/// `fmi2GetRealStatus`: fmi2LastSuccessfulTime is the current time.
///
/// # Safety
/// `value` must be NULL or writable.
pub unsafe fn get_real_status<M: Model>(c: *mut c_void, kind: c_int, value: *mut f64) -> Status {
    with_instance::<M>(API, c, "fmi2GetRealStatus", mask::GET_STATUS, |inst| {
        let value = out(value, "value")?;
        if kind != FMI2_LAST_SUCCESSFUL_TIME {
            return Err(no_status(kind));
        }
        *value = inst.time;
        Ok(Status::Ok)
    })
}

/// `fmi2GetIntegerStatus`: no integer status exists (Discard).
///
/// # Safety
/// `value` must be NULL or writable.
pub unsafe fn get_integer_status<M: Model>(c: *mut c_void, kind: c_int, value: *mut c_int) -> Status {
    with_instance::<M>(API, c, "fmi2GetIntegerStatus", mask::GET_STATUS, |_| {
        let _ = out(value, "value")?;
        Err(no_status(kind))
    })
}

/// `fmi2GetBooleanStatus`: fmi2Terminated is always false (the model never asks to stop).
///
/// # Safety
/// `value` must be NULL or writable.
pub unsafe fn get_boolean_status<M: Model>(c: *mut c_void, kind: c_int, value: *mut c_int) -> Status {
    with_instance::<M>(API, c, "fmi2GetBooleanStatus", mask::GET_STATUS, |_| {
        let value = out(value, "value")?;
        if kind != FMI2_TERMINATED {
            return Err(no_status(kind));
        }
        *value = 0;
        Ok(Status::Ok)
    })
}

/// `fmi2GetStringStatus`: nothing is pending (Discard).
///
/// # Safety
/// `value` must be NULL or writable.
pub unsafe fn get_string_status<M: Model>(c: *mut c_void, kind: c_int, value: *mut *const c_char) -> Status {
    with_instance::<M>(API, c, "fmi2GetStringStatus", mask::GET_STATUS, |_| {
        let _ = out(value, "value")?;
        Err(no_status(kind))
    })
}

/// A model-exchange function: runs `f` for a model-exchange model, else is unsupported
/// (exactly as before model exchange existed).
unsafe fn me<M: Model>(
    c: *mut c_void,
    function: &str,
    mask: crate::state::Mask,
    f: impl FnOnce(&mut Instance<M>) -> Result<Status, Failure>,
) -> Status {
    if !is_model_exchange::<M>() {
        return unsupported::<M>(c, function);
    }
    with_instance::<M>(API, c, function, mask, f)
}

/// `fmi2EnterEventMode`.
///
/// # Safety
/// `c` may be anything (checked against the registry).
pub unsafe fn enter_event_mode<M: Model>(c: *mut c_void) -> Status {
    me::<M>(c, "fmi2EnterEventMode", mask::ENTER_EVENT_MODE, |inst| {
        inst.enter_event_mode();
        Ok(Status::Ok)
    })
}

/// `fmi2NewDiscreteStates`: one pass handles every event due (newDiscreteStatesNeeded is
/// always false); the model never requests termination; nominals are constant.
///
/// # Safety
/// `event_info` must be NULL (an error) or writable.
pub unsafe fn new_discrete_states<M: Model>(c: *mut c_void, event_info: *mut EventInfo) -> Status {
    me::<M>(c, "fmi2NewDiscreteStates", mask::NEW_DISCRETE_STATES, |inst| {
        let ei = out(event_info, "fmi2EventInfo")?;
        let info = inst.update_discrete_states()?;
        *ei = EventInfo {
            new_discrete_states_needed: 0,
            terminate_simulation: 0,
            nominals_of_continuous_states_changed: 0,
            values_of_continuous_states_changed: info.values_of_continuous_states_changed as c_int,
            next_event_time_defined: info.next_event_time.is_some() as c_int,
            next_event_time: info.next_event_time.unwrap_or(0.0),
        };
        Ok(Status::Ok)
    })
}

/// `fmi2EnterContinuousTimeMode`.
///
/// # Safety
/// `c` may be anything (checked against the registry).
pub unsafe fn enter_continuous_time_mode<M: Model>(c: *mut c_void) -> Status {
    me::<M>(c, "fmi2EnterContinuousTimeMode", mask::ENTER_CONTINUOUS_TIME_MODE, |inst| {
        inst.enter_continuous_time_mode();
        Ok(Status::Ok)
    })
}

/// `fmi2CompletedIntegratorStep`: no step events, never terminates
/// (completedIntegratorStepNotNeeded=true, so importers may skip it).
///
/// # Safety
/// The two output pointers must be writable (NULL is an error).
pub unsafe fn completed_integrator_step<M: Model>(
    c: *mut c_void,
    _no_set_fmu_state_prior_to_current_point: c_int,
    enter_event_mode: *mut c_int,
    terminate_simulation: *mut c_int,
) -> Status {
    me::<M>(c, "fmi2CompletedIntegratorStep", mask::COMPLETED_INTEGRATOR_STEP, |_| {
        let enter = out(enter_event_mode, "enterEventMode")?;
        let term = out(terminate_simulation, "terminateSimulation")?;
        *enter = 0;
        *term = 0;
        Ok(Status::Ok)
    })
}

/// `fmi2SetTime`.
///
/// # Safety
/// `c` may be anything (checked against the registry).
pub unsafe fn set_time<M: Model>(c: *mut c_void, time: f64) -> Status {
    me::<M>(c, "fmi2SetTime", mask::SET_TIME, |inst| {
        inst.set_time(time)?;
        Ok(Status::Ok)
    })
}

/// `fmi2SetContinuousStates`: all-or-nothing (every value finite).
///
/// # Safety
/// `x` must hold `nx` values (or be NULL when 0).
pub unsafe fn set_continuous_states<M: Model>(c: *mut c_void, x: *const f64, nx: usize) -> Status {
    me::<M>(c, "fmi2SetContinuousStates", mask::SET_CONTINUOUS_STATES, |inst| {
        inst.set_continuous_states(slice(x, nx, "x")?)?;
        Ok(Status::Ok)
    })
}

/// `fmi2GetDerivatives`.
///
/// # Safety
/// `dx` must have room for `nx` values (or be NULL when 0).
pub unsafe fn get_derivatives<M: Model>(c: *mut c_void, dx: *mut f64, nx: usize) -> Status {
    me::<M>(c, "fmi2GetDerivatives", mask::GET_CONTINUOUS, |inst| {
        inst.derivatives(slice_mut(dx, nx, "derivatives")?)?;
        Ok(Status::Ok)
    })
}

/// `fmi2GetEventIndicators`: there are none, so only `ni = 0` succeeds.
///
/// # Safety
/// `z` must have room for `ni` values (or be NULL when 0).
pub unsafe fn get_event_indicators<M: Model>(c: *mut c_void, z: *mut f64, ni: usize) -> Status {
    me::<M>(c, "fmi2GetEventIndicators", mask::GET_CONTINUOUS, |inst| {
        let _ = slice_mut(z, ni, "eventIndicators")?;
        inst.event_indicators(ni)?;
        Ok(Status::Ok)
    })
}

/// `fmi2GetContinuousStates`.
///
/// # Safety
/// `x` must have room for `nx` values (or be NULL when 0).
pub unsafe fn get_continuous_states<M: Model>(c: *mut c_void, x: *mut f64, nx: usize) -> Status {
    me::<M>(c, "fmi2GetContinuousStates", mask::GET_CONTINUOUS, |inst| {
        inst.continuous_states(slice_mut(x, nx, "x")?)?;
        Ok(Status::Ok)
    })
}

/// `fmi2GetNominalsOfContinuousStates`.
///
/// # Safety
/// `nominals` must have room for `nx` values (or be NULL when 0).
pub unsafe fn get_nominals_of_continuous_states<M: Model>(c: *mut c_void, nominals: *mut f64, nx: usize) -> Status {
    me::<M>(c, "fmi2GetNominalsOfContinuousStates", mask::GET_NOMINALS, |inst| {
        inst.nominals(slice_mut(nominals, nx, "x_nominal")?)?;
        Ok(Status::Ok)
    })
}

/// Why each unsupported function is unsupported (logged with the error).
pub fn unsupported_reason(function: &str) -> &'static str {
    match function {
        "fmi2GetDirectionalDerivative" => "no partial derivatives (providesDirectionalDerivative=false)",
        "fmi2SetRealInputDerivatives" => "inputs cannot be interpolated (canInterpolateInputs=false)",
        "fmi2GetRealOutputDerivatives" => "no output derivatives (maxOutputDerivativeOrder=0)",
        "fmi2CancelStep" => "steps are synchronous (canRunAsynchronuously=false); there is nothing to cancel",
        _ => "this FMU supports Co-Simulation only (no Model Exchange functions)",
    }
}

/// Any function of [`unsupported_reason`]: Error, logged.
///
/// # Safety
/// `c` may be anything (checked against the registry).
pub unsafe fn unsupported<M: Model>(c: *mut c_void, function: &str) -> Status {
    guard::unsupported::<M>(API, c, function, unsupported_reason(function))
}
