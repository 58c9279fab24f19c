//! One FMU shared library, loaded and with its co-simulation functions resolved.
//!
//! Function pointers are copied out of the library once; they stay valid exactly as long as
//! the `libloading::Library` in the same struct, which every [`super::Instance`] keeps alive
//! through an `Arc`. Loading the same file again (a second instance, or a second archive
//! unpacked to the same cache path) only bumps the dynamic loader's reference count.

use std::ffi::CStr;
use std::path::{Path, PathBuf};

use super::ffi;

/// Resolved FMI 3.0 co-simulation functions.
pub(crate) struct Functions {
    pub get_version: ffi::GetVersion,
    /// Co-simulation (absent from a model-exchange-only binary).
    pub instantiate_co_simulation: Option<ffi::InstantiateCoSimulation>,
    pub free_instance: ffi::FreeInstance,
    pub enter_initialization_mode: ffi::EnterInitializationMode,
    pub exit_initialization_mode: ffi::InstanceOnly,
    pub terminate: ffi::InstanceOnly,
    pub reset: ffi::InstanceOnly,
    pub do_step: Option<ffi::DoStep>,
    pub get_float64: ffi::Getter<f64>,
    pub set_float64: ffi::Setter<f64>,
    pub get_int32: ffi::Getter<i32>,
    pub set_int32: ffi::Setter<i32>,
    pub get_int64: ffi::Getter<i64>,
    pub set_int64: ffi::Setter<i64>,
    pub get_boolean: ffi::Getter<bool>,
    pub set_boolean: ffi::Setter<bool>,
    pub get_string: ffi::Getter<*const std::ffi::c_char>,
    pub set_string: ffi::Setter<*const std::ffi::c_char>,
    pub get_binary: ffi::GetBinary,
    pub set_binary: ffi::SetBinary,
    /// Required by FMI 3.0, but resolved as optional: an FMU without it still runs with
    /// debug logging as chosen at instantiation, and asking for more is refused up front.
    pub set_debug_logging: Option<ffi::SetDebugLogging>,
    /// Optional: only needed when the FMU declares canGetAndSetFMUState.
    pub get_fmu_state: Option<ffi::GetFmuState>,
    pub set_fmu_state: Option<ffi::SetFmuState>,
    pub free_fmu_state: Option<ffi::FreeFmuState>,
    /// Optional: only needed when the FMU declares canSerializeFMUState.
    pub serialized_fmu_state_size: Option<ffi::SerializedFmuStateSize>,
    pub serialize_fmu_state: Option<ffi::SerializeFmuState>,
    pub deserialize_fmu_state: Option<ffi::DeserializeFmuState>,
    /// Model exchange, when the binary exports all of it.
    pub me: Option<MeFunctions>,
}

pub(crate) struct MeFunctions {
    pub instantiate: ffi::InstantiateModelExchange,
    pub enter_event_mode: ffi::InstanceOnly,
    pub update_discrete_states: ffi::UpdateDiscreteStates,
    pub enter_continuous_time_mode: ffi::InstanceOnly,
    pub completed_integrator_step: ffi::CompletedIntegratorStep,
    pub set_time: ffi::SetTime,
    pub set_continuous_states: ffi::SetVector,
    pub get_derivatives: ffi::GetVector,
    pub get_event_indicators: ffi::GetVector,
    pub get_continuous_states: ffi::GetVector,
}

/// A loaded FMU binary.
pub struct Fmi3Library {
    pub(crate) f: Functions,
    path: PathBuf,
    // Last field: dropped (dlclose'd) after everything else.
    _lib: libloading::Library,
}

impl Fmi3Library {
    /// Loads `path` and resolves the functions. Errors are plain text (the caller adds the
    /// FMU and instance names): the dlopen failure, or the first missing symbol.
    /// The functions of `interface` are required; the other interface's are optional.
    pub fn load(path: &Path, interface: crate::model_description::Interface) -> Result<Fmi3Library, String> {
        let lib = crate::fmu::library::open(path)?;
        // SAFETY (both): each field's type below is the FMI 3.0 signature of its symbol.
        macro_rules! sym {
            ($name:literal) => {
                unsafe { crate::fmu::library::symbol(&lib, path, $name)? }
            };
        }
        macro_rules! opt_sym {
            ($name:literal) => {
                unsafe { crate::fmu::library::optional_symbol(&lib, $name) }
            };
        }
        let f = Functions {
            get_version: sym!("fmi3GetVersion"),
            instantiate_co_simulation: opt_sym!("fmi3InstantiateCoSimulation"),
            free_instance: sym!("fmi3FreeInstance"),
            enter_initialization_mode: sym!("fmi3EnterInitializationMode"),
            exit_initialization_mode: sym!("fmi3ExitInitializationMode"),
            terminate: sym!("fmi3Terminate"),
            reset: sym!("fmi3Reset"),
            do_step: opt_sym!("fmi3DoStep"),
            get_float64: sym!("fmi3GetFloat64"),
            set_float64: sym!("fmi3SetFloat64"),
            get_int32: sym!("fmi3GetInt32"),
            set_int32: sym!("fmi3SetInt32"),
            get_int64: sym!("fmi3GetInt64"),
            set_int64: sym!("fmi3SetInt64"),
            get_boolean: sym!("fmi3GetBoolean"),
            set_boolean: sym!("fmi3SetBoolean"),
            get_string: sym!("fmi3GetString"),
            set_string: sym!("fmi3SetString"),
            get_binary: sym!("fmi3GetBinary"),
            set_binary: sym!("fmi3SetBinary"),
            set_debug_logging: opt_sym!("fmi3SetDebugLogging"),
            get_fmu_state: opt_sym!("fmi3GetFMUState"),
            set_fmu_state: opt_sym!("fmi3SetFMUState"),
            free_fmu_state: opt_sym!("fmi3FreeFMUState"),
            serialized_fmu_state_size: opt_sym!("fmi3SerializedFMUStateSize"),
            serialize_fmu_state: opt_sym!("fmi3SerializeFMUState"),
            deserialize_fmu_state: opt_sym!("fmi3DeserializeFMUState"),
            me: (|| {
                Some(MeFunctions {
                    instantiate: opt_sym!("fmi3InstantiateModelExchange")?,
                    enter_event_mode: opt_sym!("fmi3EnterEventMode")?,
                    update_discrete_states: opt_sym!("fmi3UpdateDiscreteStates")?,
                    enter_continuous_time_mode: opt_sym!("fmi3EnterContinuousTimeMode")?,
                    completed_integrator_step: opt_sym!("fmi3CompletedIntegratorStep")?,
                    set_time: opt_sym!("fmi3SetTime")?,
                    set_continuous_states: opt_sym!("fmi3SetContinuousStates")?,
                    get_derivatives: opt_sym!("fmi3GetContinuousStateDerivatives")?,
                    get_event_indicators: opt_sym!("fmi3GetEventIndicators")?,
                    get_continuous_states: opt_sym!("fmi3GetContinuousStates")?,
                })
            })(),
        };
        let required: &[&str] = match interface {
            crate::model_description::Interface::CoSimulation => &["fmi3InstantiateCoSimulation", "fmi3DoStep"],
            crate::model_description::Interface::ModelExchange => &[
                "fmi3InstantiateModelExchange",
                "fmi3EnterEventMode",
                "fmi3UpdateDiscreteStates",
                "fmi3EnterContinuousTimeMode",
                "fmi3CompletedIntegratorStep",
                "fmi3SetTime",
                "fmi3SetContinuousStates",
                "fmi3GetContinuousStateDerivatives",
                "fmi3GetEventIndicators",
                "fmi3GetContinuousStates",
            ],
        };
        for name in required {
            // SAFETY: only checks that the symbol exists.
            if unsafe { lib.get::<*const ()>(name.as_bytes()) }.is_err() {
                return Err(format!("shared library '{}' does not export {name}", path.display()));
            }
        }
        Ok(Fmi3Library { f, path: path.to_path_buf(), _lib: lib })
    }

    /// What `fmi3GetVersion` returns (should be "3.0").
    pub fn version(&self) -> String {
        // SAFETY: resolved with the right signature; the result is a static C string or NULL.
        let p = unsafe { (self.f.get_version)() };
        if p.is_null() {
            return String::new();
        }
        unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
    }

    pub fn path(&self) -> &Path {
        &self.path
    }
}
