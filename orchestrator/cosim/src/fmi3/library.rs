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
    pub instantiate_co_simulation: ffi::InstantiateCoSimulation,
    pub free_instance: ffi::FreeInstance,
    pub enter_initialization_mode: ffi::EnterInitializationMode,
    pub exit_initialization_mode: ffi::InstanceOnly,
    pub terminate: ffi::InstanceOnly,
    pub reset: ffi::InstanceOnly,
    pub do_step: ffi::DoStep,
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
    pub fn load(path: &Path) -> Result<Fmi3Library, String> {
        // SAFETY: loading runs the library's initialisers; FMU binaries are trusted code by
        // the nature of co-simulation. RTLD_LOCAL keeps two FMUs' identical fmi3* symbols apart.
        let lib: libloading::Library = unsafe {
            #[cfg(unix)]
            {
                use libloading::os::unix::{Library, RTLD_LOCAL, RTLD_NOW};
                Library::open(Some(path), RTLD_NOW | RTLD_LOCAL).map(Into::into)
            }
            #[cfg(not(unix))]
            {
                libloading::Library::new(path)
            }
        }
        .map_err(|e| format!("cannot load shared library '{}': {e}", path.display()))?;

        macro_rules! sym {
            ($name:literal) => {
                // SAFETY: the type is the FMI 3.0 signature of this symbol.
                match unsafe { lib.get(concat!($name, "\0").as_bytes()) } {
                    Ok(s) => *s,
                    Err(_) => return Err(format!("shared library '{}' does not export {}", path.display(), $name)),
                }
            };
        }
        macro_rules! opt_sym {
            ($name:literal) => {
                // SAFETY: as above.
                unsafe { lib.get(concat!($name, "\0").as_bytes()) }.ok().map(|s| *s)
            };
        }
        let f = Functions {
            get_version: sym!("fmi3GetVersion"),
            instantiate_co_simulation: sym!("fmi3InstantiateCoSimulation"),
            free_instance: sym!("fmi3FreeInstance"),
            enter_initialization_mode: sym!("fmi3EnterInitializationMode"),
            exit_initialization_mode: sym!("fmi3ExitInitializationMode"),
            terminate: sym!("fmi3Terminate"),
            reset: sym!("fmi3Reset"),
            do_step: sym!("fmi3DoStep"),
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
        };
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
