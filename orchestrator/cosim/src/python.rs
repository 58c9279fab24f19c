//! An embedded Python for FMUs that need one. pythonfmu's binary calls Python's C API but
//! does not link libpython: a Python process provides the symbols, any other host must load
//! libpython globally and make the FMU's Python packages importable. This does that once per
//! process, so a user swaps a pythonfmu model in without LD_PRELOAD or PYTHONHOME.
//!
//! The interpreter is the first of: `$AGRISIM_PYTHON`; `$VIRTUAL_ENV/bin/python`; a `.venv`
//! beside or above the running program (agrisim's own, which has pythonfmu); `python3` on
//! PATH. It is asked where its libpython is and what its `sys.path` is; that libpython is
//! loaded with RTLD_GLOBAL, initialized when nobody has yet (never inside a Python process,
//! which already is), given that `sys.path`, and its GIL released so the FMU can take it from
//! any thread.

use std::ffi::{c_char, c_int, c_void, CString};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// Whether a dlopen error means the binary wants Python's C API from the host.
pub(crate) fn needs_python(dlopen_error: &str) -> bool {
    dlopen_error.contains("undefined symbol: Py") || dlopen_error.contains("undefined symbol: _Py")
}

/// Loads and initializes the embedded Python once; later calls return the first outcome.
pub(crate) fn ensure() -> Result<(), String> {
    static DONE: OnceLock<Result<(), String>> = OnceLock::new();
    DONE.get_or_init(start).clone()
}

fn interpreter() -> PathBuf {
    if let Some(p) = std::env::var_os("AGRISIM_PYTHON") {
        return PathBuf::from(p);
    }
    if let Some(v) = std::env::var_os("VIRTUAL_ENV") {
        let p = Path::new(&v).join("bin/python");
        if p.is_file() {
            return p;
        }
    }
    if let Ok(exe) = std::env::current_exe() {
        for dir in exe.ancestors().skip(1) {
            let p = dir.join(".venv/bin/python");
            if p.is_file() {
                return p;
            }
        }
    }
    PathBuf::from("python3")
}

/// Prints libpython's path, then one `sys.path` entry per line.
const PROBE: &str = "import os, sys, sysconfig
d = sysconfig.get_config_var('LIBDIR') or ''
n = sysconfig.get_config_var('INSTSONAME') or sysconfig.get_config_var('LDLIBRARY') or ''
print(os.path.join(d, n))
for p in sys.path:
    if p:
        print(p)";

fn start() -> Result<(), String> {
    let python = interpreter();
    let out = std::process::Command::new(&python)
        .args(["-c", PROBE])
        .output()
        .map_err(|e| format!("cannot run Python '{}' (set AGRISIM_PYTHON): {e}", python.display()))?;
    if !out.status.success() {
        return Err(format!("Python '{}' failed: {}", python.display(), String::from_utf8_lossy(&out.stderr).trim()));
    }
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    let mut lines = text.lines();
    let lib_path = lines.next().unwrap_or_default().to_string();
    let sys_path: Vec<&str> = lines.collect();
    // SAFETY: loading libpython runs its initialisers, which only set up static data.
    let lib = unsafe {
        libloading::os::unix::Library::open(
            Some(&lib_path),
            libloading::os::unix::RTLD_NOW | libloading::os::unix::RTLD_GLOBAL,
        )
    }
    .map_err(|e| format!("Python '{}': cannot load its libpython '{lib_path}': {e}", python.display()))?;
    macro_rules! f {
        ($name:literal, $t:ty) => {
            // SAFETY: the type is the C API's signature of this symbol.
            *unsafe { lib.get::<$t>(concat!($name, "\0").as_bytes()) }
                .map_err(|e| format!("libpython '{lib_path}' lacks {}: {e}", $name))?
        };
    }
    let is_initialized = f!("Py_IsInitialized", unsafe extern "C" fn() -> c_int);
    let initialize = f!("Py_InitializeEx", unsafe extern "C" fn(c_int));
    let run = f!("PyRun_SimpleString", unsafe extern "C" fn(*const c_char) -> c_int);
    let save_thread = f!("PyEval_SaveThread", unsafe extern "C" fn() -> *mut c_void);
    let gil_ensure = f!("PyGILState_Ensure", unsafe extern "C" fn() -> c_int);
    let gil_release = f!("PyGILState_Release", unsafe extern "C" fn(c_int));
    let entries: Vec<String> = sys_path.iter().map(|p| format!("{p:?}")).collect();
    let code = format!(
        "import sys\nfor _p in reversed([{}]):\n    if _p not in sys.path:\n        sys.path.insert(0, _p)\n",
        entries.join(", ")
    );
    let code = CString::new(code).map_err(|_| "a sys.path entry contains a NUL byte".to_string())?;
    // SAFETY: the C API used as documented: initialize once (not inside a running Python),
    // run code holding the GIL, release the GIL for the FMU's own PyGILState_Ensure.
    unsafe {
        if is_initialized() == 0 {
            initialize(0);
            let rc = run(code.as_ptr());
            save_thread();
            if rc != 0 {
                return Err("setting sys.path in the embedded Python failed".into());
            }
        } else {
            let g = gil_ensure();
            let rc = run(code.as_ptr());
            gil_release(g);
            if rc != 0 {
                return Err("setting sys.path in the running Python failed".into());
            }
        }
    }
    // libpython stays loaded for the life of the process (the FMUs need it until exit).
    std::mem::forget(lib);
    Ok(())
}
