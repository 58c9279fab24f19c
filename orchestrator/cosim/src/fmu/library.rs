//! Opening an FMU's shared library, the same way for every FMI version.

use std::path::Path;

/// Opens an FMU binary: now (every symbol resolved up front) and locally, so two FMUs'
/// identical `fmi*` symbols stay apart. A binary that leaves Python's C API unresolved
/// (pythonfmu's) gets an embedded Python first ([`crate::python`]).
pub(crate) fn open(path: &Path) -> Result<libloading::Library, String> {
    let fail = |e: libloading::Error| format!("cannot load shared library '{}': {}", path.display(), describe(&e));
    match dlopen(path) {
        Ok(lib) => Ok(lib),
        Err(e) if crate::python::needs_python(&describe(&e)) => {
            crate::python::ensure()
                .map_err(|why| format!("{}; it needs an embedded Python, which failed: {why}", fail(e)))?;
            dlopen(path).map_err(fail)
        }
        Err(e) => Err(fail(e)),
    }
}

/// A symbol every FMU of its version must export; the error names the binary and symbol.
///
/// # Safety
/// `T` must be the standard's C signature of `name`.
pub(crate) unsafe fn symbol<T: Copy>(lib: &libloading::Library, path: &Path, name: &str) -> Result<T, String> {
    // SAFETY: as the caller promises.
    match unsafe { lib.get::<T>(name.as_bytes()) } {
        Ok(s) => Ok(*s),
        Err(_) => Err(format!("shared library '{}' does not export {name}", path.display())),
    }
}

/// A symbol an FMU exports only for the capabilities it declares.
///
/// # Safety
/// As for [`symbol`].
pub(crate) unsafe fn optional_symbol<T: Copy>(lib: &libloading::Library, name: &str) -> Option<T> {
    // SAFETY: as the caller promises.
    unsafe { lib.get::<T>(name.as_bytes()) }.ok().map(|s| *s)
}

fn dlopen(path: &Path) -> Result<libloading::Library, libloading::Error> {
    // SAFETY: loading runs the library's initialisers; FMU binaries are trusted code by the
    // nature of co-simulation.
    unsafe {
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
}

/// The loader's own words (libloading's Display alone says only "dlopen failed").
fn describe(e: &libloading::Error) -> String {
    match std::error::Error::source(e) {
        Some(why) => format!("{e}: {why}"),
        None => e.to_string(),
    }
}
