//! One FMI 2.0 shared library, loaded and with its functions resolved. Function pointers
//! stay valid as long as the `libloading::Library` in the same struct, which every instance
//! keeps alive. Functions of the interface that is not used may be missing: a
//! co-simulation-only binary has no `fmi2SetTime`.

use std::ffi::CStr;
use std::path::{Path, PathBuf};

use super::ffi;
use crate::model_description::Interface;

pub(crate) struct Functions {
    pub get_version: ffi::GetString,
    pub instantiate: ffi::Instantiate,
    pub free_instance: ffi::FreeInstance,
    pub set_debug_logging: Option<ffi::SetDebugLogging>,
    pub setup_experiment: ffi::SetupExperiment,
    pub enter_initialization_mode: ffi::ComponentOnly,
    pub exit_initialization_mode: ffi::ComponentOnly,
    pub terminate: ffi::ComponentOnly,
    pub reset: ffi::ComponentOnly,
    pub get_real: ffi::Getter<f64>,
    pub set_real: ffi::Setter<f64>,
    pub get_integer: ffi::Getter<i32>,
    pub set_integer: ffi::Setter<i32>,
    pub get_boolean: ffi::Getter<ffi::Fmi2Boolean>,
    pub set_boolean: ffi::Setter<ffi::Fmi2Boolean>,
    pub get_string: ffi::Getter<*const std::ffi::c_char>,
    pub set_string: ffi::Setter<*const std::ffi::c_char>,
    pub get_fmu_state: Option<ffi::GetFmuState>,
    pub set_fmu_state: Option<ffi::SetFmuState>,
    pub free_fmu_state: Option<ffi::FreeFmuState>,
    pub serialized_fmu_state_size: Option<ffi::SerializedFmuStateSize>,
    pub serialize_fmu_state: Option<ffi::SerializeFmuState>,
    pub deserialize_fmu_state: Option<ffi::DeSerializeFmuState>,
    /// Co-simulation.
    pub do_step: Option<ffi::DoStep>,
    pub get_boolean_status: Option<ffi::GetBooleanStatus>,
    pub get_real_status: Option<ffi::GetRealStatus>,
    /// Model exchange.
    pub me: Option<MeFunctions>,
}

pub(crate) struct MeFunctions {
    pub enter_event_mode: ffi::ComponentOnly,
    pub new_discrete_states: ffi::NewDiscreteStates,
    pub enter_continuous_time_mode: ffi::ComponentOnly,
    pub completed_integrator_step: ffi::CompletedIntegratorStep,
    pub set_time: ffi::SetTime,
    pub set_continuous_states: ffi::SetVector,
    pub get_derivatives: ffi::GetVector,
    pub get_event_indicators: ffi::GetVector,
    pub get_continuous_states: ffi::GetVector,
}

/// A loaded FMI 2.0 binary.
pub struct Fmi2Library {
    pub(crate) f: Functions,
    path: PathBuf,
    _lib: libloading::Library,
}

impl Fmi2Library {
    /// Loads `path` (now, locally; pythonfmu binaries get an embedded Python) and resolves the functions
    /// `interface` needs.
    pub fn load(path: &Path, interface: Interface) -> Result<Fmi2Library, String> {
        let lib = crate::fmu::library::open(path)?;
        // SAFETY (both): each field's type below is the FMI 2.0 signature of its symbol.
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
        let me = match interface {
            Interface::CoSimulation => None,
            Interface::ModelExchange => Some(MeFunctions {
                enter_event_mode: sym!("fmi2EnterEventMode"),
                new_discrete_states: sym!("fmi2NewDiscreteStates"),
                enter_continuous_time_mode: sym!("fmi2EnterContinuousTimeMode"),
                completed_integrator_step: sym!("fmi2CompletedIntegratorStep"),
                set_time: sym!("fmi2SetTime"),
                set_continuous_states: sym!("fmi2SetContinuousStates"),
                get_derivatives: sym!("fmi2GetDerivatives"),
                get_event_indicators: sym!("fmi2GetEventIndicators"),
                get_continuous_states: sym!("fmi2GetContinuousStates"),
            }),
        };
        let do_step = match interface {
            Interface::CoSimulation => Some(sym!("fmi2DoStep")),
            Interface::ModelExchange => None,
        };
        let f = Functions {
            get_version: sym!("fmi2GetVersion"),
            instantiate: sym!("fmi2Instantiate"),
            free_instance: sym!("fmi2FreeInstance"),
            set_debug_logging: opt_sym!("fmi2SetDebugLogging"),
            setup_experiment: sym!("fmi2SetupExperiment"),
            enter_initialization_mode: sym!("fmi2EnterInitializationMode"),
            exit_initialization_mode: sym!("fmi2ExitInitializationMode"),
            terminate: sym!("fmi2Terminate"),
            reset: sym!("fmi2Reset"),
            get_real: sym!("fmi2GetReal"),
            set_real: sym!("fmi2SetReal"),
            get_integer: sym!("fmi2GetInteger"),
            set_integer: sym!("fmi2SetInteger"),
            get_boolean: sym!("fmi2GetBoolean"),
            set_boolean: sym!("fmi2SetBoolean"),
            get_string: sym!("fmi2GetString"),
            set_string: sym!("fmi2SetString"),
            get_fmu_state: opt_sym!("fmi2GetFMUstate"),
            set_fmu_state: opt_sym!("fmi2SetFMUstate"),
            free_fmu_state: opt_sym!("fmi2FreeFMUstate"),
            serialized_fmu_state_size: opt_sym!("fmi2SerializedFMUstateSize"),
            serialize_fmu_state: opt_sym!("fmi2SerializeFMUstate"),
            deserialize_fmu_state: opt_sym!("fmi2DeSerializeFMUstate"),
            do_step,
            get_boolean_status: opt_sym!("fmi2GetBooleanStatus"),
            get_real_status: opt_sym!("fmi2GetRealStatus"),
            me,
        };
        Ok(Fmi2Library { f, path: path.to_path_buf(), _lib: lib })
    }

    /// What `fmi2GetVersion` returns (should be "2.0").
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
