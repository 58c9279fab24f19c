//! Routes messages to the importer's logger callback (FMI 3 or FMI 2 flavour).
//!
//! Lazy: nothing is formatted or allocated unless a message is going to reach a callback.
//! Errors and warnings are always reported (they explain a returned status; FMI allows it
//! with logging off); debug messages (categories logModel, logCalls) only while debug logging
//! is on (`loggingOn` at instantiation, or SetDebugLogging) for their category. Without a
//! category list, logging on enables every category (FMI 3.0 section 2.3.5).

use std::ffi::{c_char, c_void, CStr, CString};
use std::fmt;

use crate::model::Log;
use crate::state::Status;

/// `fmi3LogMessageCallback`.
pub type Fmi3LogMessage =
    unsafe extern "C" fn(env: *mut c_void, status: Status, category: *const c_char, message: *const c_char);

/// `fmi2CallbackLogger` (printf-style: the message is a format string).
pub type Fmi2Logger = unsafe extern "C" fn(
    env: *mut c_void,
    instance_name: *const c_char,
    status: Status,
    category: *const c_char,
    message: *const c_char,
    ...
);

/// Log categories declared in modelDescription.xml (name, description).
pub const LOG_CATEGORIES: &[(&str, &str)] = &[
    ("logStatusWarning", "Warnings (always reported)"),
    ("logStatusError", "Errors: illegal calls, bad arguments, model failures (always reported)"),
    ("logModel", "Informational messages of the model"),
    ("logCalls", "Trace of FMI API calls"),
];

const CAT_MODEL: u8 = 1 << 2;
const CAT_CALLS: u8 = 1 << 3;

/// The category names as C strings, in [`LOG_CATEGORIES`] order.
const WARNING: &CStr = c"logStatusWarning";
const ERROR: &CStr = c"logStatusError";
const MODEL: &CStr = c"logModel";
const CALLS: &CStr = c"logCalls";

#[derive(Clone, Copy)]
enum Sink {
    Fmi3 { env: *mut c_void, cb: Option<Fmi3LogMessage> },
    Fmi2 { env: *mut c_void, cb: Option<Fmi2Logger> },
}

/// The logger of one instance.
pub struct Logger {
    sink: Sink,
    instance_name: CString,
    debug: bool,
    /// Bit i set = category `LOG_CATEGORIES[i]` enabled (only matters when `debug`).
    enabled: u8,
}

/// A C string of `message`; NUL (which C cannot carry) becomes U+FFFD, and for FMI 2 '%'
/// is doubled (its loggers treat the message as a printf format).
fn c_message(message: fmt::Arguments<'_>, printf: bool) -> CString {
    let mut text = fmt::format(message);
    if text.contains('\0') {
        text = text.replace('\0', "\u{FFFD}");
    }
    if printf && text.contains('%') {
        text = text.replace('%', "%%");
    }
    CString::new(text).unwrap_or_default()
}

fn c_string(s: &str) -> CString {
    CString::new(s.replace('\0', "\u{FFFD}")).unwrap_or_default()
}

impl Logger {
    pub fn fmi3(instance_name: &str, env: *mut c_void, cb: Option<Fmi3LogMessage>, debug: bool) -> Logger {
        Logger { sink: Sink::Fmi3 { env, cb }, instance_name: c_string(instance_name), debug, enabled: u8::MAX }
    }
    pub fn fmi2(instance_name: &str, env: *mut c_void, cb: Option<Fmi2Logger>, debug: bool) -> Logger {
        Logger { sink: Sink::Fmi2 { env, cb }, instance_name: c_string(instance_name), debug, enabled: u8::MAX }
    }

    pub fn instance_name(&self) -> &str {
        self.instance_name.to_str().unwrap_or("?")
    }

    /// Formats `message` and calls the callback; nothing happens without a callback.
    fn emit(&self, status: Status, category: &CStr, message: fmt::Arguments<'_>) {
        match self.sink {
            Sink::Fmi3 { env, cb: Some(cb) } => {
                let message = c_message(message, false);
                // SAFETY: the importer gave us this callback and environment for this instance.
                unsafe { cb(env, status, category.as_ptr(), message.as_ptr()) }
            }
            Sink::Fmi2 { env, cb: Some(cb) } => {
                let message = c_message(message, true);
                // SAFETY: as above; no variadic arguments are passed and none are referenced.
                unsafe { cb(env, self.instance_name.as_ptr(), status, category.as_ptr(), message.as_ptr()) }
            }
            _ => {}
        }
    }

    /// True when debug messages of the category bit `cat` are wanted.
    fn debug_enabled(&self, cat: u8) -> bool {
        self.debug && self.enabled & cat != 0
    }

    pub fn error(&self, message: &str) {
        self.emit(Status::Error, ERROR, format_args!("{message}"));
    }
    pub fn fatal(&self, message: &str) {
        self.emit(Status::Fatal, ERROR, format_args!("{message}"));
    }
    pub fn warn(&self, message: &str) {
        self.emit(Status::Warning, WARNING, format_args!("{message}"));
    }
    /// Trace of an API call, if enabled.
    pub fn call(&self, function: &str) {
        if self.debug_enabled(CAT_CALLS) {
            self.emit(Status::Ok, CALLS, format_args!("{function}"));
        }
    }

    /// `SetDebugLogging`: `categories` empty = all. Returns the unknown category names.
    pub fn set_debug_logging(&mut self, on: bool, categories: &[&CStr]) -> Vec<String> {
        self.debug = on;
        if categories.is_empty() {
            self.enabled = u8::MAX;
            return Vec::new();
        }
        let mut unknown = Vec::new();
        self.enabled = 0;
        for c in categories {
            let name = c.to_string_lossy();
            match LOG_CATEGORIES.iter().position(|(n, _)| *n == name) {
                Some(i) => self.enabled |= 1 << i,
                None => unknown.push(name.into_owned()),
            }
        }
        unknown
    }
}

/// What the model sees: `info` goes to category logModel (formatted only when that category
/// is on), `warning` is always reported.
impl Log for Logger {
    fn info(&mut self, message: fmt::Arguments<'_>) {
        if self.debug_enabled(CAT_MODEL) {
            self.emit(Status::Ok, MODEL, message);
        }
    }
    fn warning(&mut self, message: fmt::Arguments<'_>) {
        self.emit(Status::Warning, WARNING, message);
    }
}
