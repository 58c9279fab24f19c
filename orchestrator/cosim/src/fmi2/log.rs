//! The FMI 2.0 logger: `logger.c` formats the variadic message and calls [`sink`] with the
//! [`Env`] the instance passed as `componentEnvironment`; messages land in the same
//! per-instance [`LogSink`] as FMI 3's.

use std::ffi::{c_char, c_int, c_void, CStr};

use crate::fmu::log::LogSink;
use crate::fmu::{LogMessage, Status};

extern "C" {
    /// `fmi2CallbackLogger`, defined in logger.c.
    pub(crate) fn agrisim_cosim_fmi2_logger(
        env: *mut c_void,
        instance_name: *const c_char,
        status: c_int,
        category: *const c_char,
        message: *const c_char,
        ...
    );
    fn calloc(n: usize, size: usize) -> *mut c_void;
    fn free(p: *mut c_void);
}

/// `componentEnvironment`: what logger.c calls back with (layout shared with logger.c).
#[repr(C)]
pub(crate) struct Env {
    sink: unsafe extern "C" fn(*mut c_void, c_int, *const c_char, *const c_char),
    ctx: *const LogSink,
}

impl Env {
    pub(crate) fn new(sink: &LogSink) -> Env {
        Env { sink: push, ctx: sink }
    }
}

unsafe fn lossy(p: *const c_char) -> String {
    if p.is_null() {
        String::new()
    } else {
        CStr::from_ptr(p).to_string_lossy().into_owned()
    }
}

unsafe extern "C" fn push(ctx: *mut c_void, status: c_int, category: *const c_char, message: *const c_char) {
    // Nothing may unwind into the FMU.
    let _ = std::panic::catch_unwind(|| {
        if ctx.is_null() {
            return;
        }
        // SAFETY: ctx is the LogSink boxed by the instance, which outlives the FMU instance.
        let sink = &*(ctx as *const LogSink);
        sink.push(LogMessage { status: Status::from_raw(status), category: lossy(category), message: lossy(message) });
    });
}

/// `allocateMemory`: FMI 2.0 wants calloc semantics.
pub(crate) unsafe extern "C" fn allocate(n: usize, size: usize) -> *mut c_void {
    calloc(n, size)
}

pub(crate) unsafe extern "C" fn release(p: *mut c_void) {
    free(p)
}
