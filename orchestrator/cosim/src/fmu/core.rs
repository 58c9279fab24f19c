//! The bookkeeping every FMI instance wrapper shares, whatever the version: names for
//! messages, the wrapper's view of the state machine, the log sink, saved FMU states, and
//! how a call's status and log become a result or a printed warning.

use std::collections::BTreeMap;
use std::ffi::c_void;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

use super::error::{write_call, FmiErrorInfo};
use super::log::LogSink;
use super::{FmiError, FmuState, InstanceState, Status, Vr};

/// Call context for messages, formatted only when a message needs it.
#[derive(Clone, Copy)]
pub(crate) enum Ctx {
    None,
    At(f64),
    Step(f64, f64),
}

impl Ctx {
    pub(crate) fn text(self) -> Option<String> {
        match self {
            Ctx::None => None,
            Ctx::At(t) => Some(format!("at t={t}")),
            Ctx::Step(t, h) => Some(format!("at t={t} (h={h})")),
        }
    }
}

static NEXT_INSTANCE_ID: AtomicU64 = AtomicU64::new(1);

pub(crate) struct Core {
    pub name: String,
    pub model: String,
    pub state: InstanceState,
    pub debug_logging: bool,
    pub can_get_and_set_state: bool,
    pub can_serialize_state: bool,
    pub log_categories: Vec<String>,
    /// vr -> variable name, for error messages.
    pub names: Arc<BTreeMap<Vr, String>>,
    /// Saved FMU states by slot, with the wrapper's state when saved; `None` once freed.
    pub fmu_states: Vec<Option<(*mut c_void, InstanceState)>>,
    pub id: u64,
    /// Read by the logger callback; boxed so its address is stable.
    pub sink: Box<LogSink>,
}

impl Core {
    pub(crate) fn new(name: &str, md: &crate::model_description::ModelDescription, debug_logging: bool) -> Core {
        Core {
            name: name.to_string(),
            model: md.model_name.clone(),
            state: InstanceState::Instantiated,
            debug_logging,
            can_get_and_set_state: md.can_get_and_set_fmu_state,
            can_serialize_state: md.can_serialize_fmu_state,
            log_categories: md.log_categories.clone(),
            names: Arc::new(md.variables.iter().map(|v| (v.value_reference, v.name.clone())).collect()),
            fmu_states: Vec::new(),
            id: NEXT_INSTANCE_ID.fetch_add(1, Ordering::Relaxed),
            sink: Box::default(),
        }
    }

    /// Before an FFI call: refused after Fatal; else the log mark to pass to [`Core::after`].
    pub(crate) fn before(&self, function: &str, vrs: &[Vr], context: Ctx) -> Result<u64, FmiError> {
        if self.state == InstanceState::Fatal {
            let mut e =
                self.refuse(function, vrs, "refused: this instance returned a fatal status earlier and is unusable");
            e.status = Some(Status::Fatal);
            e.context = context.text();
            return Err(e);
        }
        Ok(self.sink.mark())
    }

    /// After an FFI call: maps the status, attaches the call's log to its error or reports
    /// it. Error and Fatal move the wrapper's state; Discard does not.
    pub(crate) fn after(
        &mut self,
        function: &str,
        vrs: &[Vr],
        context: Ctx,
        mark: u64,
        raw: std::ffi::c_int,
    ) -> Result<Status, FmiError> {
        let status = Status::from_raw(raw);
        if status <= Status::Warning {
            if status == Status::Warning || self.sink.mark() != mark {
                self.report(function, vrs, context, mark, status);
            }
            return Ok(status);
        }
        match status {
            Status::Fatal => self.state = InstanceState::Fatal,
            Status::Error => self.state = InstanceState::Error,
            _ => {}
        }
        Err(FmiErrorInfo {
            instance: self.name.clone(),
            model: self.model.clone(),
            function: function.to_string(),
            context: context.text(),
            variables: self.var_names(vrs),
            status: Some(status),
            detail: None,
            messages: self.sink.since(mark),
            step: None,
        }
        .into())
    }

    /// Prints what a call nobody gets an error from logged since `mark`: warnings or worse
    /// always, debug messages when debug logging is on, and a non-OK status without a reason.
    pub(crate) fn report(&self, function: &str, vrs: &[Vr], context: Ctx, mark: u64, status: Status) {
        let messages = self.sink.since(mark);
        let serious = messages.iter().any(|m| m.status >= Status::Warning);
        let debug = self.debug_logging && !messages.is_empty();
        if !serious && !debug && status == Status::Ok {
            return;
        }
        let mut call = String::new();
        let context = context.text();
        let _ = write_call(&mut call, &self.name, &self.model, function, &self.var_names(vrs), context.as_deref());
        for m in &messages {
            if m.status >= Status::Warning {
                eprintln!("warning: {call} logged {} [{}]: {}", m.status, m.category, m.message.trim());
            } else if self.debug_logging {
                eprintln!("FMU '{}' [{}]: {}", self.name, m.category, m.message.trim());
            }
        }
        if status > Status::Ok && !serious {
            eprintln!("warning: {call} returned {status} (the FMU logged no reason)");
        }
    }

    /// An error the wrapper raises itself (no FMU status).
    pub(crate) fn refuse(&self, function: &str, vrs: &[Vr], detail: &str) -> FmiError {
        FmiErrorInfo {
            instance: self.name.clone(),
            model: self.model.clone(),
            function: function.to_string(),
            context: None,
            variables: self.var_names(vrs),
            status: None,
            detail: Some(detail.to_string()),
            messages: Vec::new(),
            step: None,
        }
        .into()
    }

    pub(crate) fn check_len(&self, function: &str, vrs: &[Vr], n: usize) -> Result<(), FmiError> {
        if vrs.len() == n {
            Ok(())
        } else {
            Err(self.refuse(function, vrs, &format!("{} value references but {n} values", vrs.len())))
        }
    }

    pub(crate) fn var_names(&self, vrs: &[Vr]) -> Vec<String> {
        vrs.iter().map(|vr| self.names.get(vr).cloned().unwrap_or_else(|| format!("vr {vr}"))).collect()
    }

    /// Refused up front (not called) when a capability flag the function needs is not
    /// declared, or the library does not export it.
    pub(crate) fn optional<T>(&self, function: &str, needs: &[(bool, &str)], f: Option<T>) -> Result<T, FmiError> {
        if let Some((_, flag)) = needs.iter().find(|(declared, _)| !declared) {
            return Err(self.refuse(
                function,
                &[],
                &format!(
                    "refused: not supported, the FMU declares {flag}=\"false\" (not called; instance state unchanged)"
                ),
            ));
        }
        f.ok_or_else(|| {
            self.refuse(
                function,
                &[],
                "refused: the shared library does not export this function (not called; instance state unchanged)",
            )
        })
    }

    /// Refuses a call the FMI version has no function for.
    pub(crate) fn unsupported(&self, function: &str, vrs: &[Vr], what: &str) -> FmiError {
        self.refuse(function, vrs, &format!("refused: {what} (not called; instance state unchanged)"))
    }

    /// What dropping an instance does, in FMI 2 and 3 alike: terminate only from Step Mode
    /// (neither standard allows it in the other states we track), free the saved FMU states
    /// (not after an Error), then free the instance; nothing at all after a fatal status, for
    /// which the standards allow no further call, not even freeing (the instance leaks).
    /// Nobody receives an error from a drop, so what the FMU reports is printed (see `report`).
    /// `prefix` is "fmi2" or "fmi3"; the closures make the version's calls on the live handle.
    pub(crate) fn release(
        &mut self,
        prefix: &str,
        terminate: impl FnOnce() -> std::ffi::c_int,
        free_state: Option<impl FnMut(*mut c_void)>,
        free_instance: impl FnOnce(),
    ) {
        if self.state == InstanceState::Fatal {
            return;
        }
        if self.state == InstanceState::StepMode {
            let mark = self.sink.mark();
            let status = Status::from_raw(terminate());
            self.report(&format!("{prefix}Terminate (on drop)"), &[], Ctx::None, mark, status);
            if status == Status::Fatal {
                return;
            }
        }
        if self.state != InstanceState::Error {
            if let Some(mut free) = free_state {
                for (s, _) in self.fmu_states.iter_mut().filter_map(Option::take) {
                    free(s);
                }
            }
        }
        let mark = self.sink.mark();
        free_instance();
        self.report(&format!("{prefix}FreeInstance"), &[], Ctx::None, mark, Status::Ok);
    }

    pub(crate) fn keep_state(&mut self, s: *mut c_void, saved_in: InstanceState) -> FmuState {
        self.fmu_states.push(Some((s, saved_in)));
        FmuState { slot: self.fmu_states.len() - 1, owner: self.id }
    }

    pub(crate) fn own_state(&self, function: &str, state: &FmuState) -> Result<(*mut c_void, InstanceState), FmiError> {
        match self.fmu_states.get(state.slot) {
            Some(Some(s)) if state.owner == self.id => Ok(*s),
            _ => Err(self.refuse(function, &[], "the FMU state belongs to another instance or was freed")),
        }
    }

    /// Checks a debug-logging category list against the declared categories.
    pub(crate) fn check_categories(&self, function: &str, categories: &[&str]) -> Result<(), FmiError> {
        if self.log_categories.is_empty() {
            return Ok(());
        }
        let unknown: Vec<&str> =
            categories.iter().copied().filter(|c| !self.log_categories.iter().any(|k| k == c)).collect();
        if unknown.is_empty() {
            return Ok(());
        }
        let detail = format!(
            "refused: unknown log categor{} {} (the FMU declares: {})",
            if unknown.len() == 1 { "y" } else { "ies" },
            unknown.join(", "),
            self.log_categories.join(", ")
        );
        Err(self.refuse(function, &[], &detail))
    }
}
