//! `export_fmu!`: the C symbols of an FMU shared library.
//!
//! Every symbol is a one-line wrapper over the generic layer ([`crate::fmi3`],
//! [`crate::fmi2`]), which is where validation, the state machine and panic containment
//! live. All 75 `fmi3*` functions are exported because FMPy (and others) resolve every one
//! at load time; the unsupported ones return Error and log why.
//!
//! Generated from the FMI 3.0 / 2.0 headers' function list (argument names follow them).

/// Exports the FMI 3.0 and FMI 2.0 C API for a [`Model`](crate::Model) type (co-simulation,
/// or model exchange for a model with continuous states; the other interface's functions
/// fail and log why),
/// plus `agrisim_model_description_fmi3()` / `agrisim_model_description_fmi2()` returning
/// the NUL-terminated modelDescription.xml texts (used by `agrisim fmu pack`).
///
/// ```ignore
/// agrisim_fmi::export_fmu!(crate::MyModel);
/// ```
///
/// Use it once per cdylib: the symbols have fixed C names, so two FMU crates exporting
/// them cannot be linked into the same binary (tests should use the generic layer).
#[macro_export]
macro_rules! export_fmu {
    ($M:ty) => {
        #[doc(hidden)]
        #[allow(non_snake_case, clippy::missing_safety_doc, clippy::too_many_arguments)]
        pub mod __agrisim_fmi_exports {
            #[allow(unused_imports)]
            use super::*;

            /// modelDescription.xml for FMI 3.0, NUL-terminated, built once.
            #[unsafe(no_mangle)]
            pub extern "C" fn agrisim_model_description_fmi3() -> *const ::std::ffi::c_char {
                static XML: ::std::sync::OnceLock<Option<::std::ffi::CString>> = ::std::sync::OnceLock::new();
                $crate::xml::c_text(&XML, $crate::xml::fmi3::<$M>)
            }

            /// modelDescription.xml for FMI 2.0, NUL-terminated, built once.
            #[unsafe(no_mangle)]
            pub extern "C" fn agrisim_model_description_fmi2() -> *const ::std::ffi::c_char {
                static XML: ::std::sync::OnceLock<Option<::std::ffi::CString>> = ::std::sync::OnceLock::new();
                $crate::xml::c_text(&XML, $crate::xml::fmi2::<$M>)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetVersion() -> *const ::std::ffi::c_char {
                $crate::fmi3::get_version()
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3SetDebugLogging(
                instance: *mut ::std::ffi::c_void,
                logging_on: u8,
                n_categories: usize,
                categories: *const *const ::std::ffi::c_char,
            ) -> $crate::Status {
                $crate::fmi3::set_debug_logging::<$M>(instance, logging_on, n_categories, categories)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3InstantiateModelExchange(
                instance_name: *const ::std::ffi::c_char,
                token: *const ::std::ffi::c_char,
                resource_path: *const ::std::ffi::c_char,
                visible: u8,
                logging_on: u8,
                env: *mut ::std::ffi::c_void,
                log_message: Option<$crate::logger::Fmi3LogMessage>,
            ) -> *mut ::std::ffi::c_void {
                $crate::fmi3::instantiate_model_exchange::<$M>(
                    instance_name,
                    token,
                    resource_path,
                    visible,
                    logging_on,
                    env,
                    log_message,
                )
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3InstantiateCoSimulation(
                instance_name: *const ::std::ffi::c_char,
                token: *const ::std::ffi::c_char,
                resource_path: *const ::std::ffi::c_char,
                visible: u8,
                logging_on: u8,
                event_mode_used: u8,
                early_return_allowed: u8,
                required: *const u32,
                n_required: usize,
                env: *mut ::std::ffi::c_void,
                log_message: Option<$crate::logger::Fmi3LogMessage>,
                intermediate_update: Option<$crate::fmi3::IntermediateUpdate>,
            ) -> *mut ::std::ffi::c_void {
                $crate::fmi3::instantiate_co_simulation::<$M>(
                    instance_name,
                    token,
                    resource_path,
                    visible,
                    logging_on,
                    event_mode_used,
                    early_return_allowed,
                    required,
                    n_required,
                    env,
                    log_message,
                    intermediate_update,
                )
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3InstantiateScheduledExecution(
                instance_name: *const ::std::ffi::c_char,
                token: *const ::std::ffi::c_char,
                resource_path: *const ::std::ffi::c_char,
                visible: u8,
                logging_on: u8,
                env: *mut ::std::ffi::c_void,
                log_message: Option<$crate::logger::Fmi3LogMessage>,
                clock_update: Option<$crate::fmi3::ClockUpdate>,
                lock_preemption: Option<$crate::fmi3::Preemption>,
                unlock_preemption: Option<$crate::fmi3::Preemption>,
            ) -> *mut ::std::ffi::c_void {
                $crate::fmi3::instantiate_scheduled_execution::<$M>(
                    instance_name,
                    token,
                    resource_path,
                    visible,
                    logging_on,
                    env,
                    log_message,
                    clock_update,
                    lock_preemption,
                    unlock_preemption,
                )
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3FreeInstance(instance: *mut ::std::ffi::c_void) {
                $crate::fmi3::free_instance::<$M>(instance)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3EnterInitializationMode(
                instance: *mut ::std::ffi::c_void,
                tolerance_defined: u8,
                tolerance: f64,
                start_time: f64,
                stop_time_defined: u8,
                stop_time: f64,
            ) -> $crate::Status {
                $crate::fmi3::enter_initialization_mode::<$M>(
                    instance,
                    tolerance_defined,
                    tolerance,
                    start_time,
                    stop_time_defined,
                    stop_time,
                )
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3ExitInitializationMode(instance: *mut ::std::ffi::c_void) -> $crate::Status {
                $crate::fmi3::exit_initialization_mode::<$M>(instance)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3EnterEventMode(instance: *mut ::std::ffi::c_void) -> $crate::Status {
                $crate::fmi3::enter_event_mode::<$M>(instance)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3Terminate(instance: *mut ::std::ffi::c_void) -> $crate::Status {
                $crate::fmi3::terminate::<$M>(instance)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3Reset(instance: *mut ::std::ffi::c_void) -> $crate::Status {
                $crate::fmi3::reset::<$M>(instance)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetFloat32(
                instance: *mut ::std::ffi::c_void,
                vrs: *const u32,
                n_vr: usize,
                values: *mut f32,
                n_values: usize,
            ) -> $crate::Status {
                $crate::fmi3::get_float32::<$M>(instance, vrs, n_vr, values, n_values)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetFloat64(
                instance: *mut ::std::ffi::c_void,
                vrs: *const u32,
                n_vr: usize,
                values: *mut f64,
                n_values: usize,
            ) -> $crate::Status {
                $crate::fmi3::get_float64::<$M>(instance, vrs, n_vr, values, n_values)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetInt8(
                instance: *mut ::std::ffi::c_void,
                vrs: *const u32,
                n_vr: usize,
                values: *mut i8,
                n_values: usize,
            ) -> $crate::Status {
                $crate::fmi3::get_int8::<$M>(instance, vrs, n_vr, values, n_values)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetUInt8(
                instance: *mut ::std::ffi::c_void,
                vrs: *const u32,
                n_vr: usize,
                values: *mut u8,
                n_values: usize,
            ) -> $crate::Status {
                $crate::fmi3::get_uint8::<$M>(instance, vrs, n_vr, values, n_values)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetInt16(
                instance: *mut ::std::ffi::c_void,
                vrs: *const u32,
                n_vr: usize,
                values: *mut i16,
                n_values: usize,
            ) -> $crate::Status {
                $crate::fmi3::get_int16::<$M>(instance, vrs, n_vr, values, n_values)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetUInt16(
                instance: *mut ::std::ffi::c_void,
                vrs: *const u32,
                n_vr: usize,
                values: *mut u16,
                n_values: usize,
            ) -> $crate::Status {
                $crate::fmi3::get_uint16::<$M>(instance, vrs, n_vr, values, n_values)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetInt32(
                instance: *mut ::std::ffi::c_void,
                vrs: *const u32,
                n_vr: usize,
                values: *mut i32,
                n_values: usize,
            ) -> $crate::Status {
                $crate::fmi3::get_int32::<$M>(instance, vrs, n_vr, values, n_values)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetUInt32(
                instance: *mut ::std::ffi::c_void,
                vrs: *const u32,
                n_vr: usize,
                values: *mut u32,
                n_values: usize,
            ) -> $crate::Status {
                $crate::fmi3::get_uint32::<$M>(instance, vrs, n_vr, values, n_values)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetInt64(
                instance: *mut ::std::ffi::c_void,
                vrs: *const u32,
                n_vr: usize,
                values: *mut i64,
                n_values: usize,
            ) -> $crate::Status {
                $crate::fmi3::get_int64::<$M>(instance, vrs, n_vr, values, n_values)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetUInt64(
                instance: *mut ::std::ffi::c_void,
                vrs: *const u32,
                n_vr: usize,
                values: *mut u64,
                n_values: usize,
            ) -> $crate::Status {
                $crate::fmi3::get_uint64::<$M>(instance, vrs, n_vr, values, n_values)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetBoolean(
                instance: *mut ::std::ffi::c_void,
                vrs: *const u32,
                n_vr: usize,
                values: *mut u8,
                n_values: usize,
            ) -> $crate::Status {
                $crate::fmi3::get_boolean::<$M>(instance, vrs, n_vr, values, n_values)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetString(
                instance: *mut ::std::ffi::c_void,
                vrs: *const u32,
                n_vr: usize,
                values: *mut *const ::std::ffi::c_char,
                n_values: usize,
            ) -> $crate::Status {
                $crate::fmi3::get_string::<$M>(instance, vrs, n_vr, values, n_values)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetBinary(
                instance: *mut ::std::ffi::c_void,
                vrs: *const u32,
                n_vr: usize,
                value_sizes: *mut usize,
                values: *mut *const u8,
                n_values: usize,
            ) -> $crate::Status {
                $crate::fmi3::get_binary::<$M>(instance, vrs, n_vr, value_sizes, values, n_values)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetClock(
                instance: *mut ::std::ffi::c_void,
                _vrs: *const u32,
                _n_vr: usize,
                _values: *mut u8,
            ) -> $crate::Status {
                $crate::fmi3::unsupported::<$M>(instance, "fmi3GetClock")
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3SetFloat32(
                instance: *mut ::std::ffi::c_void,
                vrs: *const u32,
                n_vr: usize,
                values: *const f32,
                n_values: usize,
            ) -> $crate::Status {
                $crate::fmi3::set_float32::<$M>(instance, vrs, n_vr, values, n_values)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3SetFloat64(
                instance: *mut ::std::ffi::c_void,
                vrs: *const u32,
                n_vr: usize,
                values: *const f64,
                n_values: usize,
            ) -> $crate::Status {
                $crate::fmi3::set_float64::<$M>(instance, vrs, n_vr, values, n_values)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3SetInt8(
                instance: *mut ::std::ffi::c_void,
                vrs: *const u32,
                n_vr: usize,
                values: *const i8,
                n_values: usize,
            ) -> $crate::Status {
                $crate::fmi3::set_int8::<$M>(instance, vrs, n_vr, values, n_values)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3SetUInt8(
                instance: *mut ::std::ffi::c_void,
                vrs: *const u32,
                n_vr: usize,
                values: *const u8,
                n_values: usize,
            ) -> $crate::Status {
                $crate::fmi3::set_uint8::<$M>(instance, vrs, n_vr, values, n_values)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3SetInt16(
                instance: *mut ::std::ffi::c_void,
                vrs: *const u32,
                n_vr: usize,
                values: *const i16,
                n_values: usize,
            ) -> $crate::Status {
                $crate::fmi3::set_int16::<$M>(instance, vrs, n_vr, values, n_values)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3SetUInt16(
                instance: *mut ::std::ffi::c_void,
                vrs: *const u32,
                n_vr: usize,
                values: *const u16,
                n_values: usize,
            ) -> $crate::Status {
                $crate::fmi3::set_uint16::<$M>(instance, vrs, n_vr, values, n_values)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3SetInt32(
                instance: *mut ::std::ffi::c_void,
                vrs: *const u32,
                n_vr: usize,
                values: *const i32,
                n_values: usize,
            ) -> $crate::Status {
                $crate::fmi3::set_int32::<$M>(instance, vrs, n_vr, values, n_values)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3SetUInt32(
                instance: *mut ::std::ffi::c_void,
                vrs: *const u32,
                n_vr: usize,
                values: *const u32,
                n_values: usize,
            ) -> $crate::Status {
                $crate::fmi3::set_uint32::<$M>(instance, vrs, n_vr, values, n_values)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3SetInt64(
                instance: *mut ::std::ffi::c_void,
                vrs: *const u32,
                n_vr: usize,
                values: *const i64,
                n_values: usize,
            ) -> $crate::Status {
                $crate::fmi3::set_int64::<$M>(instance, vrs, n_vr, values, n_values)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3SetUInt64(
                instance: *mut ::std::ffi::c_void,
                vrs: *const u32,
                n_vr: usize,
                values: *const u64,
                n_values: usize,
            ) -> $crate::Status {
                $crate::fmi3::set_uint64::<$M>(instance, vrs, n_vr, values, n_values)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3SetBoolean(
                instance: *mut ::std::ffi::c_void,
                vrs: *const u32,
                n_vr: usize,
                values: *const u8,
                n_values: usize,
            ) -> $crate::Status {
                $crate::fmi3::set_boolean::<$M>(instance, vrs, n_vr, values, n_values)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3SetString(
                instance: *mut ::std::ffi::c_void,
                vrs: *const u32,
                n_vr: usize,
                values: *const *const ::std::ffi::c_char,
                n_values: usize,
            ) -> $crate::Status {
                $crate::fmi3::set_string::<$M>(instance, vrs, n_vr, values, n_values)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3SetBinary(
                instance: *mut ::std::ffi::c_void,
                vrs: *const u32,
                n_vr: usize,
                value_sizes: *const usize,
                values: *const *const u8,
                n_values: usize,
            ) -> $crate::Status {
                $crate::fmi3::set_binary::<$M>(instance, vrs, n_vr, value_sizes, values, n_values)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3SetClock(
                instance: *mut ::std::ffi::c_void,
                _vrs: *const u32,
                _n_vr: usize,
                _values: *const u8,
            ) -> $crate::Status {
                $crate::fmi3::unsupported::<$M>(instance, "fmi3SetClock")
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetNumberOfVariableDependencies(
                instance: *mut ::std::ffi::c_void,
                _value_reference: u32,
                _n_dependencies: *mut usize,
            ) -> $crate::Status {
                $crate::fmi3::unsupported::<$M>(instance, "fmi3GetNumberOfVariableDependencies")
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetVariableDependencies(
                instance: *mut ::std::ffi::c_void,
                _dependent: u32,
                _element_indices_of_dependent: *mut usize,
                _independents: *mut u32,
                _element_indices_of_independents: *mut usize,
                _dependency_kinds: *mut ::std::ffi::c_int,
                _n_dependencies: usize,
            ) -> $crate::Status {
                $crate::fmi3::unsupported::<$M>(instance, "fmi3GetVariableDependencies")
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetFMUState(
                instance: *mut ::std::ffi::c_void,
                state: *mut *mut ::std::ffi::c_void,
            ) -> $crate::Status {
                $crate::fmi3::get_fmu_state::<$M>(instance, state)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3SetFMUState(
                instance: *mut ::std::ffi::c_void,
                state: *mut ::std::ffi::c_void,
            ) -> $crate::Status {
                $crate::fmi3::set_fmu_state::<$M>(instance, state)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3FreeFMUState(
                instance: *mut ::std::ffi::c_void,
                state: *mut *mut ::std::ffi::c_void,
            ) -> $crate::Status {
                $crate::fmi3::free_fmu_state::<$M>(instance, state)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3SerializedFMUStateSize(
                instance: *mut ::std::ffi::c_void,
                state: *mut ::std::ffi::c_void,
                size: *mut usize,
            ) -> $crate::Status {
                $crate::fmi3::serialized_fmu_state_size::<$M>(instance, state, size)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3SerializeFMUState(
                instance: *mut ::std::ffi::c_void,
                state: *mut ::std::ffi::c_void,
                serialized_state: *mut u8,
                size: usize,
            ) -> $crate::Status {
                $crate::fmi3::serialize_fmu_state::<$M>(instance, state, serialized_state, size)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3DeserializeFMUState(
                instance: *mut ::std::ffi::c_void,
                serialized_state: *const u8,
                size: usize,
                state: *mut *mut ::std::ffi::c_void,
            ) -> $crate::Status {
                $crate::fmi3::deserialize_fmu_state::<$M>(instance, serialized_state, size, state)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetDirectionalDerivative(
                instance: *mut ::std::ffi::c_void,
                _unknowns: *const u32,
                _n_unknowns: usize,
                _knowns: *const u32,
                _n_knowns: usize,
                _seed: *const f64,
                _n_seed: usize,
                _sensitivity: *mut f64,
                _n_sensitivity: usize,
            ) -> $crate::Status {
                $crate::fmi3::unsupported::<$M>(instance, "fmi3GetDirectionalDerivative")
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetAdjointDerivative(
                instance: *mut ::std::ffi::c_void,
                _unknowns: *const u32,
                _n_unknowns: usize,
                _knowns: *const u32,
                _n_knowns: usize,
                _seed: *const f64,
                _n_seed: usize,
                _sensitivity: *mut f64,
                _n_sensitivity: usize,
            ) -> $crate::Status {
                $crate::fmi3::unsupported::<$M>(instance, "fmi3GetAdjointDerivative")
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3EnterConfigurationMode(instance: *mut ::std::ffi::c_void) -> $crate::Status {
                $crate::fmi3::unsupported::<$M>(instance, "fmi3EnterConfigurationMode")
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3ExitConfigurationMode(instance: *mut ::std::ffi::c_void) -> $crate::Status {
                $crate::fmi3::unsupported::<$M>(instance, "fmi3ExitConfigurationMode")
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetIntervalDecimal(
                instance: *mut ::std::ffi::c_void,
                _vrs: *const u32,
                _n_vr: usize,
                _intervals: *mut f64,
                _qualifiers: *mut ::std::ffi::c_int,
            ) -> $crate::Status {
                $crate::fmi3::unsupported::<$M>(instance, "fmi3GetIntervalDecimal")
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetIntervalFraction(
                instance: *mut ::std::ffi::c_void,
                _vrs: *const u32,
                _n_vr: usize,
                _counters: *mut u64,
                _resolutions: *mut u64,
                _qualifiers: *mut ::std::ffi::c_int,
            ) -> $crate::Status {
                $crate::fmi3::unsupported::<$M>(instance, "fmi3GetIntervalFraction")
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetShiftDecimal(
                instance: *mut ::std::ffi::c_void,
                _vrs: *const u32,
                _n_vr: usize,
                _shifts: *mut f64,
            ) -> $crate::Status {
                $crate::fmi3::unsupported::<$M>(instance, "fmi3GetShiftDecimal")
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetShiftFraction(
                instance: *mut ::std::ffi::c_void,
                _vrs: *const u32,
                _n_vr: usize,
                _counters: *mut u64,
                _resolutions: *mut u64,
            ) -> $crate::Status {
                $crate::fmi3::unsupported::<$M>(instance, "fmi3GetShiftFraction")
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3SetIntervalDecimal(
                instance: *mut ::std::ffi::c_void,
                _vrs: *const u32,
                _n_vr: usize,
                _intervals: *const f64,
            ) -> $crate::Status {
                $crate::fmi3::unsupported::<$M>(instance, "fmi3SetIntervalDecimal")
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3SetIntervalFraction(
                instance: *mut ::std::ffi::c_void,
                _vrs: *const u32,
                _n_vr: usize,
                _counters: *const u64,
                _resolutions: *const u64,
            ) -> $crate::Status {
                $crate::fmi3::unsupported::<$M>(instance, "fmi3SetIntervalFraction")
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3SetShiftDecimal(
                instance: *mut ::std::ffi::c_void,
                _vrs: *const u32,
                _n_vr: usize,
                _shifts: *const f64,
            ) -> $crate::Status {
                $crate::fmi3::unsupported::<$M>(instance, "fmi3SetShiftDecimal")
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3SetShiftFraction(
                instance: *mut ::std::ffi::c_void,
                _vrs: *const u32,
                _n_vr: usize,
                _counters: *const u64,
                _resolutions: *const u64,
            ) -> $crate::Status {
                $crate::fmi3::unsupported::<$M>(instance, "fmi3SetShiftFraction")
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3EvaluateDiscreteStates(instance: *mut ::std::ffi::c_void) -> $crate::Status {
                $crate::fmi3::unsupported::<$M>(instance, "fmi3EvaluateDiscreteStates")
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3UpdateDiscreteStates(
                instance: *mut ::std::ffi::c_void,
                discrete_states_need_update: *mut u8,
                terminate_simulation: *mut u8,
                nominals_of_continuous_states_changed: *mut u8,
                values_of_continuous_states_changed: *mut u8,
                next_event_time_defined: *mut u8,
                next_event_time: *mut f64,
            ) -> $crate::Status {
                $crate::fmi3::update_discrete_states::<$M>(
                    instance,
                    discrete_states_need_update,
                    terminate_simulation,
                    nominals_of_continuous_states_changed,
                    values_of_continuous_states_changed,
                    next_event_time_defined,
                    next_event_time,
                )
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3EnterContinuousTimeMode(instance: *mut ::std::ffi::c_void) -> $crate::Status {
                $crate::fmi3::enter_continuous_time_mode::<$M>(instance)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3CompletedIntegratorStep(
                instance: *mut ::std::ffi::c_void,
                no_set_fmu_state_prior_to_current_point: u8,
                enter_event_mode: *mut u8,
                terminate_simulation: *mut u8,
            ) -> $crate::Status {
                $crate::fmi3::completed_integrator_step::<$M>(
                    instance,
                    no_set_fmu_state_prior_to_current_point,
                    enter_event_mode,
                    terminate_simulation,
                )
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3SetTime(instance: *mut ::std::ffi::c_void, time: f64) -> $crate::Status {
                $crate::fmi3::set_time::<$M>(instance, time)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3SetContinuousStates(
                instance: *mut ::std::ffi::c_void,
                continuous_states: *const f64,
                n_continuous_states: usize,
            ) -> $crate::Status {
                $crate::fmi3::set_continuous_states::<$M>(instance, continuous_states, n_continuous_states)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetContinuousStateDerivatives(
                instance: *mut ::std::ffi::c_void,
                derivatives: *mut f64,
                n_continuous_states: usize,
            ) -> $crate::Status {
                $crate::fmi3::get_continuous_state_derivatives::<$M>(instance, derivatives, n_continuous_states)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetEventIndicators(
                instance: *mut ::std::ffi::c_void,
                event_indicators: *mut f64,
                n_event_indicators: usize,
            ) -> $crate::Status {
                $crate::fmi3::get_event_indicators::<$M>(instance, event_indicators, n_event_indicators)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetContinuousStates(
                instance: *mut ::std::ffi::c_void,
                continuous_states: *mut f64,
                n_continuous_states: usize,
            ) -> $crate::Status {
                $crate::fmi3::get_continuous_states::<$M>(instance, continuous_states, n_continuous_states)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetNominalsOfContinuousStates(
                instance: *mut ::std::ffi::c_void,
                nominals: *mut f64,
                n_continuous_states: usize,
            ) -> $crate::Status {
                $crate::fmi3::get_nominals_of_continuous_states::<$M>(instance, nominals, n_continuous_states)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetNumberOfEventIndicators(
                instance: *mut ::std::ffi::c_void,
                n_event_indicators: *mut usize,
            ) -> $crate::Status {
                $crate::fmi3::get_number_of_event_indicators::<$M>(instance, n_event_indicators)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetNumberOfContinuousStates(
                instance: *mut ::std::ffi::c_void,
                n_continuous_states: *mut usize,
            ) -> $crate::Status {
                $crate::fmi3::get_number_of_continuous_states::<$M>(instance, n_continuous_states)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3EnterStepMode(instance: *mut ::std::ffi::c_void) -> $crate::Status {
                $crate::fmi3::unsupported::<$M>(instance, "fmi3EnterStepMode")
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3GetOutputDerivatives(
                instance: *mut ::std::ffi::c_void,
                _vrs: *const u32,
                _n_vr: usize,
                _orders: *const i32,
                _values: *mut f64,
                _n_values: usize,
            ) -> $crate::Status {
                $crate::fmi3::unsupported::<$M>(instance, "fmi3GetOutputDerivatives")
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3DoStep(
                instance: *mut ::std::ffi::c_void,
                current_communication_point: f64,
                communication_step_size: f64,
                no_set_fmu_state_prior_to_current_point: u8,
                event_handling_needed: *mut u8,
                terminate_simulation: *mut u8,
                early_return: *mut u8,
                last_successful_time: *mut f64,
            ) -> $crate::Status {
                $crate::fmi3::do_step::<$M>(
                    instance,
                    current_communication_point,
                    communication_step_size,
                    no_set_fmu_state_prior_to_current_point,
                    event_handling_needed,
                    terminate_simulation,
                    early_return,
                    last_successful_time,
                )
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi3ActivateModelPartition(
                instance: *mut ::std::ffi::c_void,
                _clock_reference: u32,
                _activation_time: f64,
            ) -> $crate::Status {
                $crate::fmi3::unsupported::<$M>(instance, "fmi3ActivateModelPartition")
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2GetTypesPlatform() -> *const ::std::ffi::c_char {
                $crate::fmi2::get_types_platform()
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2GetVersion() -> *const ::std::ffi::c_char {
                $crate::fmi2::get_version()
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2SetDebugLogging(
                c: *mut ::std::ffi::c_void,
                logging_on: ::std::ffi::c_int,
                n_categories: usize,
                categories: *const *const ::std::ffi::c_char,
            ) -> $crate::Status {
                $crate::fmi2::set_debug_logging::<$M>(c, logging_on, n_categories, categories)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2Instantiate(
                instance_name: *const ::std::ffi::c_char,
                fmu_type: ::std::ffi::c_int,
                fmu_guid: *const ::std::ffi::c_char,
                fmu_resource_location: *const ::std::ffi::c_char,
                functions: *const $crate::fmi2::CallbackFunctions,
                visible: ::std::ffi::c_int,
                logging_on: ::std::ffi::c_int,
            ) -> *mut ::std::ffi::c_void {
                $crate::fmi2::instantiate::<$M>(
                    instance_name,
                    fmu_type,
                    fmu_guid,
                    fmu_resource_location,
                    functions,
                    visible,
                    logging_on,
                )
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2FreeInstance(c: *mut ::std::ffi::c_void) {
                $crate::fmi2::free_instance::<$M>(c)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2SetupExperiment(
                c: *mut ::std::ffi::c_void,
                tolerance_defined: ::std::ffi::c_int,
                tolerance: f64,
                start_time: f64,
                stop_time_defined: ::std::ffi::c_int,
                stop_time: f64,
            ) -> $crate::Status {
                $crate::fmi2::setup_experiment::<$M>(
                    c,
                    tolerance_defined,
                    tolerance,
                    start_time,
                    stop_time_defined,
                    stop_time,
                )
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2EnterInitializationMode(c: *mut ::std::ffi::c_void) -> $crate::Status {
                $crate::fmi2::enter_initialization_mode::<$M>(c)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2ExitInitializationMode(c: *mut ::std::ffi::c_void) -> $crate::Status {
                $crate::fmi2::exit_initialization_mode::<$M>(c)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2Terminate(c: *mut ::std::ffi::c_void) -> $crate::Status {
                $crate::fmi2::terminate::<$M>(c)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2Reset(c: *mut ::std::ffi::c_void) -> $crate::Status {
                $crate::fmi2::reset::<$M>(c)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2GetReal(
                c: *mut ::std::ffi::c_void,
                vr: *const u32,
                nvr: usize,
                value: *mut f64,
            ) -> $crate::Status {
                $crate::fmi2::get_real::<$M>(c, vr, nvr, value)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2GetInteger(
                c: *mut ::std::ffi::c_void,
                vr: *const u32,
                nvr: usize,
                value: *mut ::std::ffi::c_int,
            ) -> $crate::Status {
                $crate::fmi2::get_integer::<$M>(c, vr, nvr, value)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2GetBoolean(
                c: *mut ::std::ffi::c_void,
                vr: *const u32,
                nvr: usize,
                value: *mut ::std::ffi::c_int,
            ) -> $crate::Status {
                $crate::fmi2::get_boolean::<$M>(c, vr, nvr, value)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2GetString(
                c: *mut ::std::ffi::c_void,
                vr: *const u32,
                nvr: usize,
                value: *mut *const ::std::ffi::c_char,
            ) -> $crate::Status {
                $crate::fmi2::get_string::<$M>(c, vr, nvr, value)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2SetReal(
                c: *mut ::std::ffi::c_void,
                vr: *const u32,
                nvr: usize,
                value: *const f64,
            ) -> $crate::Status {
                $crate::fmi2::set_real::<$M>(c, vr, nvr, value)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2SetInteger(
                c: *mut ::std::ffi::c_void,
                vr: *const u32,
                nvr: usize,
                value: *const ::std::ffi::c_int,
            ) -> $crate::Status {
                $crate::fmi2::set_integer::<$M>(c, vr, nvr, value)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2SetBoolean(
                c: *mut ::std::ffi::c_void,
                vr: *const u32,
                nvr: usize,
                value: *const ::std::ffi::c_int,
            ) -> $crate::Status {
                $crate::fmi2::set_boolean::<$M>(c, vr, nvr, value)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2SetString(
                c: *mut ::std::ffi::c_void,
                vr: *const u32,
                nvr: usize,
                value: *const *const ::std::ffi::c_char,
            ) -> $crate::Status {
                $crate::fmi2::set_string::<$M>(c, vr, nvr, value)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2GetFMUstate(
                c: *mut ::std::ffi::c_void,
                state: *mut *mut ::std::ffi::c_void,
            ) -> $crate::Status {
                $crate::fmi2::get_fmu_state::<$M>(c, state)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2SetFMUstate(
                c: *mut ::std::ffi::c_void,
                state: *mut ::std::ffi::c_void,
            ) -> $crate::Status {
                $crate::fmi2::set_fmu_state::<$M>(c, state)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2FreeFMUstate(
                c: *mut ::std::ffi::c_void,
                state: *mut *mut ::std::ffi::c_void,
            ) -> $crate::Status {
                $crate::fmi2::free_fmu_state::<$M>(c, state)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
                c: *mut ::std::ffi::c_void,
                state: *mut ::std::ffi::c_void,
                size: *mut usize,
            ) -> $crate::Status {
                $crate::fmi2::serialized_fmu_state_size::<$M>(c, state, size)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2SerializeFMUstate(
                c: *mut ::std::ffi::c_void,
                state: *mut ::std::ffi::c_void,
                serialized_state: *mut ::std::ffi::c_char,
                size: usize,
            ) -> $crate::Status {
                $crate::fmi2::serialize_fmu_state::<$M>(c, state, serialized_state, size)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
                c: *mut ::std::ffi::c_void,
                serialized_state: *const ::std::ffi::c_char,
                size: usize,
                state: *mut *mut ::std::ffi::c_void,
            ) -> $crate::Status {
                $crate::fmi2::deserialize_fmu_state::<$M>(c, serialized_state, size, state)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
                c: *mut ::std::ffi::c_void,
                _v_unknown_ref: *const u32,
                _n_unknown: usize,
                _v_known_ref: *const u32,
                _n_known: usize,
                _dv_known: *const f64,
                _dv_unknown: *mut f64,
            ) -> $crate::Status {
                $crate::fmi2::unsupported::<$M>(c, "fmi2GetDirectionalDerivative")
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2EnterEventMode(c: *mut ::std::ffi::c_void) -> $crate::Status {
                $crate::fmi2::enter_event_mode::<$M>(c)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2NewDiscreteStates(
                c: *mut ::std::ffi::c_void,
                event_info: *mut $crate::fmi2::EventInfo,
            ) -> $crate::Status {
                $crate::fmi2::new_discrete_states::<$M>(c, event_info)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2EnterContinuousTimeMode(c: *mut ::std::ffi::c_void) -> $crate::Status {
                $crate::fmi2::enter_continuous_time_mode::<$M>(c)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2CompletedIntegratorStep(
                c: *mut ::std::ffi::c_void,
                no_set_fmu_state_prior_to_current_point: ::std::ffi::c_int,
                enter_event_mode: *mut ::std::ffi::c_int,
                terminate_simulation: *mut ::std::ffi::c_int,
            ) -> $crate::Status {
                $crate::fmi2::completed_integrator_step::<$M>(
                    c,
                    no_set_fmu_state_prior_to_current_point,
                    enter_event_mode,
                    terminate_simulation,
                )
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2SetTime(c: *mut ::std::ffi::c_void, time: f64) -> $crate::Status {
                $crate::fmi2::set_time::<$M>(c, time)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2SetContinuousStates(
                c: *mut ::std::ffi::c_void,
                x: *const f64,
                nx: usize,
            ) -> $crate::Status {
                $crate::fmi2::set_continuous_states::<$M>(c, x, nx)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2GetDerivatives(
                c: *mut ::std::ffi::c_void,
                derivatives: *mut f64,
                nx: usize,
            ) -> $crate::Status {
                $crate::fmi2::get_derivatives::<$M>(c, derivatives, nx)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2GetEventIndicators(
                c: *mut ::std::ffi::c_void,
                event_indicators: *mut f64,
                ni: usize,
            ) -> $crate::Status {
                $crate::fmi2::get_event_indicators::<$M>(c, event_indicators, ni)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2GetContinuousStates(
                c: *mut ::std::ffi::c_void,
                x: *mut f64,
                nx: usize,
            ) -> $crate::Status {
                $crate::fmi2::get_continuous_states::<$M>(c, x, nx)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2GetNominalsOfContinuousStates(
                c: *mut ::std::ffi::c_void,
                x_nominal: *mut f64,
                nx: usize,
            ) -> $crate::Status {
                $crate::fmi2::get_nominals_of_continuous_states::<$M>(c, x_nominal, nx)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
                c: *mut ::std::ffi::c_void,
                _vr: *const u32,
                _nvr: usize,
                _order: *const ::std::ffi::c_int,
                _value: *const f64,
            ) -> $crate::Status {
                $crate::fmi2::unsupported::<$M>(c, "fmi2SetRealInputDerivatives")
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
                c: *mut ::std::ffi::c_void,
                _vr: *const u32,
                _nvr: usize,
                _order: *const ::std::ffi::c_int,
                _value: *mut f64,
            ) -> $crate::Status {
                $crate::fmi2::unsupported::<$M>(c, "fmi2GetRealOutputDerivatives")
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2DoStep(
                c: *mut ::std::ffi::c_void,
                current_communication_point: f64,
                communication_step_size: f64,
                no_set_fmu_state_prior_to_current_point: ::std::ffi::c_int,
            ) -> $crate::Status {
                $crate::fmi2::do_step::<$M>(
                    c,
                    current_communication_point,
                    communication_step_size,
                    no_set_fmu_state_prior_to_current_point,
                )
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2CancelStep(c: *mut ::std::ffi::c_void) -> $crate::Status {
                $crate::fmi2::unsupported::<$M>(c, "fmi2CancelStep")
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2GetStatus(
                c: *mut ::std::ffi::c_void,
                kind: ::std::ffi::c_int,
                value: *mut $crate::Status,
            ) -> $crate::Status {
                $crate::fmi2::get_status::<$M>(c, kind, value)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2GetRealStatus(
                c: *mut ::std::ffi::c_void,
                kind: ::std::ffi::c_int,
                value: *mut f64,
            ) -> $crate::Status {
                $crate::fmi2::get_real_status::<$M>(c, kind, value)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2GetIntegerStatus(
                c: *mut ::std::ffi::c_void,
                kind: ::std::ffi::c_int,
                value: *mut ::std::ffi::c_int,
            ) -> $crate::Status {
                $crate::fmi2::get_integer_status::<$M>(c, kind, value)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2GetBooleanStatus(
                c: *mut ::std::ffi::c_void,
                kind: ::std::ffi::c_int,
                value: *mut ::std::ffi::c_int,
            ) -> $crate::Status {
                $crate::fmi2::get_boolean_status::<$M>(c, kind, value)
            }

            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn fmi2GetStringStatus(
                c: *mut ::std::ffi::c_void,
                kind: ::std::ffi::c_int,
                value: *mut *const ::std::ffi::c_char,
            ) -> $crate::Status {
                $crate::fmi2::get_string_status::<$M>(c, kind, value)
            }
        }
    };
}
