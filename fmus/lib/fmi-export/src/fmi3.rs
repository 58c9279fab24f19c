//! The FMI 3.0 co-simulation API as generic functions over a [`Model`].
//!
//! `export_fmu!` wraps each in a `#[no_mangle] extern "C"` symbol; tests call these directly.
//! Argument conventions follow fmi3FunctionTypes.h (FMI 3.0): `fmi3Boolean` is taken as `u8`
//! (any non-zero byte is true), value references as `u32`, `size_t` as `usize`.

use std::ffi::{c_char, c_void, CStr};

use crate::ctype::{self, CType};
use crate::guard::{self, out, slice, slice_mut, with_instance, Failure};
use crate::instance::Instance;
use crate::logger::{Fmi3LogMessage, Logger};
use crate::model::{is_model_exchange, Model};
use crate::registry::Api;
use crate::state::{fmi3 as mask, Status};

pub use crate::state::Status as Fmi3Status;

/// `fmi3IntermediateUpdateCallback` (never called: intermediate update is not provided).
pub type IntermediateUpdate = unsafe extern "C" fn(
    env: *mut c_void,
    intermediate_update_time: f64,
    intermediate_variable_set_requested: u8,
    intermediate_variable_get_allowed: u8,
    intermediate_step_finished: u8,
    can_return_early: u8,
    early_return_requested: *mut u8,
    early_return_time: *mut f64,
);
/// `fmi3ClockUpdateCallback` (scheduled execution; never called).
pub type ClockUpdate = unsafe extern "C" fn(env: *mut c_void);
/// `fmi3LockPreemptionCallback` / `fmi3UnlockPreemptionCallback` (never called).
pub type Preemption = unsafe extern "C" fn();

const API: Api = Api::Fmi3;

pub fn get_version() -> *const c_char {
    c"3.0".as_ptr()
}

unsafe fn opt_str<'a>(p: *const c_char) -> Option<&'a str> {
    if p.is_null() {
        None
    } else {
        CStr::from_ptr(p).to_str().ok()
    }
}

fn log_instantiate_error(name: &str, env: *mut c_void, log: Option<Fmi3LogMessage>, function: &str, msg: &str) {
    Logger::fmi3(name, env, log, true).error(&format!("{function}: {msg}"));
}

/// `fmi3InstantiateCoSimulation`. Returns NULL (and logs why) for a missing instance name,
/// a wrong instantiation token, `eventModeUsed` (this FMU has no event mode) or required
/// intermediate variables (none exist). `resourcePath` may be NULL.
///
/// # Safety
/// String arguments must be NULL or NUL-terminated; `required` must hold `n_required` values.
#[allow(clippy::too_many_arguments)]
pub unsafe fn instantiate_co_simulation<M: Model>(
    instance_name: *const c_char,
    instantiation_token: *const c_char,
    _resource_path: *const c_char,
    _visible: u8,
    logging_on: u8,
    event_mode_used: u8,
    _early_return_allowed: u8,
    _required_intermediate_variables: *const u32,
    n_required_intermediate_variables: usize,
    instance_environment: *mut c_void,
    log_message: Option<Fmi3LogMessage>,
    _intermediate_update: Option<IntermediateUpdate>,
) -> *mut c_void {
    const F: &str = "fmi3InstantiateCoSimulation";
    let result = std::panic::catch_unwind(|| {
        let name = opt_str(instance_name).unwrap_or("");
        let fail = |msg: &str| {
            log_instantiate_error(name, instance_environment, log_message, F, msg);
            std::ptr::null_mut()
        };
        if name.is_empty() {
            return fail("instanceName must be a non-empty UTF-8 string");
        }
        if is_model_exchange::<M>() {
            return fail("this FMU supports Model Exchange only (it has no <CoSimulation> interface)");
        }
        match opt_str(instantiation_token) {
            Some(t) if t == M::TOKEN => {}
            Some(t) => {
                return fail(&format!(
                    "instantiationToken '{t}' does not match this FMU's '{}' (modelDescription.xml and binary differ)",
                    M::TOKEN
                ))
            }
            None => return fail("instantiationToken is NULL or not UTF-8"),
        }
        if event_mode_used != 0 {
            return fail("eventModeUsed=true, but this FMU has no event mode (hasEventMode=false)");
        }
        if n_required_intermediate_variables != 0 {
            return fail("requiredIntermediateVariables given, but this FMU provides no intermediate update");
        }
        let logger = Logger::fmi3(name, instance_environment, log_message, logging_on != 0);
        match Instance::<M>::new(API, logger) {
            Ok(inst) => guard::publish(inst),
            Err(e) => fail(&e),
        }
    });
    result.unwrap_or(std::ptr::null_mut())
}

/// `fmi3InstantiateModelExchange`: a model-exchange instance of a model with continuous
/// states; NULL (logged) for a co-simulation model, a missing instance name or a wrong token.
///
/// # Safety
/// String arguments must be NULL or NUL-terminated.
#[allow(clippy::too_many_arguments)]
pub unsafe fn instantiate_model_exchange<M: Model>(
    instance_name: *const c_char,
    instantiation_token: *const c_char,
    _resource_path: *const c_char,
    _visible: u8,
    logging_on: u8,
    instance_environment: *mut c_void,
    log_message: Option<Fmi3LogMessage>,
) -> *mut c_void {
    if is_model_exchange::<M>() {
        return instantiate_me::<M>(instance_name, instantiation_token, logging_on, instance_environment, log_message);
    }
    let _ = std::panic::catch_unwind(|| {
        let name = opt_str(instance_name).unwrap_or("");
        log_instantiate_error(
            name,
            instance_environment,
            log_message,
            "fmi3InstantiateModelExchange",
            "this FMU supports Co-Simulation only",
        );
    });
    std::ptr::null_mut()
}

unsafe fn instantiate_me<M: Model>(
    instance_name: *const c_char,
    instantiation_token: *const c_char,
    logging_on: u8,
    instance_environment: *mut c_void,
    log_message: Option<Fmi3LogMessage>,
) -> *mut c_void {
    const F: &str = "fmi3InstantiateModelExchange";
    let result = std::panic::catch_unwind(|| {
        let name = opt_str(instance_name).unwrap_or("");
        let fail = |msg: &str| {
            log_instantiate_error(name, instance_environment, log_message, F, msg);
            std::ptr::null_mut()
        };
        if name.is_empty() {
            return fail("instanceName must be a non-empty UTF-8 string");
        }
        match opt_str(instantiation_token) {
            Some(t) if t == M::TOKEN => {}
            Some(t) => {
                return fail(&format!(
                    "instantiationToken '{t}' does not match this FMU's '{}' (modelDescription.xml and binary differ)",
                    M::TOKEN
                ))
            }
            None => return fail("instantiationToken is NULL or not UTF-8"),
        }
        let problems = crate::xml::check_continuous_states(M::VARIABLES, M::CONTINUOUS_STATES);
        if !problems.is_empty() {
            return fail(&format!("the model's continuous states are declared wrongly: {}", problems.join("; ")));
        }
        let logger = Logger::fmi3(name, instance_environment, log_message, logging_on != 0);
        match Instance::<M>::new(API, logger) {
            Ok(inst) => guard::publish(inst),
            Err(e) => fail(&e),
        }
    });
    result.unwrap_or(std::ptr::null_mut())
}

/// `fmi3InstantiateScheduledExecution`: not supported (NULL, logged).
///
/// # Safety
/// `instance_name` must be NULL or NUL-terminated.
#[allow(clippy::too_many_arguments)]
pub unsafe fn instantiate_scheduled_execution<M: Model>(
    instance_name: *const c_char,
    _instantiation_token: *const c_char,
    _resource_path: *const c_char,
    _visible: u8,
    _logging_on: u8,
    instance_environment: *mut c_void,
    log_message: Option<Fmi3LogMessage>,
    _clock_update: Option<ClockUpdate>,
    _lock_preemption: Option<Preemption>,
    _unlock_preemption: Option<Preemption>,
) -> *mut c_void {
    let _ = std::panic::catch_unwind(|| {
        let name = opt_str(instance_name).unwrap_or("");
        log_instantiate_error(
            name,
            instance_environment,
            log_message,
            "fmi3InstantiateScheduledExecution",
            if is_model_exchange::<M>() {
                "this FMU supports Model Exchange only"
            } else {
                "this FMU supports Co-Simulation only"
            },
        );
    });
    std::ptr::null_mut()
}

/// `fmi3FreeInstance`: NULL and unknown handles are ignored.
///
/// # Safety
/// `instance` may be anything (checked against the registry).
pub unsafe fn free_instance<M: Model>(instance: *mut c_void) {
    guard::free::<M>(API, instance)
}

/// `fmi3SetDebugLogging`: unknown categories are reported and return Warning.
///
/// # Safety
/// `categories` must hold `n_categories` NULL or NUL-terminated strings.
pub unsafe fn set_debug_logging<M: Model>(
    instance: *mut c_void,
    logging_on: u8,
    n_categories: usize,
    categories: *const *const c_char,
) -> Status {
    with_instance::<M>(API, instance, "fmi3SetDebugLogging", mask::SET_DEBUG_LOGGING, |inst| {
        set_debug_logging_impl(&mut inst.logger, "fmi3SetDebugLogging", logging_on != 0, n_categories, categories)
    })
}

/// Shared by both APIs.
pub(crate) unsafe fn set_debug_logging_impl(
    logger: &mut Logger,
    function: &str,
    on: bool,
    n: usize,
    categories: *const *const c_char,
) -> Result<Status, Failure> {
    let ptrs = slice(categories, n, "categories")?;
    let mut names = Vec::with_capacity(n);
    for (i, &p) in ptrs.iter().enumerate() {
        if p.is_null() {
            return Err(format!("categories[{i}] is NULL").into());
        }
        names.push(CStr::from_ptr(p));
    }
    let unknown = logger.set_debug_logging(on, &names);
    if unknown.is_empty() {
        Ok(Status::Ok)
    } else {
        logger.warn(&format!("{function}: unknown log categories ignored: {}", unknown.join(", ")));
        Ok(Status::Warning)
    }
}

/// `fmi3EnterInitializationMode`: the tolerance is ignored (the models are not adaptive).
///
/// # Safety
/// `instance` may be anything (checked against the registry).
pub unsafe fn enter_initialization_mode<M: Model>(
    instance: *mut c_void,
    _tolerance_defined: u8,
    _tolerance: f64,
    start_time: f64,
    stop_time_defined: u8,
    stop_time: f64,
) -> Status {
    with_instance::<M>(API, instance, "fmi3EnterInitializationMode", mask::ENTER_INITIALIZATION_MODE, |inst| {
        inst.enter_initialization(start_time, (stop_time_defined != 0).then_some(stop_time))?;
        Ok(Status::Ok)
    })
}

/// `fmi3ExitInitializationMode`: runs `Model::initialize`; goes straight to Step Mode.
///
/// # Safety
/// `instance` may be anything (checked against the registry).
pub unsafe fn exit_initialization_mode<M: Model>(instance: *mut c_void) -> Status {
    with_instance::<M>(API, instance, "fmi3ExitInitializationMode", mask::EXIT_INITIALIZATION_MODE, |inst| {
        inst.exit_initialization()?;
        Ok(Status::Ok)
    })
}

/// `fmi3Terminate`.
///
/// # Safety
/// `instance` may be anything (checked against the registry).
pub unsafe fn terminate<M: Model>(instance: *mut c_void) -> Status {
    with_instance::<M>(API, instance, "fmi3Terminate", mask::TERMINATE, |inst| {
        inst.terminate();
        Ok(Status::Ok)
    })
}

/// `fmi3Reset`: back to Instantiated with start values (Fatal if the model cannot be rebuilt).
///
/// # Safety
/// `instance` may be anything (checked against the registry).
pub unsafe fn reset<M: Model>(instance: *mut c_void) -> Status {
    with_instance::<M>(API, instance, "fmi3Reset", mask::RESET, |inst| {
        inst.reset().map_err(Failure::fatal)?;
        Ok(Status::Ok)
    })
}

fn check_n_values(n_vr: usize, n_values: usize) -> Result<(), Failure> {
    if n_values != n_vr {
        return Err(format!(
            "nValues ({n_values}) must equal the number of scalar values of the {n_vr} requested variables ({n_vr})"
        )
        .into());
    }
    Ok(())
}

/// `fmi3Get{Type}` for any scalar type `T` (see [`ctype`]); `function` names it in messages.
///
/// # Safety
/// `vrs` must hold `n_vr` values and `values` room for `n_values` (or be NULL when 0).
pub unsafe fn get<M: Model, T: CType>(
    instance: *mut c_void,
    function: &str,
    vrs: *const u32,
    n_vr: usize,
    values: *mut T::C,
    n_values: usize,
) -> Status {
    with_instance::<M>(API, instance, function, mask::GET, |inst| {
        let vrs = slice(vrs, n_vr, "valueReferences")?;
        let values = slice_mut(values, n_values, "values")?;
        check_n_values(n_vr, n_values)?;
        let got = inst.get::<T>(vrs)?;
        values.copy_from_slice(&got);
        Ok(Status::Ok)
    })
}

/// `fmi3Set{Type}` for any scalar type `T`. All-or-nothing: nothing is set if any reference,
/// type, mode rule or value is wrong.
///
/// # Safety
/// `vrs` must hold `n_vr` values and `values` `n_values` (or be NULL when 0).
pub unsafe fn set<M: Model, T: CType>(
    instance: *mut c_void,
    function: &str,
    vrs: *const u32,
    n_vr: usize,
    values: *const T::C,
    n_values: usize,
) -> Status {
    with_instance::<M>(API, instance, function, mask::SET, |inst| {
        let vrs = slice(vrs, n_vr, "valueReferences")?;
        let values = slice(values, n_values, "values")?;
        check_n_values(n_vr, n_values)?;
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
        pub unsafe fn $get<M: Model>(
            i: *mut c_void,
            vrs: *const u32,
            n_vr: usize,
            values: *mut $c,
            n_values: usize,
        ) -> Status {
            get::<M, ctype::$marker>(i, $gname, vrs, n_vr, values, n_values)
        }
        #[doc = concat!("`", $sname, "`.")]
        ///
        /// # Safety
        /// As [`set`].
        pub unsafe fn $set<M: Model>(
            i: *mut c_void,
            vrs: *const u32,
            n_vr: usize,
            values: *const $c,
            n_values: usize,
        ) -> Status {
            set::<M, ctype::$marker>(i, $sname, vrs, n_vr, values, n_values)
        }
    };
}

typed!(get_float64, set_float64, Float64, f64, "fmi3GetFloat64", "fmi3SetFloat64");
typed!(get_int32, set_int32, Int32, i32, "fmi3GetInt32", "fmi3SetInt32");
typed!(get_int64, set_int64, Int64, i64, "fmi3GetInt64", "fmi3SetInt64");
typed!(get_boolean, set_boolean, Bool3, u8, "fmi3GetBoolean", "fmi3SetBoolean");
typed!(get_string, set_string, Str, *const c_char, "fmi3GetString", "fmi3SetString");
typed!(get_float32, set_float32, Float32, f32, "fmi3GetFloat32", "fmi3SetFloat32");
typed!(get_int8, set_int8, Int8, i8, "fmi3GetInt8", "fmi3SetInt8");
typed!(get_uint8, set_uint8, UInt8, u8, "fmi3GetUInt8", "fmi3SetUInt8");
typed!(get_int16, set_int16, Int16, i16, "fmi3GetInt16", "fmi3SetInt16");
typed!(get_uint16, set_uint16, UInt16, u16, "fmi3GetUInt16", "fmi3SetUInt16");
typed!(get_uint32, set_uint32, UInt32, u32, "fmi3GetUInt32", "fmi3SetUInt32");
typed!(get_uint64, set_uint64, UInt64, u64, "fmi3GetUInt64", "fmi3SetUInt64");

/// `fmi3GetBinary`: the returned pointers are FMU-owned and valid until the next call on
/// this instance.
///
/// # Safety
/// `vrs` must hold `n_vr` values; `sizes` and `values` room for `n_values` (or NULL when 0).
pub unsafe fn get_binary<M: Model>(
    instance: *mut c_void,
    vrs: *const u32,
    n_vr: usize,
    sizes: *mut usize,
    values: *mut *const u8,
    n_values: usize,
) -> Status {
    with_instance::<M>(API, instance, "fmi3GetBinary", mask::GET, |inst| {
        let vrs = slice(vrs, n_vr, "valueReferences")?;
        let sizes = slice_mut(sizes, n_values, "valueSizes")?;
        let values = slice_mut(values, n_values, "values")?;
        check_n_values(n_vr, n_values)?;
        for (k, (size, ptr)) in inst.get::<ctype::Bin>(vrs)?.into_iter().enumerate() {
            sizes[k] = size;
            values[k] = ptr;
        }
        Ok(Status::Ok)
    })
}

/// `fmi3SetBinary`: the bytes are copied.
///
/// # Safety
/// `vrs` must hold `n_vr` values; `sizes` and `values` `n_values`, each `values[k]` pointing
/// to `sizes[k]` bytes.
pub unsafe fn set_binary<M: Model>(
    instance: *mut c_void,
    vrs: *const u32,
    n_vr: usize,
    sizes: *const usize,
    values: *const *const u8,
    n_values: usize,
) -> Status {
    with_instance::<M>(API, instance, "fmi3SetBinary", mask::SET, |inst| {
        let vrs = slice(vrs, n_vr, "valueReferences")?;
        let sizes = slice(sizes, n_values, "valueSizes")?;
        let values = slice(values, n_values, "values")?;
        check_n_values(n_vr, n_values)?;
        let pairs: Vec<(usize, *const u8)> = sizes.iter().copied().zip(values.iter().copied()).collect();
        inst.set::<ctype::Bin>(vrs, &pairs)?;
        Ok(Status::Ok)
    })
}

/// `fmi3GetFMUState`: a new state if `*state` is NULL, else `*state` is overwritten.
///
/// # Safety
/// `state` must be NULL or point to a writable `fmi3FMUState`.
pub unsafe fn get_fmu_state<M: Model>(instance: *mut c_void, state: *mut *mut c_void) -> Status {
    with_instance::<M>(API, instance, "fmi3GetFMUState", mask::GET_FMU_STATE, |inst| {
        let state = out(state, "FMUState")?;
        *state = inst.get_state(*state)?;
        Ok(Status::Ok)
    })
}

/// `fmi3SetFMUState`: restores values, model state, time and mode (also out of Error).
///
/// # Safety
/// `instance` may be anything; `state` is only used if it is a live state of this instance.
pub unsafe fn set_fmu_state<M: Model>(instance: *mut c_void, state: *mut c_void) -> Status {
    with_instance::<M>(API, instance, "fmi3SetFMUState", mask::SET_FMU_STATE, |inst| {
        inst.set_state(state)?;
        Ok(Status::Ok)
    })
}

/// `fmi3FreeFMUState`: NULL (or `*state` NULL) is ignored; `*state` is set to NULL.
///
/// # Safety
/// `state` must be NULL or point to a writable `fmi3FMUState`.
pub unsafe fn free_fmu_state<M: Model>(instance: *mut c_void, state: *mut *mut c_void) -> Status {
    with_instance::<M>(API, instance, "fmi3FreeFMUState", mask::FREE_FMU_STATE, |inst| {
        if let Some(state) = state.as_mut() {
            inst.free_state(*state)?;
            *state = std::ptr::null_mut();
        }
        Ok(Status::Ok)
    })
}

/// `fmi3SerializedFMUStateSize`.
///
/// # Safety
/// `size` must be NULL or writable.
pub unsafe fn serialized_fmu_state_size<M: Model>(
    instance: *mut c_void,
    state: *mut c_void,
    size: *mut usize,
) -> Status {
    serialized_size_impl::<M>(API, instance, "fmi3SerializedFMUStateSize", mask::SERIALIZE_FMU_STATE, state, size)
}

/// `fmi3SerializeFMUState`: the bytes of [`serial`](crate::serial) into a buffer of `size` bytes.
///
/// # Safety
/// `serialized` must be NULL or point to `size` writable bytes.
pub unsafe fn serialize_fmu_state<M: Model>(
    instance: *mut c_void,
    state: *mut c_void,
    serialized: *mut u8,
    size: usize,
) -> Status {
    serialize_impl::<M>(API, instance, "fmi3SerializeFMUState", mask::SERIALIZE_FMU_STATE, state, serialized, size)
}

/// `fmi3DeserializeFMUState`: a new FMU state (or `*state`, a live one, overwritten).
///
/// # Safety
/// `serialized` must be NULL or point to `size` readable bytes; `state` NULL or writable.
pub unsafe fn deserialize_fmu_state<M: Model>(
    instance: *mut c_void,
    serialized: *const u8,
    size: usize,
    state: *mut *mut c_void,
) -> Status {
    deserialize_impl::<M>(
        API,
        instance,
        "fmi3DeserializeFMUState",
        mask::DESERIALIZE_FMU_STATE,
        serialized,
        size,
        state,
    )
}

/// Shared by the FMI 3 and FMI 2 size functions.
pub(crate) unsafe fn serialized_size_impl<M: Model>(
    api: Api,
    instance: *mut c_void,
    function: &str,
    mask: crate::state::Mask,
    state: *mut c_void,
    size: *mut usize,
) -> Status {
    with_instance::<M>(api, instance, function, mask, |inst| {
        let size = out(size, "size")?;
        *size = inst.serialized_state(state)?.len();
        Ok(Status::Ok)
    })
}

/// Shared by the FMI 3 and FMI 2 serialize functions.
pub(crate) unsafe fn serialize_impl<M: Model>(
    api: Api,
    instance: *mut c_void,
    function: &str,
    mask: crate::state::Mask,
    state: *mut c_void,
    serialized: *mut u8,
    size: usize,
) -> Status {
    with_instance::<M>(api, instance, function, mask, |inst| {
        let buf = slice_mut(serialized, size, "serializedState")?;
        let bytes = inst.serialized_state(state)?;
        if bytes.len() > buf.len() {
            return Err(format!(
                "the buffer holds {} bytes but the state needs {} (ask for the size first)",
                buf.len(),
                bytes.len()
            )
            .into());
        }
        buf[..bytes.len()].copy_from_slice(bytes);
        Ok(Status::Ok)
    })
}

/// Shared by the FMI 3 and FMI 2 deserialize functions.
pub(crate) unsafe fn deserialize_impl<M: Model>(
    api: Api,
    instance: *mut c_void,
    function: &str,
    mask: crate::state::Mask,
    serialized: *const u8,
    size: usize,
    state: *mut *mut c_void,
) -> Status {
    with_instance::<M>(api, instance, function, mask, |inst| {
        let bytes = slice(serialized, size, "serializedState")?;
        let state = out(state, "FMUState")?;
        *state = inst.deserialize_state(bytes, *state)?;
        Ok(Status::Ok)
    })
}

/// `fmi3DoStep`: never returns early, never requests events or termination.
///
/// # Safety
/// The four output pointers must be writable (NULL is an error).
#[allow(clippy::too_many_arguments)]
pub unsafe fn do_step<M: Model>(
    instance: *mut c_void,
    current_communication_point: f64,
    communication_step_size: f64,
    _no_set_fmu_state_prior_to_current_point: u8,
    event_handling_needed: *mut u8,
    terminate_simulation: *mut u8,
    early_return: *mut u8,
    last_successful_time: *mut f64,
) -> Status {
    with_instance::<M>(API, instance, "fmi3DoStep", mask::DO_STEP, |inst| {
        let event = out(event_handling_needed, "eventHandlingNeeded")?;
        let term = out(terminate_simulation, "terminateSimulation")?;
        let early = out(early_return, "earlyReturn")?;
        let last = out(last_successful_time, "lastSuccessfulTime")?;
        *event = 0;
        *term = 0;
        *early = 0;
        *last = inst.time;
        inst.do_step(current_communication_point, communication_step_size)?;
        *last = inst.time;
        Ok(Status::Ok)
    })
}

/// A model-exchange function: runs `f` for a model-exchange model, else is unsupported
/// (exactly as before model exchange existed).
unsafe fn me<M: Model>(
    instance: *mut c_void,
    function: &str,
    mask: crate::state::Mask,
    f: impl FnOnce(&mut Instance<M>) -> Result<Status, Failure>,
) -> Status {
    if !is_model_exchange::<M>() {
        return unsupported::<M>(instance, function);
    }
    with_instance::<M>(API, instance, function, mask, f)
}

/// `fmi3EnterEventMode`.
///
/// # Safety
/// `instance` may be anything (checked against the registry).
pub unsafe fn enter_event_mode<M: Model>(instance: *mut c_void) -> Status {
    me::<M>(instance, "fmi3EnterEventMode", mask::ENTER_EVENT_MODE, |inst| {
        inst.enter_event_mode();
        Ok(Status::Ok)
    })
}

/// `fmi3UpdateDiscreteStates`: one pass handles every event due (discreteStatesNeedUpdate
/// is always false); the model never requests termination; nominals are constant.
///
/// # Safety
/// The six output pointers must be writable (NULL is an error).
#[allow(clippy::too_many_arguments)]
pub unsafe fn update_discrete_states<M: Model>(
    instance: *mut c_void,
    discrete_states_need_update: *mut u8,
    terminate_simulation: *mut u8,
    nominals_of_continuous_states_changed: *mut u8,
    values_of_continuous_states_changed: *mut u8,
    next_event_time_defined: *mut u8,
    next_event_time: *mut f64,
) -> Status {
    me::<M>(instance, "fmi3UpdateDiscreteStates", mask::UPDATE_DISCRETE_STATES, |inst| {
        let need = out(discrete_states_need_update, "discreteStatesNeedUpdate")?;
        let term = out(terminate_simulation, "terminateSimulation")?;
        let nominals = out(nominals_of_continuous_states_changed, "nominalsOfContinuousStatesChanged")?;
        let values = out(values_of_continuous_states_changed, "valuesOfContinuousStatesChanged")?;
        let defined = out(next_event_time_defined, "nextEventTimeDefined")?;
        let next = out(next_event_time, "nextEventTime")?;
        let info = inst.update_discrete_states()?;
        *need = 0;
        *term = 0;
        *nominals = 0;
        *values = info.values_of_continuous_states_changed as u8;
        *defined = info.next_event_time.is_some() as u8;
        *next = info.next_event_time.unwrap_or(0.0);
        Ok(Status::Ok)
    })
}

/// `fmi3EnterContinuousTimeMode`.
///
/// # Safety
/// `instance` may be anything (checked against the registry).
pub unsafe fn enter_continuous_time_mode<M: Model>(instance: *mut c_void) -> Status {
    me::<M>(instance, "fmi3EnterContinuousTimeMode", mask::ENTER_CONTINUOUS_TIME_MODE, |inst| {
        inst.enter_continuous_time_mode();
        Ok(Status::Ok)
    })
}

/// `fmi3CompletedIntegratorStep`: no step events, never terminates
/// (needsCompletedIntegratorStep=false, so importers may skip it).
///
/// # Safety
/// The two output pointers must be writable (NULL is an error).
pub unsafe fn completed_integrator_step<M: Model>(
    instance: *mut c_void,
    _no_set_fmu_state_prior_to_current_point: u8,
    enter_event_mode: *mut u8,
    terminate_simulation: *mut u8,
) -> Status {
    me::<M>(instance, "fmi3CompletedIntegratorStep", mask::COMPLETED_INTEGRATOR_STEP, |_| {
        let enter = out(enter_event_mode, "enterEventMode")?;
        let term = out(terminate_simulation, "terminateSimulation")?;
        *enter = 0;
        *term = 0;
        Ok(Status::Ok)
    })
}

/// `fmi3SetTime`.
///
/// # Safety
/// `instance` may be anything (checked against the registry).
pub unsafe fn set_time<M: Model>(instance: *mut c_void, time: f64) -> Status {
    me::<M>(instance, "fmi3SetTime", mask::SET_TIME, |inst| {
        inst.set_time(time)?;
        Ok(Status::Ok)
    })
}

/// `fmi3SetContinuousStates`: all-or-nothing (every value finite).
///
/// # Safety
/// `x` must hold `nx` values (or be NULL when 0).
pub unsafe fn set_continuous_states<M: Model>(instance: *mut c_void, x: *const f64, nx: usize) -> Status {
    me::<M>(instance, "fmi3SetContinuousStates", mask::SET_CONTINUOUS_STATES, |inst| {
        let x = slice(x, nx, "continuousStates")?;
        inst.set_continuous_states(x)?;
        Ok(Status::Ok)
    })
}

/// `fmi3GetContinuousStateDerivatives`.
///
/// # Safety
/// `dx` must have room for `nx` values (or be NULL when 0).
pub unsafe fn get_continuous_state_derivatives<M: Model>(instance: *mut c_void, dx: *mut f64, nx: usize) -> Status {
    me::<M>(instance, "fmi3GetContinuousStateDerivatives", mask::GET_CONTINUOUS, |inst| {
        let dx = slice_mut(dx, nx, "derivatives")?;
        inst.derivatives(dx)?;
        Ok(Status::Ok)
    })
}

/// `fmi3GetEventIndicators`: there are none, so only `ni = 0` succeeds.
///
/// # Safety
/// `z` must have room for `ni` values (or be NULL when 0).
pub unsafe fn get_event_indicators<M: Model>(instance: *mut c_void, z: *mut f64, ni: usize) -> Status {
    me::<M>(instance, "fmi3GetEventIndicators", mask::GET_CONTINUOUS, |inst| {
        let _ = slice_mut(z, ni, "eventIndicators")?;
        inst.event_indicators(ni)?;
        Ok(Status::Ok)
    })
}

/// `fmi3GetContinuousStates`.
///
/// # Safety
/// `x` must have room for `nx` values (or be NULL when 0).
pub unsafe fn get_continuous_states<M: Model>(instance: *mut c_void, x: *mut f64, nx: usize) -> Status {
    me::<M>(instance, "fmi3GetContinuousStates", mask::GET_CONTINUOUS, |inst| {
        let x = slice_mut(x, nx, "continuousStates")?;
        inst.continuous_states(x)?;
        Ok(Status::Ok)
    })
}

/// `fmi3GetNominalsOfContinuousStates`.
///
/// # Safety
/// `nominals` must have room for `nx` values (or be NULL when 0).
pub unsafe fn get_nominals_of_continuous_states<M: Model>(
    instance: *mut c_void,
    nominals: *mut f64,
    nx: usize,
) -> Status {
    me::<M>(instance, "fmi3GetNominalsOfContinuousStates", mask::GET_NOMINALS, |inst| {
        let nominals = slice_mut(nominals, nx, "nominals")?;
        inst.nominals(nominals)?;
        Ok(Status::Ok)
    })
}

/// `fmi3GetNumberOfEventIndicators`: 0.
///
/// # Safety
/// `n` must be writable (NULL is an error).
pub unsafe fn get_number_of_event_indicators<M: Model>(instance: *mut c_void, n: *mut usize) -> Status {
    me::<M>(instance, "fmi3GetNumberOfEventIndicators", mask::GET_NUMBER_OF, |_| {
        *out(n, "nEventIndicators")? = 0;
        Ok(Status::Ok)
    })
}

/// `fmi3GetNumberOfContinuousStates`.
///
/// # Safety
/// `n` must be writable (NULL is an error).
pub unsafe fn get_number_of_continuous_states<M: Model>(instance: *mut c_void, n: *mut usize) -> Status {
    me::<M>(instance, "fmi3GetNumberOfContinuousStates", mask::GET_NUMBER_OF, |_| {
        *out(n, "nContinuousStates")? = M::CONTINUOUS_STATES.len();
        Ok(Status::Ok)
    })
}

/// Why each unsupported function is unsupported (logged with the error).
pub fn unsupported_reason(function: &str) -> &'static str {
    match function {
        "fmi3EnterEventMode" | "fmi3UpdateDiscreteStates" | "fmi3EvaluateDiscreteStates" | "fmi3EnterStepMode" => {
            "this FMU has no event mode (hasEventMode=false); ExitInitializationMode enters Step Mode directly"
        }
        "fmi3GetClock"
        | "fmi3SetClock"
        | "fmi3GetIntervalDecimal"
        | "fmi3GetIntervalFraction"
        | "fmi3GetShiftDecimal"
        | "fmi3GetShiftFraction"
        | "fmi3SetIntervalDecimal"
        | "fmi3SetIntervalFraction"
        | "fmi3SetShiftDecimal"
        | "fmi3SetShiftFraction"
        | "fmi3ActivateModelPartition" => "this FMU has no clocks",
        "fmi3EnterConfigurationMode" | "fmi3ExitConfigurationMode" => "this FMU has no structural parameters",
        "fmi3GetDirectionalDerivative" | "fmi3GetAdjointDerivative" => {
            "no partial derivatives (providesDirectionalDerivatives=false, providesAdjointDerivatives=false)"
        }
        "fmi3GetOutputDerivatives" => "no output derivatives (maxOutputDerivativeOrder=0)",
        "fmi3GetNumberOfVariableDependencies" | "fmi3GetVariableDependencies" => {
            "dependency information is not provided (see ModelStructure in modelDescription.xml)"
        }
        _ => "this FMU supports Co-Simulation only (no Model Exchange functions)",
    }
}

/// Why a function a model-exchange FMU does not support is unsupported.
fn unsupported_reason_me(function: &str) -> &'static str {
    match function {
        "fmi3EnterStepMode" => "this is a Model Exchange FMU (Step Mode belongs to Co-Simulation)",
        "fmi3EvaluateDiscreteStates" => "providesEvaluateDiscreteStates=false",
        other => unsupported_reason(other),
    }
}

/// Any function of [`unsupported_reason`]: Error, logged.
///
/// # Safety
/// `instance` may be anything (checked against the registry).
pub unsafe fn unsupported<M: Model>(instance: *mut c_void, function: &str) -> Status {
    let why = if is_model_exchange::<M>() { unsupported_reason_me(function) } else { unsupported_reason(function) };
    guard::unsupported::<M>(API, instance, function, why)
}
