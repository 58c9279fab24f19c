//! The entry guard every instance function runs through: pointer validation, panic
//! containment, the allowed-call mask, logging and the move to Error/Fatal on failure.

use std::any::TypeId;
use std::ffi::c_void;
use std::panic::{catch_unwind, AssertUnwindSafe};

use crate::instance::{panic_message, Instance};
use crate::model::{is_model_exchange, Model};
use crate::registry::{self, Api};
use crate::state::{mask_names, Mask, Mode, Status, CONTINUOUS_TIME, EVENT, STEP};

/// Why a call failed: the status to return and the message to log.
#[derive(Debug)]
pub struct Failure {
    pub status: Status,
    pub message: String,
}

impl Failure {
    pub fn fatal(message: impl Into<String>) -> Failure {
        Failure { status: Status::Fatal, message: message.into() }
    }
}

impl From<String> for Failure {
    fn from(message: String) -> Failure {
        Failure { status: Status::Error, message }
    }
}

impl From<&str> for Failure {
    fn from(message: &str) -> Failure {
        Failure { status: Status::Error, message: message.to_string() }
    }
}

/// Runs `f` on the instance behind `ptr` if `ptr` is a live `M` instance of `api` and its
/// mode is in `mask`. Failures are logged as "`function`: reason"; Error moves the instance
/// to [`Mode::Error`], Fatal to [`Mode::Fatal`]; a panic counts as Error. An invalid handle
/// returns Error without logging (there is no logger to reach).
///
/// # Safety
/// `ptr` may be anything; it is only dereferenced after the registry confirms it.
pub unsafe fn with_instance<M: Model>(
    api: Api,
    ptr: *mut c_void,
    function: &str,
    mask: Mask,
    f: impl FnOnce(&mut Instance<M>) -> Result<Status, Failure>,
) -> Status {
    if ptr.is_null() || !registry::contains(ptr as usize, TypeId::of::<M>(), api) {
        return Status::Error;
    }
    let inst = ptr.cast::<Instance<M>>();
    let result = catch_unwind(AssertUnwindSafe(|| {
        // SAFETY: the registry holds exactly the live instances of this type and API.
        let inst = unsafe { &mut *inst };
        inst.logger.call(function);
        if inst.mode == Mode::Fatal {
            return Err(Failure::fatal("the instance is in the Fatal state; only FreeInstance may be called"));
        }
        if mask & inst.mode.bit() == 0 {
            // Name only the modes of this FMU's interface (step vs event/continuous time).
            let other = if is_model_exchange::<M>() { STEP } else { EVENT | CONTINUOUS_TIME };
            return Err(Failure::from(format!(
                "must not be called in mode {} (allowed in: {})",
                inst.mode.name(),
                mask_names(mask & !other)
            )));
        }
        f(inst)
    }));
    // SAFETY: as above; the closure's borrow has ended.
    let inst = unsafe { &mut *inst };
    let failure = match result {
        Ok(Ok(status)) => return status,
        Ok(Err(failure)) => failure,
        Err(payload) => Failure::from(format!("the model panicked: {}", panic_message(&*payload))),
    };
    // Logging and the mode change must not unwind either (a logger callback cannot panic,
    // but formatting could in theory); ignore a second panic.
    let _ = catch_unwind(AssertUnwindSafe(|| {
        let message = format!("{function}: {}", failure.message);
        match failure.status {
            Status::Fatal => {
                inst.logger.fatal(&message);
                inst.mode = Mode::Fatal;
            }
            Status::Error => {
                inst.logger.error(&message);
                if inst.mode != Mode::Fatal {
                    inst.mode = Mode::Error;
                }
            }
            _ => inst.logger.warn(&message),
        }
    }));
    failure.status
}

/// A function this FMU does not support: always Error (Fatal in Fatal), logged with `why`.
///
/// # Safety
/// As [`with_instance`].
pub unsafe fn unsupported<M: Model>(api: Api, ptr: *mut c_void, function: &str, why: &str) -> Status {
    with_instance::<M>(api, ptr, function, Mask::MAX, |_| {
        Err(Failure::from(format!("not supported by this FMU: {why}")))
    })
}

/// `ptr[..n]` as a slice; NULL is accepted only for `n == 0`.
///
/// # Safety
/// A non-NULL `ptr` must point to `n` readable elements.
pub unsafe fn slice<'a, T>(ptr: *const T, n: usize, what: &str) -> Result<&'a [T], Failure> {
    if n == 0 {
        return Ok(&[]);
    }
    if ptr.is_null() {
        return Err(format!("{what} is NULL but its length is {n}").into());
    }
    if n > isize::MAX as usize / std::mem::size_of::<T>().max(1) {
        return Err(format!("{what}: length {n} is impossible").into());
    }
    Ok(std::slice::from_raw_parts(ptr, n))
}

/// Mutable counterpart of [`slice`].
///
/// # Safety
/// A non-NULL `ptr` must point to `n` writable elements.
pub unsafe fn slice_mut<'a, T>(ptr: *mut T, n: usize, what: &str) -> Result<&'a mut [T], Failure> {
    if n == 0 {
        return Ok(&mut []);
    }
    if ptr.is_null() {
        return Err(format!("{what} is NULL but its length is {n}").into());
    }
    if n > isize::MAX as usize / std::mem::size_of::<T>().max(1) {
        return Err(format!("{what}: length {n} is impossible").into());
    }
    Ok(std::slice::from_raw_parts_mut(ptr, n))
}

/// A required output pointer.
///
/// # Safety
/// A non-NULL `ptr` must be writable.
pub unsafe fn out<'a, T>(ptr: *mut T, what: &str) -> Result<&'a mut T, Failure> {
    ptr.as_mut().ok_or_else(|| Failure::from(format!("{what} is NULL")))
}

/// Registers a new instance and returns its handle.
pub fn publish<M: Model>(inst: Instance<M>) -> *mut c_void {
    let api = inst.api;
    let p = Box::into_raw(Box::new(inst)).cast::<c_void>();
    registry::insert(p as usize, TypeId::of::<M>(), api);
    p
}

/// Unregisters and drops an instance; unknown handles are ignored.
///
/// # Safety
/// `ptr` may be anything; it is only freed if registered.
pub unsafe fn free<M: Model>(api: Api, ptr: *mut c_void) {
    if ptr.is_null() || !registry::remove(ptr as usize, TypeId::of::<M>(), api) {
        return;
    }
    let _ = catch_unwind(AssertUnwindSafe(|| drop(Box::from_raw(ptr.cast::<Instance<M>>()))));
}
