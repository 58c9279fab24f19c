//! `fmi3Status`, and what `fmi3DoStep` returns besides it.

use std::fmt;

/// Ordered by severity, so `status >= Status::Discard` means "the call did not do its job".
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Status {
    Ok,
    Warning,
    Discard,
    Error,
    Fatal,
}

impl Status {
    /// An out-of-range value means the FMU is broken beyond trust: treated as Fatal.
    pub fn from_raw(raw: std::ffi::c_int) -> Status {
        match raw {
            0 => Status::Ok,
            1 => Status::Warning,
            2 => Status::Discard,
            3 => Status::Error,
            _ => Status::Fatal,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Status::Ok => "fmi3OK",
            Status::Warning => "fmi3Warning",
            Status::Discard => "fmi3Discard",
            Status::Error => "fmi3Error",
            Status::Fatal => "fmi3Fatal",
        }
    }
}

impl fmt::Display for Status {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Flags returned by `fmi3DoStep` (also carried by the error of a discarded step).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepResult {
    pub event_handling_needed: bool,
    pub terminate_simulation: bool,
    pub early_return: bool,
    pub last_successful_time: f64,
}
