//! [`FmiError`]: everything needed to understand a failed FMU call from one line.

use std::fmt;

use super::log::LogMessage;
use super::status::Status;

/// A failed call on an FMU instance (or a call the wrapper refused / could not make).
/// Boxed so `Result<(), FmiError>` stays one word on the per-step get/set path; the fields
/// are reached through `Deref` (`err.status`, `err.messages`, ...).
#[derive(Clone, Debug, PartialEq)]
pub struct FmiError(Box<FmiErrorInfo>);

/// The contents of an [`FmiError`].
#[derive(Clone, Debug, PartialEq)]
pub struct FmiErrorInfo {
    /// Instance name given at instantiation (the SSP component name).
    pub instance: String,
    /// `modelName` of the FMU.
    pub model: String,
    /// The fmi3 function (e.g. `fmi3DoStep`) or the loading step that failed.
    pub function: String,
    /// Extra call context, e.g. `at t=1.24`.
    pub context: Option<String>,
    /// Names of the variables involved (resolved from the value references).
    pub variables: Vec<String>,
    /// Status returned by the FMU; `None` when the wrapper itself refused or failed.
    pub status: Option<Status>,
    /// The wrapper's own reason, when it has one.
    pub detail: Option<String>,
    /// What the FMU logged during this call.
    pub messages: Vec<LogMessage>,
}

impl From<FmiErrorInfo> for FmiError {
    fn from(info: FmiErrorInfo) -> FmiError {
        FmiError(Box::new(info))
    }
}

impl std::ops::Deref for FmiError {
    type Target = FmiErrorInfo;
    fn deref(&self) -> &FmiErrorInfo {
        &self.0
    }
}

impl std::ops::DerefMut for FmiError {
    fn deref_mut(&mut self) -> &mut FmiErrorInfo {
        &mut self.0
    }
}

impl FmiErrorInfo {
    /// True when the FMU reported fmi3Fatal (the instance is unusable).
    pub fn is_fatal(&self) -> bool {
        self.status == Some(Status::Fatal)
    }

    /// The FMU's reason: its warning-or-worse messages of the call, else all of them.
    fn reason(&self) -> String {
        let serious: Vec<&str> = self
            .messages
            .iter()
            .filter(|m| m.status >= Status::Warning)
            .map(|m| m.message.as_str())
            .collect();
        let msgs: Vec<&str> = if serious.is_empty() {
            self.messages.iter().map(|m| m.message.as_str()).collect()
        } else {
            serious
        };
        let mut parts: Vec<String> = msgs
            .into_iter()
            .map(|m| m.trim().to_string())
            .filter(|m| !m.is_empty())
            .collect();
        if let Some(d) = &self.detail {
            parts.push(d.clone());
        }
        if parts.is_empty() {
            "(the FMU logged no reason)".to_string()
        } else {
            parts.join("; ")
        }
    }
}

impl fmt::Display for FmiError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.0.fmt(f)
    }
}

impl fmt::Display for FmiErrorInfo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "FMU '{}' ({}): {}",
            self.instance, self.model, self.function
        )?;
        if !self.variables.is_empty() {
            write!(f, "({})", self.variables.join(", "))?;
        }
        if let Some(c) = &self.context {
            write!(f, " {c}")?;
        }
        match self.status {
            Some(s) => write!(f, " returned {s}: {}", self.reason()),
            None => write!(f, " failed: {}", self.reason()),
        }
    }
}

impl std::error::Error for FmiError {}
