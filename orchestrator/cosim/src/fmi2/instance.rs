//! [`Instance`]: one FMI 2.0 instance (co-simulation, or model exchange for the master's
//! integrator) behind the same safe API as FMI 3's ([`crate::fmu::FmuInstance`]).
//!
//! Differences from FMI 3 handled here: `fmi2SetupExperiment` is called as part of
//! entering Initialization Mode; `fmi2Boolean` is C `int`; the resource location is a
//! `file://` URI; the logger is variadic (formatted in logger.c); FMI 2 has no Int64 and no
//! Binary, so those calls are refused without calling the FMU. The state rules match FMI 3's
//! wrapper: drop terminates only from Step Mode, nothing is called after a fatal status.

use std::ffi::{c_char, c_int, CStr, CString};
use std::path::Path;
use std::ptr;
use std::sync::Arc;

use super::ffi::{self, EventInfo, Fmi2Component, Vr};
use super::library::{Fmi2Library, Functions, MeFunctions};
use super::log::{agrisim_cosim_fmi2_logger, allocate, release, Env};
use crate::archive::FmuArchive;
use crate::fmu::core::{Core, Ctx};
use crate::fmu::{FmiError, FmuState, InstanceState, LogMessage, Status, StepResult};
use crate::model_description::{FmiVersion, Interface};

/// A live FMI 2.0 instance.
pub struct Instance {
    handle: Fmi2Component,
    core: Core,
    interface: Interface,
    /// `componentEnvironment` and the callback struct: the FMU keeps pointers to both.
    _env: Box<Env>,
    _callbacks: Box<ffi::CallbackFunctions>,
    /// Declared last so the library is released last.
    lib: Arc<Fmi2Library>,
}

// SAFETY: as for FMI 3 (calls are never concurrent: every FFI call takes `&mut self`).
unsafe impl Send for Instance {}

/// `fmi2Boolean` from `bool`.
fn b(x: bool) -> c_int {
    x as c_int
}

impl Instance {
    /// Loads the archive's binary and instantiates it for `interface` (the description's
    /// own interface unless the caller picks model exchange of an FMU that has both).
    pub fn instantiate(
        archive: &FmuArchive,
        instance_name: &str,
        interface: Interface,
        logging_on: bool,
    ) -> Result<Instance, FmiError> {
        let md = &archive.md;
        let core = Core::new(instance_name, md, logging_on);
        let f_name = "fmi2Instantiate";
        let lib = Fmi2Library::load(&archive.library_path, interface).map_err(|e| core.refuse("loading", &[], &e))?;
        let version = lib.version();
        if !version.starts_with("2.") {
            return Err(core.refuse(
                "fmi2GetVersion",
                &[],
                &format!("reports FMI version \"{version}\", expected 2.0"),
            ));
        }
        let lib = Arc::new(lib);
        let c_name =
            CString::new(instance_name).map_err(|_| core.refuse(f_name, &[], "instance name contains a NUL byte"))?;
        let c_guid = CString::new(md.instantiation_token.as_str())
            .map_err(|_| core.refuse(f_name, &[], "guid contains a NUL byte"))?;
        let c_resources = CString::new(resource_uri(&archive.resources_dir))
            .map_err(|_| core.refuse(f_name, &[], "resources path contains a NUL byte"))?;
        let env = Box::new(Env::new(&core.sink));
        let callbacks = Box::new(ffi::CallbackFunctions {
            logger: Some(agrisim_cosim_fmi2_logger),
            allocate_memory: Some(allocate),
            free_memory: Some(release),
            step_finished: None,
            component_environment: &*env as *const Env as *mut std::ffi::c_void,
        });
        let kind = match interface {
            Interface::CoSimulation => ffi::CO_SIMULATION,
            Interface::ModelExchange => ffi::MODEL_EXCHANGE,
        };
        // SAFETY: all strings outlive the call; `env` and `callbacks` outlive the instance.
        let handle = unsafe {
            (lib.f.instantiate)(
                c_name.as_ptr(),
                kind,
                c_guid.as_ptr(),
                c_resources.as_ptr(),
                &*callbacks,
                0,
                b(logging_on),
            )
        };
        if handle.is_null() {
            let mut e = core.refuse(f_name, &[], "returned NULL (instantiation failed)");
            e.messages = core.sink.take();
            return Err(e);
        }
        let inst = Instance { handle, core, interface, _env: env, _callbacks: callbacks, lib };
        inst.core.report(f_name, &[], Ctx::None, 0, Status::Ok);
        Ok(inst)
    }

    pub fn name(&self) -> &str {
        &self.core.name
    }

    pub fn model_name(&self) -> &str {
        &self.core.model
    }

    pub fn fmi_version(&self) -> FmiVersion {
        FmiVersion::V2
    }

    pub fn interface(&self) -> Interface {
        self.interface
    }

    pub fn state(&self) -> InstanceState {
        self.core.state
    }

    pub fn take_log(&mut self) -> Vec<LogMessage> {
        self.core.sink.take()
    }

    pub fn log_count(&self) -> u64 {
        self.core.sink.mark()
    }

    /// One FFI call through the shared bookkeeping.
    fn call(
        &mut self,
        function: &'static str,
        vrs: &[Vr],
        context: Ctx,
        f: impl FnOnce(&Functions, Fmi2Component) -> ffi::Fmi2Status,
    ) -> Result<Status, FmiError> {
        let mark = self.core.before(function, vrs, context)?;
        let raw = f(&self.lib.f, self.handle);
        self.core.after(function, vrs, context, mark, raw)
    }

    pub fn set_debug_logging(&mut self, on: bool, categories: &[&str]) -> Result<(), FmiError> {
        const F: &str = "fmi2SetDebugLogging";
        let set = self.core.optional(F, &[], self.lib.f.set_debug_logging)?;
        self.core.check_categories(F, categories)?;
        let c: Vec<CString> = categories
            .iter()
            .map(|c| CString::new(*c))
            .collect::<Result<_, _>>()
            .map_err(|_| self.core.refuse(F, &[], "a category name contains a NUL byte"))?;
        let ptrs: Vec<*const c_char> = c.iter().map(|c| c.as_ptr()).collect();
        let p = if ptrs.is_empty() { ptr::null() } else { ptrs.as_ptr() };
        self.call(F, &[], Ctx::None, |_, h| unsafe { set(h, b(on), ptrs.len(), p) })?;
        self.core.debug_logging = on;
        Ok(())
    }

    /// `fmi2SetupExperiment` then `fmi2EnterInitializationMode`.
    pub fn enter_initialization_mode(&mut self, start_time: f64, stop_time: Option<f64>) -> Result<(), FmiError> {
        self.call("fmi2SetupExperiment", &[], Ctx::At(start_time), |f, h| unsafe {
            (f.setup_experiment)(h, 0, 0.0, start_time, b(stop_time.is_some()), stop_time.unwrap_or(0.0))
        })?;
        self.call("fmi2EnterInitializationMode", &[], Ctx::At(start_time), |f, h| unsafe {
            (f.enter_initialization_mode)(h)
        })?;
        self.core.state = InstanceState::InitializationMode;
        Ok(())
    }

    pub fn exit_initialization_mode(&mut self) -> Result<(), FmiError> {
        self.call("fmi2ExitInitializationMode", &[], Ctx::None, |f, h| unsafe { (f.exit_initialization_mode)(h) })?;
        self.core.state = InstanceState::StepMode;
        Ok(())
    }

    /// `fmi2DoStep` from `t` to `t + h`. fmi2Discard is an error of its own kind (see
    /// [`crate::fmu::FmiErrorInfo::is_discard`]) carrying the last successful time when the
    /// FMU reports it.
    pub fn do_step(&mut self, t: f64, h: f64) -> Result<StepResult, FmiError> {
        const F: &str = "fmi2DoStep";
        let Some(step) = self.lib.f.do_step else {
            return Err(self.core.unsupported(F, &[], "this instance is model exchange"));
        };
        let res = self.call(F, &[], Ctx::Step(t, h), |_, c| unsafe { step(c, t, h, 1) });
        let mut r = StepResult {
            event_handling_needed: false,
            terminate_simulation: false,
            early_return: false,
            last_successful_time: t + h,
        };
        match res {
            Ok(_) => Ok(r),
            Err(mut e) => {
                if e.is_discard() {
                    r.last_successful_time = t;
                    if let Some(get) = self.lib.f.get_real_status {
                        let mut last = t;
                        // SAFETY: allowed after a discarded step (FMI 2.0 section 4.2.3).
                        if unsafe { get(self.handle, ffi::LAST_SUCCESSFUL_TIME, &mut last) } == 0 {
                            r.last_successful_time = last;
                        }
                    }
                    if let Some(get) = self.lib.f.get_boolean_status {
                        let mut term = 0;
                        // SAFETY: as above.
                        if unsafe { get(self.handle, ffi::TERMINATED, &mut term) } == 0 {
                            r.terminate_simulation = term != 0;
                        }
                    }
                }
                e.step = Some(r);
                Err(e)
            }
        }
    }

    /// `fmi2Terminate`, from Step Mode only (else refused, as for FMI 3).
    pub fn terminate(&mut self) -> Result<(), FmiError> {
        if self.core.state != InstanceState::StepMode {
            let detail = format!(
                "refused: not allowed in state {:?} (terminates from Step Mode only; not called; instance state unchanged)",
                self.core.state
            );
            return Err(self.core.refuse("fmi2Terminate", &[], &detail));
        }
        self.call("fmi2Terminate", &[], Ctx::None, |f, h| unsafe { (f.terminate)(h) })?;
        self.core.state = InstanceState::Terminated;
        Ok(())
    }

    pub fn reset(&mut self) -> Result<(), FmiError> {
        self.call("fmi2Reset", &[], Ctx::None, |f, h| unsafe { (f.reset)(h) })?;
        self.core.state = InstanceState::Instantiated;
        Ok(())
    }

    pub fn set_f64(&mut self, vrs: &[Vr], values: &[f64]) -> Result<(), FmiError> {
        self.core.check_len("fmi2SetReal", vrs, values.len())?;
        self.call("fmi2SetReal", vrs, Ctx::None, |f, h| unsafe {
            (f.set_real)(h, vrs.as_ptr(), vrs.len(), values.as_ptr())
        })
        .map(drop)
    }

    pub fn get_f64(&mut self, vrs: &[Vr], values: &mut [f64]) -> Result<(), FmiError> {
        self.core.check_len("fmi2GetReal", vrs, values.len())?;
        self.call("fmi2GetReal", vrs, Ctx::None, |f, h| unsafe {
            (f.get_real)(h, vrs.as_ptr(), vrs.len(), values.as_mut_ptr())
        })
        .map(drop)
    }

    pub fn set_i32(&mut self, vrs: &[Vr], values: &[i32]) -> Result<(), FmiError> {
        self.core.check_len("fmi2SetInteger", vrs, values.len())?;
        self.call("fmi2SetInteger", vrs, Ctx::None, |f, h| unsafe {
            (f.set_integer)(h, vrs.as_ptr(), vrs.len(), values.as_ptr())
        })
        .map(drop)
    }

    pub fn get_i32(&mut self, vrs: &[Vr], values: &mut [i32]) -> Result<(), FmiError> {
        self.core.check_len("fmi2GetInteger", vrs, values.len())?;
        self.call("fmi2GetInteger", vrs, Ctx::None, |f, h| unsafe {
            (f.get_integer)(h, vrs.as_ptr(), vrs.len(), values.as_mut_ptr())
        })
        .map(drop)
    }

    pub fn set_i64(&mut self, vrs: &[Vr], _values: &[i64]) -> Result<(), FmiError> {
        Err(self.core.unsupported("fmi2SetInteger", vrs, "FMI 2.0 has no 64-bit integers"))
    }

    pub fn get_i64(&mut self, vrs: &[Vr], _values: &mut [i64]) -> Result<(), FmiError> {
        Err(self.core.unsupported("fmi2GetInteger", vrs, "FMI 2.0 has no 64-bit integers"))
    }

    pub fn set_bool(&mut self, vrs: &[Vr], values: &[bool]) -> Result<(), FmiError> {
        self.core.check_len("fmi2SetBoolean", vrs, values.len())?;
        let v: Vec<c_int> = values.iter().map(|&x| b(x)).collect();
        self.call("fmi2SetBoolean", vrs, Ctx::None, |f, h| unsafe {
            (f.set_boolean)(h, vrs.as_ptr(), vrs.len(), v.as_ptr())
        })
        .map(drop)
    }

    pub fn get_bool(&mut self, vrs: &[Vr], values: &mut [bool]) -> Result<(), FmiError> {
        self.core.check_len("fmi2GetBoolean", vrs, values.len())?;
        let mut v = vec![0 as c_int; vrs.len()];
        self.call("fmi2GetBoolean", vrs, Ctx::None, |f, h| unsafe {
            (f.get_boolean)(h, vrs.as_ptr(), vrs.len(), v.as_mut_ptr())
        })?;
        values.iter_mut().zip(v).for_each(|(o, x)| *o = x != 0);
        Ok(())
    }

    pub fn set_string(&mut self, vr: Vr, value: &str) -> Result<(), FmiError> {
        let c = CString::new(value)
            .map_err(|_| self.core.refuse("fmi2SetString", &[vr], "the string contains a NUL byte"))?;
        let p = c.as_ptr();
        self.call("fmi2SetString", &[vr], Ctx::None, |f, h| unsafe { (f.set_string)(h, &vr, 1, &p) }).map(drop)
    }

    pub fn get_string(&mut self, vr: Vr) -> Result<String, FmiError> {
        let mut p: *const c_char = ptr::null();
        self.call("fmi2GetString", &[vr], Ctx::None, |f, h| unsafe { (f.get_string)(h, &vr, 1, &mut p) })?;
        if p.is_null() {
            return Err(self.core.refuse("fmi2GetString", &[vr], "the FMU returned a NULL string"));
        }
        // SAFETY: a NUL-terminated string valid until the FMU's next call.
        Ok(unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned())
    }

    pub fn set_binary(&mut self, vr: Vr, _value: &[u8]) -> Result<(), FmiError> {
        Err(self.core.unsupported("fmi2SetBinary", &[vr], "FMI 2.0 has no Binary variables"))
    }

    pub fn get_binary_ref(&mut self, vr: Vr) -> Result<&[u8], FmiError> {
        Err(self.core.unsupported("fmi2GetBinary", &[vr], "FMI 2.0 has no Binary variables"))
    }

    fn state_flags(&self) -> [(bool, &'static str); 1] {
        [(self.core.can_get_and_set_state, "canGetAndSetFMUstate")]
    }

    pub fn get_state(&mut self) -> Result<FmuState, FmiError> {
        const F: &str = "fmi2GetFMUstate";
        let get = self.core.optional(F, &self.state_flags(), self.lib.f.get_fmu_state)?;
        let mut s: ffi::Fmi2FmuState = ptr::null_mut();
        self.call(F, &[], Ctx::None, |_, h| unsafe { get(h, &mut s) })?;
        if s.is_null() {
            return Err(self.core.refuse(F, &[], "the FMU returned a NULL state"));
        }
        Ok(self.core.keep_state(s, self.core.state))
    }

    pub fn set_state(&mut self, state: &FmuState) -> Result<(), FmiError> {
        const F: &str = "fmi2SetFMUstate";
        let set = self.core.optional(F, &self.state_flags(), self.lib.f.set_fmu_state)?;
        let (s, saved_in) = self.core.own_state(F, state)?;
        self.call(F, &[], Ctx::None, |_, h| unsafe { set(h, s) })?;
        self.core.state = saved_in;
        Ok(())
    }

    pub fn serialize_state(&mut self, state: &FmuState) -> Result<(Vec<u8>, InstanceState), FmiError> {
        const F: &str = "fmi2SerializeFMUstate";
        let needs = [(self.core.can_serialize_state, "canSerializeFMUstate"), self.state_flags()[0]];
        let size_fn = self.core.optional(F, &needs, self.lib.f.serialized_fmu_state_size)?;
        let ser = self.core.optional(F, &needs, self.lib.f.serialize_fmu_state)?;
        let (s, saved_in) = self.core.own_state(F, state)?;
        let mut size = 0usize;
        self.call("fmi2SerializedFMUstateSize", &[], Ctx::None, |_, h| unsafe { size_fn(h, s, &mut size) })?;
        let mut bytes = vec![0u8; size];
        self.call(F, &[], Ctx::None, |_, h| unsafe { ser(h, s, bytes.as_mut_ptr() as *mut c_char, size) })?;
        Ok((bytes, saved_in))
    }

    pub fn deserialize_state(&mut self, bytes: &[u8], saved_in: InstanceState) -> Result<FmuState, FmiError> {
        const F: &str = "fmi2DeSerializeFMUstate";
        let needs = [(self.core.can_serialize_state, "canSerializeFMUstate"), self.state_flags()[0]];
        let de = self.core.optional(F, &needs, self.lib.f.deserialize_fmu_state)?;
        if matches!(saved_in, InstanceState::Fatal | InstanceState::Error) {
            return Err(self.core.refuse(F, &[], &format!("refused: no state is saved in {saved_in:?} (not called)")));
        }
        let mut s: ffi::Fmi2FmuState = ptr::null_mut();
        self.call(F, &[], Ctx::None, |_, h| unsafe { de(h, bytes.as_ptr() as *const c_char, bytes.len(), &mut s) })?;
        if s.is_null() {
            return Err(self.core.refuse(F, &[], "the FMU returned a NULL state"));
        }
        Ok(self.core.keep_state(s, saved_in))
    }

    pub fn free_state(&mut self, state: FmuState) -> Result<(), FmiError> {
        const F: &str = "fmi2FreeFMUstate";
        let free = self.core.optional(F, &self.state_flags(), self.lib.f.free_fmu_state)?;
        let (mut s, _) = self.core.own_state(F, &state)?;
        self.core.fmu_states[state.slot] = None;
        self.call(F, &[], Ctx::None, |_, h| unsafe { free(h, &mut s) }).map(drop)
    }

    // ---- model exchange (for crate::me) ----

    fn me(&self, function: &str) -> Result<&MeFunctions, FmiError> {
        self.lib.f.me.as_ref().ok_or_else(|| self.core.unsupported(function, &[], "this instance is co-simulation"))
    }

    pub(crate) fn me_call(
        &mut self,
        function: &'static str,
        context: Ctx,
        f: impl FnOnce(&MeFunctions, Fmi2Component) -> ffi::Fmi2Status,
    ) -> Result<Status, FmiError> {
        self.me(function)?;
        let mark = self.core.before(function, &[], context)?;
        let me = self.lib.f.me.as_ref().expect("checked above");
        let raw = f(me, self.handle);
        self.core.after(function, &[], context, mark, raw)
    }

    pub(crate) fn set_state_machine(&mut self, s: InstanceState) {
        self.core.state = s;
    }
}

impl crate::me::ModelExchange for Instance {
    fn enter_event_mode(&mut self) -> Result<(), FmiError> {
        self.me_call("fmi2EnterEventMode", Ctx::None, |f, h| unsafe { (f.enter_event_mode)(h) }).map(drop)
    }

    fn update_discrete_states(&mut self) -> Result<crate::me::EventUpdate, FmiError> {
        let mut info = EventInfo::default();
        self.me_call("fmi2NewDiscreteStates", Ctx::None, |f, h| unsafe { (f.new_discrete_states)(h, &mut info) })?;
        Ok(crate::me::EventUpdate {
            again: info.new_discrete_states_needed != 0,
            terminate: info.terminate_simulation != 0,
            states_changed: info.values_of_continuous_states_changed != 0,
            next_event_time: (info.next_event_time_defined != 0).then_some(info.next_event_time),
        })
    }

    fn enter_continuous_time_mode(&mut self) -> Result<(), FmiError> {
        self.me_call("fmi2EnterContinuousTimeMode", Ctx::None, |f, h| unsafe { (f.enter_continuous_time_mode)(h) })
            .map(drop)
    }

    fn completed_integrator_step(&mut self) -> Result<(bool, bool), FmiError> {
        let (mut event, mut term) = (0, 0);
        self.me_call("fmi2CompletedIntegratorStep", Ctx::None, |f, h| unsafe {
            (f.completed_integrator_step)(h, 1, &mut event, &mut term)
        })?;
        Ok((event != 0, term != 0))
    }

    fn set_time(&mut self, t: f64) -> Result<(), FmiError> {
        self.me_call("fmi2SetTime", Ctx::At(t), |f, h| unsafe { (f.set_time)(h, t) }).map(drop)
    }

    fn set_continuous_states(&mut self, x: &[f64]) -> Result<(), FmiError> {
        self.me_call("fmi2SetContinuousStates", Ctx::None, |f, h| unsafe {
            (f.set_continuous_states)(h, x.as_ptr(), x.len())
        })
        .map(drop)
    }

    fn get_continuous_states(&mut self, x: &mut [f64]) -> Result<(), FmiError> {
        self.me_call("fmi2GetContinuousStates", Ctx::None, |f, h| unsafe {
            (f.get_continuous_states)(h, x.as_mut_ptr(), x.len())
        })
        .map(drop)
    }

    fn get_derivatives(&mut self, dx: &mut [f64]) -> Result<(), FmiError> {
        self.me_call("fmi2GetDerivatives", Ctx::None, |f, h| unsafe {
            (f.get_derivatives)(h, dx.as_mut_ptr(), dx.len())
        })
        .map(drop)
    }

    fn get_event_indicators(&mut self, z: &mut [f64]) -> Result<(), FmiError> {
        self.me_call("fmi2GetEventIndicators", Ctx::None, |f, h| unsafe {
            (f.get_event_indicators)(h, z.as_mut_ptr(), z.len())
        })
        .map(drop)
    }

    fn set_wrapper_state(&mut self, s: InstanceState) {
        self.set_state_machine(s)
    }
}

crate::fmu::delegate_fmu_instance!(Instance);

impl Drop for Instance {
    /// See `Core::release`; `sink` and then `lib` are dropped after this, i.e. after the
    /// FMU can no longer log.
    fn drop(&mut self) {
        if self.handle.is_null() {
            return;
        }
        let (f, h) = (&self.lib.f, self.handle);
        // SAFETY: the handle is live (never freed before; nulled right after freeing), and
        // each call has the fmi2 signature of its symbol.
        self.core.release(
            "fmi2",
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

/// The FMI 2.0 `fmuResourceLocation`: a `file://` URI of the resources directory,
/// percent-encoding what a URI path may not hold.
fn resource_uri(dir: &Path) -> String {
    let abs = std::fs::canonicalize(dir).unwrap_or_else(|_| dir.to_path_buf());
    let mut s = String::from("file://");
    for byte in abs.to_string_lossy().bytes() {
        match byte {
            b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'/' | b'-' | b'_' | b'.' | b'~' => s.push(byte as char),
            _ => s.push_str(&format!("%{byte:02X}")),
        }
    }
    if !s.ends_with('/') {
        s.push('/');
    }
    s
}
