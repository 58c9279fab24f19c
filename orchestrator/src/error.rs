//! One error type for the orchestrator: a message that names the file, FMU, variable or
//! message at fault. Every lower-level error converts into it with its context kept.

use std::fmt;

#[derive(Debug, Clone, PartialEq)]
pub struct Error(pub String);

pub type Result<T, E = Error> = std::result::Result<T, E>;

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Error {}

/// `err!("...")` builds an [`Error`] from a format string.
#[macro_export]
macro_rules! err {
    ($($arg:tt)*) => { $crate::error::Error(format!($($arg)*)) };
}

macro_rules! from_display {
    ($($t:ty),*) => { $( impl From<$t> for Error { fn from(e: $t) -> Self { Error(e.to_string()) } } )* };
}
from_display!(crate::fmi3::FmiError, crate::archive::ImportError, crate::model_description::ModelDescriptionError, crate::ssp::SspError);

/// Adds context ("while doing X") in front of an error.
pub trait Context<T> {
    fn context(self, what: impl FnOnce() -> String) -> Result<T>;
}

impl<T, E: fmt::Display> Context<T> for std::result::Result<T, E> {
    fn context(self, what: impl FnOnce() -> String) -> Result<T> {
        self.map_err(|e| Error(format!("{}: {e}", what())))
    }
}
