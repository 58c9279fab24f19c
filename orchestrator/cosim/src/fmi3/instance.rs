//! [`Instance`]: one FMU co-simulation instance behind a safe API.
//!
//! The wrapper tracks the FMI state machine only as far as safety needs: drop terminates only
//! from Step Mode (the one state of ours where `fmi3Terminate` is allowed) before
//! `fmi3FreeInstance`, nothing is called after `fmi3Fatal` (the standard forbids any further
//! call, even freeing), and calls that would put a healthy FMU into its Error state for good
//! (an optional function it does not support, `fmi3Terminate` outside Step Mode) are refused
//! up front without calling it. Everything else (call order, allowed variables per state) the
//! FMU checks itself and reports through its status and log, which end up in the [`FmiError`].
//!
//! Logging: an FMU logs warnings and errors even with debug logging off. Messages of a failed
//! call go into its [`FmiError`]; those of a call that succeeded are printed to stderr when
//! they are warnings or worse (naming instance, function and variables), and debug messages
//! too when debug logging is on. All of them also stay available, bounded, to
//! [`Instance::take_log`].

use std::ffi::{c_char, c_void, CStr, CString};
use std::path::Path;
use std::ptr;
use std::sync::Arc;

use super::ffi::{self, Fmi3FmuState, Fmi3Instance, Vr};
use super::library::{Fmi3Library, Functions};
use crate::archive::FmuArchive;
use crate::fmu::core::{Core, Ctx};
use crate::fmu::log::{log_callback, LogMessage, LogSink};
pub use crate::fmu::FmuState;
use crate::fmu::{FmiError, FmiErrorInfo, InstanceState};
use crate::fmu::{Status, StepResult};
use crate::model_description::{FmiVersion, Interface};

/// A live FMU co-simulation instance.
pub struct Instance {
    handle: Fmi3Instance,
    /// Names, the state-machine view, the log sink and saved states (shared with FMI 2).
    core: Core,
    interface: Interface,
    /// Kept alive as long as the instance; declared last so it is released last.
    lib: Arc<Fmi3Library>,
}

// SAFETY: FMI allows an instance to be used from any thread as long as calls are not
// concurrent; `&mut self` on every FFI call guarantees that. Not `Sync`.
unsafe impl Send for Instance {}

impl Instance {
    /// Loads the archive's binary and instantiates it for co-simulation.
    ///
    /// `logging_on` is FMI's `loggingOn`: debug logging (all categories the FMU enables by
    /// default); off, the FMU reports only warnings and errors. [`Instance::set_debug_logging`]
    /// picks categories later.
    ///
    /// `resourcePath` is passed as the FMI 3.0 standard defines it: the absolute native path
    /// of `resources/` with a trailing separator (not the FMI 2.0 `file://` URI).
    pub fn instantiate(archive: &FmuArchive, instance_name: &str, logging_on: bool) -> Result<Instance, FmiError> {
        Self::instantiate_as(archive, instance_name, logging_on, Interface::CoSimulation)
    }

    /// Instantiates for model exchange (`fmi3InstantiateModelExchange`), for the master's
    /// integrator ([`crate::me::Integrated`]).
    pub fn instantiate_model_exchange(
        archive: &FmuArchive,
        instance_name: &str,
        logging_on: bool,
    ) -> Result<Instance, FmiError> {
        Self::instantiate_as(archive, instance_name, logging_on, Interface::ModelExchange)
    }

    fn instantiate_as(
        archive: &FmuArchive,
        instance_name: &str,
        logging_on: bool,
        interface: Interface,
    ) -> Result<Instance, FmiError> {
        let md = &archive.md;
        let f_name = match interface {
            Interface::CoSimulation => "fmi3InstantiateCoSimulation",
            Interface::ModelExchange => "fmi3InstantiateModelExchange",
        };
        let fail = |function: &str, detail: String, messages: Vec<LogMessage>| -> FmiError {
            FmiErrorInfo {
                instance: instance_name.to_string(),
                model: md.model_name.clone(),
                function: function.to_string(),
                context: None,
                variables: Vec::new(),
                status: None,
                detail: Some(detail),
                messages,
                step: None,
            }
            .into()
        };
        let lib = Fmi3Library::load(&archive.library_path, interface).map_err(|e| fail("loading", e, Vec::new()))?;
        let version = lib.version();
        if !version.starts_with("3.") {
            return Err(fail("fmi3GetVersion", format!("reports FMI version \"{version}\", expected 3.0"), Vec::new()));
        }
        let lib = Arc::new(lib);

        let c_name = CString::new(instance_name)
            .map_err(|_| fail(f_name, "instance name contains a NUL byte".into(), Vec::new()))?;
        let c_token = CString::new(md.instantiation_token.as_str())
            .map_err(|_| fail(f_name, "instantiationToken contains a NUL byte".into(), Vec::new()))?;
        let c_resources = CString::new(resource_path(&archive.resources_dir))
            .map_err(|_| fail(f_name, "resources path contains a NUL byte".into(), Vec::new()))?;
        let missing = || fail(f_name, "the shared library does not export this interface".into(), Vec::new());

        let core = Core::new(instance_name, md, logging_on);
        let env = &*core.sink as *const LogSink as *mut c_void;
        // SAFETY: all strings outlive the call; `env` outlives the instance (see Drop).
        let handle = match interface {
            Interface::CoSimulation => unsafe {
                (lib.f.instantiate_co_simulation.ok_or_else(missing)?)(
                    c_name.as_ptr(),
                    c_token.as_ptr(),
                    c_resources.as_ptr(),
                    false,
                    logging_on,
                    false,
                    false,
                    ptr::null(),
                    0,
                    env,
                    Some(log_callback),
                    None,
                )
            },
            Interface::ModelExchange => unsafe {
                (lib.f.me.as_ref().ok_or_else(missing)?.instantiate)(
                    c_name.as_ptr(),
                    c_token.as_ptr(),
                    c_resources.as_ptr(),
                    false,
                    logging_on,
                    env,
                    Some(log_callback),
                )
            },
        };
        if handle.is_null() {
            return Err(fail(f_name, "returned NULL (instantiation failed)".into(), core.sink.take()));
        }
        let inst = Instance { handle, core, interface, lib };
        inst.core.report(f_name, &[], Ctx::None, 0, Status::Ok);
        Ok(inst)
    }

    /// `fmi3SetDebugLogging`: debug logging on or off; `categories` empty = all categories,
    /// else those (each must be one of the modelDescription's `<LogCategories>` when it
    /// declares any). Refused up front, without calling the FMU, for an unknown category or
    /// when the FMU does not export the function.
    pub fn set_debug_logging(&mut self, on: bool, categories: &[&str]) -> Result<(), FmiError> {
        const F: &str = "fmi3SetDebugLogging";
        let Some(set) = self.lib.f.set_debug_logging else {
            return Err(self.refuse(
                F,
                &[],
                "refused: the shared library does not export this function (not called; instance state unchanged)",
            ));
        };
        self.core.check_categories(F, categories)?;
        let c: Vec<CString> = categories
            .iter()
            .map(|c| CString::new(*c))
            .collect::<Result<_, _>>()
            .map_err(|_| self.refuse(F, &[], "a category name contains a NUL byte"))?;
        let ptrs: Vec<*const c_char> = c.iter().map(|c| c.as_ptr()).collect();
        let p = if ptrs.is_empty() { ptr::null() } else { ptrs.as_ptr() };
        self.call(F, &[], Ctx::None, |_, h| unsafe { set(h, on, ptrs.len(), p) })?;
        self.core.debug_logging = on;
        Ok(())
    }

    /// Number of messages the FMU has sent through the logger callback since instantiation
    /// (with debug logging off: its warnings and errors only).
    pub fn log_count(&self) -> u64 {
        self.core.sink.mark()
    }

    pub fn name(&self) -> &str {
        &self.core.name
    }

    pub fn fmi_version(&self) -> FmiVersion {
        FmiVersion::V3
    }

    pub fn interface(&self) -> Interface {
        self.interface
    }

    pub fn model_name(&self) -> &str {
        &self.core.model
    }

    pub fn state(&self) -> InstanceState {
        self.core.state
    }

    /// The messages logged since the last `take_log` (warnings included), oldest first; at
    /// most the latest 4096.
    pub fn take_log(&mut self) -> Vec<LogMessage> {
        self.core.sink.take()
    }

    pub fn enter_initialization_mode(&mut self, start_time: f64, stop_time: Option<f64>) -> Result<(), FmiError> {
        self.call("fmi3EnterInitializationMode", &[], Ctx::At(start_time), |f, h| unsafe {
            (f.enter_initialization_mode)(h, false, 0.0, start_time, stop_time.is_some(), stop_time.unwrap_or(0.0))
        })?;
        self.core.state = InstanceState::InitializationMode;
        Ok(())
    }

    pub fn exit_initialization_mode(&mut self) -> Result<(), FmiError> {
        self.call("fmi3ExitInitializationMode", &[], Ctx::None, |f, h| unsafe { (f.exit_initialization_mode)(h) })?;
        self.core.state = InstanceState::StepMode;
        Ok(())
    }

    /// Advances from `t` to `t + h`.
    ///
    /// fmi3Discard (the FMU could not complete the step) is an error of its own kind:
    /// [`FmiErrorInfo::is_discard`], with the step's flags (how far it got) in
    /// [`FmiErrorInfo::step`]. Unlike fmi3Error it leaves the instance in Step Mode, usable.
    pub fn do_step(&mut self, t: f64, h: f64) -> Result<StepResult, FmiError> {
        let mut r = StepResult {
            event_handling_needed: false,
            terminate_simulation: false,
            early_return: false,
            last_successful_time: t,
        };
        let Some(step) = self.lib.f.do_step else {
            return Err(self.refuse("fmi3DoStep", &[], "refused: this instance is model exchange (not called)"));
        };
        let res = self.call("fmi3DoStep", &[], Ctx::Step(t, h), |_, inst| unsafe {
            step(
                inst,
                t,
                h,
                false,
                &mut r.event_handling_needed,
                &mut r.terminate_simulation,
                &mut r.early_return,
                &mut r.last_successful_time,
            )
        });
        match res {
            Ok(_) => Ok(r),
            Err(mut e) => {
                e.step = Some(r);
                Err(e)
            }
        }
    }

    /// `fmi3Terminate`. FMI 3.0 allows it only in Step Mode among the states used here; from
    /// Instantiated, Initialization Mode, Terminated or Error it is refused up front, leaving
    /// the instance as it was (drop it, or `reset` it, instead).
    pub fn terminate(&mut self) -> Result<(), FmiError> {
        if self.core.state != InstanceState::StepMode {
            let detail = format!(
                "refused: not allowed in state {:?} (FMI 3.0 terminates from Step Mode only; not called; instance state unchanged)",
                self.core.state
            );
            return Err(self.refuse("fmi3Terminate", &[], &detail));
        }
        self.call("fmi3Terminate", &[], Ctx::None, |f, h| unsafe { (f.terminate)(h) })?;
        self.core.state = InstanceState::Terminated;
        Ok(())
    }

    /// Back to the just-instantiated state (also the way out of an Error).
    pub fn reset(&mut self) -> Result<(), FmiError> {
        self.call("fmi3Reset", &[], Ctx::None, |f, h| unsafe { (f.reset)(h) })?;
        self.core.state = InstanceState::Instantiated;
        Ok(())
    }

    pub fn set_f64(&mut self, vrs: &[Vr], values: &[f64]) -> Result<(), FmiError> {
        self.check_len("fmi3SetFloat64", vrs, values.len())?;
        self.call("fmi3SetFloat64", vrs, Ctx::None, |f, h| unsafe {
            (f.set_float64)(h, vrs.as_ptr(), vrs.len(), values.as_ptr(), values.len())
        })
        .map(drop)
    }

    pub fn get_f64(&mut self, vrs: &[Vr], values: &mut [f64]) -> Result<(), FmiError> {
        self.check_len("fmi3GetFloat64", vrs, values.len())?;
        self.call("fmi3GetFloat64", vrs, Ctx::None, |f, h| unsafe {
            (f.get_float64)(h, vrs.as_ptr(), vrs.len(), values.as_mut_ptr(), values.len())
        })
        .map(drop)
    }

    pub fn set_i32(&mut self, vrs: &[Vr], values: &[i32]) -> Result<(), FmiError> {
        self.check_len("fmi3SetInt32", vrs, values.len())?;
        self.call("fmi3SetInt32", vrs, Ctx::None, |f, h| unsafe {
            (f.set_int32)(h, vrs.as_ptr(), vrs.len(), values.as_ptr(), values.len())
        })
        .map(drop)
    }

    pub fn get_i32(&mut self, vrs: &[Vr], values: &mut [i32]) -> Result<(), FmiError> {
        self.check_len("fmi3GetInt32", vrs, values.len())?;
        self.call("fmi3GetInt32", vrs, Ctx::None, |f, h| unsafe {
            (f.get_int32)(h, vrs.as_ptr(), vrs.len(), values.as_mut_ptr(), values.len())
        })
        .map(drop)
    }

    pub fn set_i64(&mut self, vrs: &[Vr], values: &[i64]) -> Result<(), FmiError> {
        self.check_len("fmi3SetInt64", vrs, values.len())?;
        self.call("fmi3SetInt64", vrs, Ctx::None, |f, h| unsafe {
            (f.set_int64)(h, vrs.as_ptr(), vrs.len(), values.as_ptr(), values.len())
        })
        .map(drop)
    }

    pub fn get_i64(&mut self, vrs: &[Vr], values: &mut [i64]) -> Result<(), FmiError> {
        self.check_len("fmi3GetInt64", vrs, values.len())?;
        self.call("fmi3GetInt64", vrs, Ctx::None, |f, h| unsafe {
            (f.get_int64)(h, vrs.as_ptr(), vrs.len(), values.as_mut_ptr(), values.len())
        })
        .map(drop)
    }

    pub fn set_bool(&mut self, vrs: &[Vr], values: &[bool]) -> Result<(), FmiError> {
        self.check_len("fmi3SetBoolean", vrs, values.len())?;
        self.call("fmi3SetBoolean", vrs, Ctx::None, |f, h| unsafe {
            (f.set_boolean)(h, vrs.as_ptr(), vrs.len(), values.as_ptr(), values.len())
        })
        .map(drop)
    }

    pub fn get_bool(&mut self, vrs: &[Vr], values: &mut [bool]) -> Result<(), FmiError> {
        self.check_len("fmi3GetBoolean", vrs, values.len())?;
        self.call("fmi3GetBoolean", vrs, Ctx::None, |f, h| unsafe {
            (f.get_boolean)(h, vrs.as_ptr(), vrs.len(), values.as_mut_ptr(), values.len())
        })
        .map(drop)
    }

    pub fn set_string(&mut self, vr: Vr, value: &str) -> Result<(), FmiError> {
        let c =
            CString::new(value).map_err(|_| self.refuse("fmi3SetString", &[vr], "the string contains a NUL byte"))?;
        let p = c.as_ptr();
        self.call("fmi3SetString", &[vr], Ctx::None, |f, h| unsafe { (f.set_string)(h, &vr, 1, &p, 1) }).map(drop)
    }

    /// Copies the string out of FMU-owned memory.
    pub fn get_string(&mut self, vr: Vr) -> Result<String, FmiError> {
        let mut p: *const c_char = ptr::null();
        self.call("fmi3GetString", &[vr], Ctx::None, |f, h| unsafe { (f.get_string)(h, &vr, 1, &mut p, 1) })?;
        if p.is_null() {
            return Err(self.refuse("fmi3GetString", &[vr], "the FMU returned a NULL string"));
        }
        // SAFETY: the FMU guarantees a NUL-terminated string valid until its next call.
        Ok(unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned())
    }

    pub fn set_binary(&mut self, vr: Vr, value: &[u8]) -> Result<(), FmiError> {
        let size = value.len();
        let p = value.as_ptr();
        self.call("fmi3SetBinary", &[vr], Ctx::None, |f, h| unsafe { (f.set_binary)(h, &vr, 1, &size, &p, 1) })
            .map(drop)
    }

    /// Copies the bytes out of FMU-owned memory (valid only until the FMU's next call).
    pub fn get_binary(&mut self, vr: Vr) -> Result<Vec<u8>, FmiError> {
        Ok(self.get_binary_ref(vr)?.to_vec())
    }

    /// The bytes in FMU-owned memory, borrowed: they stay valid until the FMU's next call,
    /// which needs `&mut self` again. A camera image is read without a copy.
    pub fn get_binary_ref(&mut self, vr: Vr) -> Result<&[u8], FmiError> {
        let mut size: usize = 0;
        let mut p: *const u8 = ptr::null();
        self.call("fmi3GetBinary", &[vr], Ctx::None, |f, h| unsafe {
            (f.get_binary)(h, &vr, 1, &mut size, &mut p, 1)
        })?;
        if size == 0 {
            return Ok(&[]);
        }
        if p.is_null() {
            return Err(self.refuse("fmi3GetBinary", &[vr], &format!("the FMU returned NULL for {size} bytes")));
        }
        // SAFETY: the FMU guarantees `size` readable bytes at `p` until its next call, and
        // every call takes `&mut self`, which the returned borrow holds.
        Ok(unsafe { std::slice::from_raw_parts(p, size) })
    }

    /// Saves the FMU's state (needs canGetAndSetFMUState).
    pub fn get_state(&mut self) -> Result<FmuState, FmiError> {
        let get = self.state_fn("fmi3GetFMUState", |f| f.get_fmu_state)?;
        let mut s: Fmi3FmuState = ptr::null_mut();
        self.call("fmi3GetFMUState", &[], Ctx::None, |_, h| unsafe { get(h, &mut s) })?;
        if s.is_null() {
            return Err(self.refuse("fmi3GetFMUState", &[], "the FMU returned a NULL state"));
        }
        Ok(self.core.keep_state(s, self.core.state))
    }

    /// Restores a state saved by this instance (and with it the state-machine state it was
    /// saved in: the way out of an Error).
    pub fn set_state(&mut self, state: &FmuState) -> Result<(), FmiError> {
        let set = self.state_fn("fmi3SetFMUState", |f| f.set_fmu_state)?;
        let (s, saved_in) = self.own_state("fmi3SetFMUState", state)?;
        self.call("fmi3SetFMUState", &[], Ctx::None, |_, h| unsafe { set(h, s) })?;
        self.core.state = saved_in;
        Ok(())
    }

    /// The bytes of a saved state (needs canSerializeFMUState), and the wrapper's state it
    /// was saved in (give both back to [`Instance::deserialize_state`]).
    pub fn serialize_state(&mut self, state: &FmuState) -> Result<(Vec<u8>, InstanceState), FmiError> {
        let (size_fn, ser) =
            self.serial_fns("fmi3SerializeFMUState", |f| Some((f.serialized_fmu_state_size?, f.serialize_fmu_state?)))?;
        let (s, saved_in) = self.own_state("fmi3SerializeFMUState", state)?;
        let mut size = 0usize;
        self.call("fmi3SerializedFMUStateSize", &[], Ctx::None, |_, h| unsafe { size_fn(h, s, &mut size) })?;
        let mut bytes = vec![0u8; size];
        self.call("fmi3SerializeFMUState", &[], Ctx::None, |_, h| unsafe { ser(h, s, bytes.as_mut_ptr(), size) })?;
        Ok((bytes, saved_in))
    }

    /// A new saved state of this instance from bytes of [`Instance::serialize_state`] (of
    /// this FMU, possibly from another instance or process); `saved_in` is restored with it.
    pub fn deserialize_state(&mut self, bytes: &[u8], saved_in: InstanceState) -> Result<FmuState, FmiError> {
        let de = self.serial_fns("fmi3DeserializeFMUState", |f| f.deserialize_fmu_state)?;
        if matches!(saved_in, InstanceState::Fatal | InstanceState::Error) {
            let detail = format!("refused: no state is saved in {saved_in:?} (not called)");
            return Err(self.refuse("fmi3DeserializeFMUState", &[], &detail));
        }
        let mut s: Fmi3FmuState = ptr::null_mut();
        self.call("fmi3DeserializeFMUState", &[], Ctx::None, |_, h| unsafe {
            de(h, bytes.as_ptr(), bytes.len(), &mut s)
        })?;
        if s.is_null() {
            return Err(self.refuse("fmi3DeserializeFMUState", &[], "the FMU returned a NULL state"));
        }
        Ok(self.core.keep_state(s, saved_in))
    }

    /// Frees a saved state now (otherwise it is freed with the instance).
    pub fn free_state(&mut self, state: FmuState) -> Result<(), FmiError> {
        let free = self.state_fn("fmi3FreeFMUState", |f| f.free_fmu_state)?;
        let (mut s, _) = self.own_state("fmi3FreeFMUState", &state)?;
        self.core.fmu_states[state.slot] = None;
        self.call("fmi3FreeFMUState", &[], Ctx::None, |_, h| unsafe { free(h, &mut s) }).map(drop)
    }

    // ---- internals ----

    /// Runs one FFI call: refuses after Fatal, maps the status, attaches the call's log to
    /// its error or reports it (see [`Instance::report`]). Error and Fatal move the wrapper's
    /// state; Discard does not.
    fn call(
        &mut self,
        function: &'static str,
        vrs: &[Vr],
        context: Ctx,
        f: impl FnOnce(&Functions, Fmi3Instance) -> ffi::Fmi3Status,
    ) -> Result<Status, FmiError> {
        let mark = self.core.before(function, vrs, context)?;
        let raw = f(&self.lib.f, self.handle);
        self.core.after(function, vrs, context, mark, raw)
    }

    fn refuse(&self, function: &str, vrs: &[Vr], detail: &str) -> FmiError {
        self.core.refuse(function, vrs, detail)
    }

    fn check_len(&self, function: &str, vrs: &[Vr], n: usize) -> Result<(), FmiError> {
        self.core.check_len(function, vrs, n)
    }

    /// An optional FMU-state function, refused up front (not called) when a capability flag
    /// it needs is not declared or the library does not export it.
    fn state_fn<T>(&self, function: &str, pick: impl FnOnce(&Functions) -> Option<T>) -> Result<T, FmiError> {
        self.optional_fn(function, &[(self.core.can_get_and_set_state, "canGetAndSetFMUState")], pick)
    }

    fn serial_fns<T>(&self, function: &str, pick: impl FnOnce(&Functions) -> Option<T>) -> Result<T, FmiError> {
        let needs = [
            (self.core.can_serialize_state, "canSerializeFMUState"),
            (self.core.can_get_and_set_state, "canGetAndSetFMUState"),
        ];
        self.optional_fn(function, &needs, pick)
    }

    fn optional_fn<T>(
        &self,
        function: &str,
        needs: &[(bool, &str)],
        pick: impl FnOnce(&Functions) -> Option<T>,
    ) -> Result<T, FmiError> {
        self.core.optional(function, needs, pick(&self.lib.f))
    }

    fn own_state(&self, function: &str, state: &FmuState) -> Result<(Fmi3FmuState, InstanceState), FmiError> {
        self.core.own_state(function, state)
    }
}

impl Drop for Instance {
    /// See `Core::release`; `sink` and then `lib` are dropped after this, i.e. after the
    /// FMU can no longer log.
    fn drop(&mut self) {
        if self.handle.is_null() {
            return;
        }
        let (f, h) = (&self.lib.f, self.handle);
        // SAFETY: the handle is live (never freed before; nulled right after freeing), and
        // each call has the fmi3 signature of its symbol.
        self.core.release(
            "fmi3",
            || unsafe { (f.terminate)(h) },
            f.free_fmu_state.map(|free| {
                move |s| {
                    let mut s = s;
                    let _ = unsafe { free(h, &mut s) };
                }
            }),
            || unsafe { (f.free_instance)(h) },
        );
        self.handle = ptr::null_mut();
    }
}

/// The FMI 3.0 `resourcePath` argument: absolute, native, with a trailing separator.
fn resource_path(dir: &Path) -> String {
    let abs = std::fs::canonicalize(dir).unwrap_or_else(|_| dir.to_path_buf());
    let mut s = abs.to_string_lossy().into_owned();
    if !s.ends_with(std::path::MAIN_SEPARATOR) {
        s.push(std::path::MAIN_SEPARATOR);
    }
    s
}

crate::fmu::delegate_fmu_instance!(Instance);

impl Instance {
    fn me_call(
        &mut self,
        function: &'static str,
        context: Ctx,
        f: impl FnOnce(&super::library::MeFunctions, Fmi3Instance) -> ffi::Fmi3Status,
    ) -> Result<Status, FmiError> {
        if self.lib.f.me.is_none() {
            return Err(self.refuse(function, &[], "refused: the binary has no model-exchange interface (not called)"));
        }
        let lib = self.lib.clone();
        self.call(function, &[], context, move |_, h| f(lib.f.me.as_ref().expect("checked above"), h))
    }
}

impl crate::me::ModelExchange for Instance {
    fn enter_event_mode(&mut self) -> Result<(), FmiError> {
        self.me_call("fmi3EnterEventMode", Ctx::None, |f, h| unsafe { (f.enter_event_mode)(h) }).map(drop)
    }

    fn update_discrete_states(&mut self) -> Result<crate::me::EventUpdate, FmiError> {
        let (mut again, mut term, mut nominals, mut values, mut defined, mut next) =
            (false, false, false, false, false, 0.0);
        self.me_call("fmi3UpdateDiscreteStates", Ctx::None, |f, h| unsafe {
            (f.update_discrete_states)(h, &mut again, &mut term, &mut nominals, &mut values, &mut defined, &mut next)
        })?;
        Ok(crate::me::EventUpdate {
            again,
            terminate: term,
            states_changed: values,
            next_event_time: defined.then_some(next),
        })
    }

    fn enter_continuous_time_mode(&mut self) -> Result<(), FmiError> {
        self.me_call("fmi3EnterContinuousTimeMode", Ctx::None, |f, h| unsafe { (f.enter_continuous_time_mode)(h) })
            .map(drop)
    }

    fn completed_integrator_step(&mut self) -> Result<(bool, bool), FmiError> {
        let (mut event, mut term) = (false, false);
        self.me_call("fmi3CompletedIntegratorStep", Ctx::None, |f, h| unsafe {
            (f.completed_integrator_step)(h, true, &mut event, &mut term)
        })?;
        Ok((event, term))
    }

    fn set_time(&mut self, t: f64) -> Result<(), FmiError> {
        self.me_call("fmi3SetTime", Ctx::At(t), |f, h| unsafe { (f.set_time)(h, t) }).map(drop)
    }

    fn set_continuous_states(&mut self, x: &[f64]) -> Result<(), FmiError> {
        self.me_call("fmi3SetContinuousStates", Ctx::None, |f, h| unsafe {
            (f.set_continuous_states)(h, x.as_ptr(), x.len())
        })
        .map(drop)
    }

    fn get_continuous_states(&mut self, x: &mut [f64]) -> Result<(), FmiError> {
        self.me_call("fmi3GetContinuousStates", Ctx::None, |f, h| unsafe {
            (f.get_continuous_states)(h, x.as_mut_ptr(), x.len())
        })
        .map(drop)
    }

    fn get_derivatives(&mut self, dx: &mut [f64]) -> Result<(), FmiError> {
        self.me_call("fmi3GetContinuousStateDerivatives", Ctx::None, |f, h| unsafe {
            (f.get_derivatives)(h, dx.as_mut_ptr(), dx.len())
        })
        .map(drop)
    }

    fn get_event_indicators(&mut self, z: &mut [f64]) -> Result<(), FmiError> {
        self.me_call("fmi3GetEventIndicators", Ctx::None, |f, h| unsafe {
            (f.get_event_indicators)(h, z.as_mut_ptr(), z.len())
        })
        .map(drop)
    }

    fn set_wrapper_state(&mut self, s: InstanceState) {
        self.core.state = s;
    }
}
