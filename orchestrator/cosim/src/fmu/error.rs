//! [`FmiError`]: everything needed to understand a failed FMU call from one line.

use std::fmt;

use super::log::LogMessage;
use super::status::{Status, StepResult};

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
    /// For `fmi3DoStep`: the flags it returned (with fmi3Discard, how far the step got).
    pub step: Option<StepResult>,
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

    /// True when the FMU reported fmi3Discard: the call did not do its job (a step ended
    /// early, see [`FmiErrorInfo::step`]), but the instance is not in the Error state and
    /// stays usable (e.g. a shorter step, reading outputs, terminating).
    pub fn is_discard(&self) -> bool {
        self.status == Some(Status::Discard)
    }

    /// True when the wrapper refused the call without calling the FMU (an unsupported
    /// optional function, a call not allowed in the instance's state, bad arguments): the
    /// instance's state is unchanged.
    pub fn is_refused(&self) -> bool {
        self.status.is_none()
    }

    /// The FMU's reason: its warning-or-worse messages of the call, else all of them.
    fn reason(&self) -> String {
        let serious: Vec<&str> =
            self.messages.iter().filter(|m| m.status >= Status::Warning).map(|m| m.message.as_str()).collect();
        let msgs: Vec<&str> =
            if serious.is_empty() { self.messages.iter().map(|m| m.message.as_str()).collect() } else { serious };
        let mut parts: Vec<String> = msgs.into_iter().map(|m| m.trim().to_string()).filter(|m| !m.is_empty()).collect();
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

/// `FMU 'chassis' (Chassis): fmi3SetFloat64(v, w) at t=1`: which call of which instance, the
/// head of every error and printed warning.
pub(crate) fn write_call(
    f: &mut impl fmt::Write,
    instance: &str,
    model: &str,
    function: &str,
    variables: &[String],
    context: Option<&str>,
) -> fmt::Result {
    write!(f, "FMU '{instance}' ({model}): {function}")?;
    if !variables.is_empty() {
        write!(f, "({})", variables.join(", "))?;
    }
    if let Some(c) = context {
        write!(f, " {c}")?;
    }
    Ok(())
}

impl fmt::Display for FmiErrorInfo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write_call(f, &self.instance, &self.model, &self.function, &self.variables, self.context.as_deref())?;
        match self.status {
            // Statuses carry the version's prefix of the function that returned them.
            Some(s) if self.function.starts_with("fmi2") => {
                write!(f, " returned {}: {}", s.name().replacen("fmi3", "fmi2", 1), self.reason())?
            }
            Some(s) => write!(f, " returned {s}: {}", self.reason())?,
            None => write!(f, " failed: {}", self.reason())?,
        }
        match self.step {
            Some(r) if self.is_discard() => write!(f, " (the step ended early, at t={})", r.last_successful_time),
            _ => Ok(()),
        }
    }
}

impl std::error::Error for FmiError {}
