use std::ffi::{c_char, c_void};

use agrisim_fmi::logger::Fmi2Logger;
use agrisim_fmi::Status;

/// Log messages received through the logger callback of the current case.
#[derive(Default)]
pub(crate) struct Logs(pub(crate) Vec<(Status, String)>);

pub(crate) unsafe extern "C" fn log3(
    env: *mut c_void,
    status: Status,
    _category: *const c_char,
    message: *const c_char,
) {
    let logs = &mut *(env as *mut Logs);
    logs.0.push((status, std::ffi::CStr::from_ptr(message).to_string_lossy().into_owned()));
}

unsafe extern "C" fn log2_fixed(
    env: *mut c_void,
    _name: *const c_char,
    status: Status,
    category: *const c_char,
    message: *const c_char,
) {
    log3(env, status, category, message)
}

/// A non-variadic function called through the variadic `fmi2CallbackLogger` type (what
/// every non-C importer does; no variadic arguments are ever passed).
pub(crate) fn log2() -> Fmi2Logger {
    // SAFETY: identical fixed arguments; the FMU passes no variadic arguments.
    unsafe {
        std::mem::transmute::<
            unsafe extern "C" fn(*mut c_void, *const c_char, Status, *const c_char, *const c_char),
            Fmi2Logger,
        >(log2_fixed)
    }
}
