//! One FMU instance: the model, its variable values, the state machine mode and the time.
//! API-independent; the FMI 3 and FMI 2 layers are thin translations onto these methods.
//!
//! Methods return `Err(message)` for anything the importer did wrong or the model reported;
//! the entry guard prefixes the function name, logs it and moves the instance to Error.

use std::ffi::{c_void, CString};
use std::panic::catch_unwind;

use crate::ctype::CType;
use crate::logger::Logger;
use crate::model::{is_model_exchange, Model};
use crate::registry::Api;
use crate::serial;
use crate::state::{settable, Mode};
use crate::store::{Store, Value};
use crate::var::{Causality, Var};

/// Where a value reference points.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Slot {
    /// vr 0, the independent variable.
    Time,
    /// Index into the model's variable table (vr - 1).
    Var(usize),
}

/// A saved FMU state (`fmi3FMUState` / `fmi2FMUstate`): everything that changes over a run.
#[derive(Clone)]
pub struct Snapshot<M: Model> {
    model: M,
    store: Store,
    mode: Mode,
    time: f64,
    start_time: f64,
    stop_time: Option<f64>,
    /// Its serialized form, made once (SerializedFMUStateSize, then SerializeFMUState).
    serialized: Option<Vec<u8>>,
}

pub struct Instance<M: Model> {
    pub api: Api,
    pub logger: Logger,
    pub mode: Mode,
    pub model: M,
    pub store: Store,
    /// Current time: the start time until the first step, then the end of the last step.
    pub time: f64,
    pub start_time: f64,
    pub stop_time: Option<f64>,
    /// In Initialization Mode: model and values after `initialize` on a clone, so getters
    /// return outputs consistent with the parameters set so far. Cleared by every set that
    /// changes a value.
    preview: Option<(M, Store)>,
    /// Strings returned by GetString, alive until the next GetString.
    strings: Vec<CString>,
    /// FMU states handed out and not yet freed (only these pointers are ever dereferenced).
    states: Vec<*mut Snapshot<M>>,
    /// Model exchange: time, states or inputs changed since the last `Model::evaluate`, so
    /// derivatives and outputs in the store are out of date.
    stale: bool,
}

/// What Event Mode's discrete-state update reports (fmi2EventInfo / fmi3UpdateDiscreteStates).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EventInfo {
    pub values_of_continuous_states_changed: bool,
    pub next_event_time: Option<f64>,
}

impl<M: Model> Drop for Instance<M> {
    fn drop(&mut self) {
        for s in self.states.drain(..) {
            // SAFETY: every pointer in `states` came from Box::into_raw and was not freed.
            drop(unsafe { Box::from_raw(s) });
        }
    }
}

/// Whether the model has run `initialize` in this mode (its state is worth saving).
fn initialized(mode: Mode) -> bool {
    matches!(mode, Mode::StepMode | Mode::Terminated | Mode::EventMode | Mode::ContinuousTimeMode)
}

/// Parameters (and everything else fixed before the run) bit for bit equal.
fn same_parameters<M: Model>(a: &Store, b: &Store) -> bool {
    M::VARIABLES.iter().enumerate().all(|(i, v)| {
        !matches!(v.causality, Causality::Parameter | Causality::CalculatedParameter)
            || a.value(i).identical(b.value(i))
    })
}

/// A deserialized store matches the variable table: count and types.
fn check_store<M: Model>(store: &Store) -> Result<(), String> {
    if store.len() != M::VARIABLES.len() {
        return Err(format!("corrupt FMU state: {} values for {} variables", store.len(), M::VARIABLES.len()));
    }
    for (i, v) in M::VARIABLES.iter().enumerate() {
        if std::mem::discriminant(store.value(i)) != std::mem::discriminant(&Value::from_start(&v.start)) {
            return Err(format!("corrupt FMU state: variable '{}' has the wrong type", v.name));
        }
    }
    Ok(())
}

/// Message of a caught panic payload.
pub fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "(non-string panic payload)".to_string()
    }
}

impl<M: Model> Instance<M> {
    pub fn new(api: Api, logger: Logger) -> Result<Instance<M>, String> {
        let model = catch_unwind(M::new).map_err(|p| format!("the model panicked in new(): {}", panic_message(&*p)))?;
        Ok(Instance {
            api,
            logger,
            mode: Mode::Instantiated,
            model,
            store: Store::new(M::VARIABLES),
            time: 0.0,
            start_time: 0.0,
            stop_time: None,
            preview: None,
            strings: Vec::new(),
            states: Vec::new(),
            stale: false,
        })
    }

    /// Back to a freshly instantiated model. A model that panics here cannot be rebuilt:
    /// the caller turns the error into Fatal.
    pub fn reset(&mut self) -> Result<(), String> {
        self.preview = None;
        self.strings.clear();
        self.model =
            catch_unwind(M::new).map_err(|p| format!("the model panicked in new(): {}", panic_message(&*p)))?;
        self.store = Store::new(M::VARIABLES);
        self.time = 0.0;
        self.start_time = 0.0;
        self.stop_time = None;
        self.mode = Mode::Instantiated;
        self.stale = false;
        Ok(())
    }

    pub fn var_name(&self, slot: Slot) -> String {
        match slot {
            Slot::Time => "'time' (vr 0)".to_string(),
            Slot::Var(i) => format!("'{}' (vr {})", M::VARIABLES[i].name, i + 1),
        }
    }

    /// Resolves a value reference visible through this instance's API.
    pub fn slot(&self, vr: u32) -> Result<Slot, String> {
        if vr == 0 {
            return Ok(Slot::Time);
        }
        let i = vr as usize - 1;
        match M::VARIABLES.get(i) {
            Some(v) if self.api == Api::Fmi3 || v.fmi2_representable() => Ok(Slot::Var(i)),
            Some(v) => Err(format!(
                "value reference {vr} ('{}') is not available through FMI 2.0 (its type has no FMI 2 equivalent)",
                v.name
            )),
            None => Err(format!("unknown value reference {vr} (valid: 0..={})", M::VARIABLES.len())),
        }
    }

    fn type_name(&self, v: &Value) -> &'static str {
        match (v, self.api) {
            (Value::Float64(_), Api::Fmi2) => "Real",
            (Value::Int32(_), Api::Fmi2) => "Integer",
            (Value::Float64(_), _) => "Float64",
            (Value::Int32(_), _) => "Int32",
            (Value::Int64(_), _) => "Int64",
            (Value::Boolean(_), _) => "Boolean",
            (Value::String(_), _) => "String",
            (Value::Binary(_), _) => "Binary",
        }
    }

    /// Values to read from: the initialization preview in Initialization Mode.
    fn ensure_view(&mut self) -> Result<(), String> {
        if self.mode == Mode::InitializationMode && self.preview.is_none() {
            let (mut model, mut store) = (self.model.clone(), self.store.clone());
            model
                .initialize(&mut store, self.start_time, &mut self.logger)
                .map_err(|e| format!("the model failed to initialize (while computing initial values): {e}"))?;
            if is_model_exchange::<M>() {
                model
                    .evaluate(&mut store, self.start_time)
                    .map_err(|e| format!("the model failed to evaluate its initial derivatives: {e}"))?;
            }
            check_output_sizes::<M>(&store)?;
            self.preview = Some((model, store));
        }
        self.refresh()
    }

    /// Model exchange: brings derivatives and outputs up to date with time, states and
    /// inputs (lazily: an integrator sets states far more often than it reads outputs).
    fn refresh(&mut self) -> Result<(), String> {
        if self.stale {
            self.model
                .evaluate(&mut self.store, self.time)
                .map_err(|e| format!("the model failed to evaluate at t={:?}: {e}", self.time))?;
            check_output_sizes::<M>(&self.store)?;
            self.stale = false;
        }
        Ok(())
    }

    /// Typed getter for `vrs`; one C value per reference (all variables are scalars).
    pub fn get<T: CType>(&mut self, vrs: &[u32]) -> Result<Vec<T::C>, String> {
        let slots = vrs.iter().map(|&vr| self.slot(vr)).collect::<Result<Vec<_>, _>>()?;
        self.ensure_view()?;
        self.strings.clear();
        let mut out = Vec::with_capacity(slots.len());
        for slot in slots {
            let time;
            let value = match slot {
                Slot::Time => {
                    time = Value::Float64(self.time);
                    &time
                }
                Slot::Var(i) => match (&self.preview, self.mode) {
                    (Some((_, s)), Mode::InitializationMode) => s.value(i),
                    _ => self.store.value(i),
                },
            };
            if !T::accepts(value) {
                return Err(format!(
                    "variable {} has type {}, which this function cannot access",
                    self.var_name(slot),
                    self.type_name(value)
                ));
            }
            out.push(T::read(value, &mut self.strings));
        }
        Ok(out)
    }

    /// Typed setter: validates every reference and value first, then applies all of them.
    ///
    /// # Safety
    /// Pointers inside `values` must be valid (see [`CType::decode`]).
    pub unsafe fn set<T: CType>(&mut self, vrs: &[u32], values: &[T::C]) -> Result<(), String> {
        let mut decoded = Vec::with_capacity(vrs.len());
        for (&vr, &x) in vrs.iter().zip(values) {
            let slot = self.slot(vr)?;
            let Slot::Var(i) = slot else {
                return Err("cannot set 'time' (vr 0): the independent variable advances only with DoStep".into());
            };
            let var = &M::VARIABLES[i];
            let current = self.store.value(i);
            if !T::accepts(current) {
                return Err(format!(
                    "variable {} has type {}, which this function cannot set",
                    self.var_name(slot),
                    self.type_name(current)
                ));
            }
            settable(var, self.mode).map_err(|why| format!("cannot set variable {}: {why}", self.var_name(slot)))?;
            if T::size(x) > var.max_size {
                return Err(format!(
                    "bad value for variable {}: {} bytes exceed its maxSize of {} bytes",
                    self.var_name(slot),
                    T::size(x),
                    var.max_size
                ));
            }
            let value = T::decode(x).map_err(|e| format!("bad value for variable {}: {e}", self.var_name(slot)))?;
            check_value(var, &value).map_err(|e| format!("bad value for variable {}: {e}", self.var_name(slot)))?;
            decoded.push((i, value));
        }
        // The initialization preview stays valid while nothing changes: an importer that
        // propagates the same values again (iterating to a consistent start) must not make a
        // heavy model (the world: scene + physics) initialize again.
        for (i, value) in decoded {
            if !self.store.value(i).identical(&value) {
                *self.store.value_mut(i) = value;
                self.preview = None;
                self.stale = is_model_exchange::<M>() && initialized(self.mode);
            }
        }
        Ok(())
    }

    /// Start and stop time of the experiment (FMI 2 SetupExperiment; part of FMI 3 EnterInitializationMode).
    pub fn setup(&mut self, start: f64, stop: Option<f64>) -> Result<(), String> {
        if !start.is_finite() {
            return Err(format!("startTime must be finite, got {start}"));
        }
        if let Some(stop) = stop {
            if stop.is_nan() || stop < start {
                return Err(format!("stopTime ({stop}) must not be less than startTime ({start})"));
            }
        }
        self.start_time = start;
        self.stop_time = stop;
        self.time = start;
        Ok(())
    }

    pub fn enter_initialization(&mut self, start: f64, stop: Option<f64>) -> Result<(), String> {
        self.setup(start, stop)?;
        self.preview = None;
        self.mode = Mode::InitializationMode;
        Ok(())
    }

    /// Ends initialization: the model computes its initial outputs (reusing the preview
    /// computed for getters when nothing changed since).
    pub fn exit_initialization(&mut self) -> Result<(), String> {
        match self.preview.take() {
            Some((model, store)) => {
                self.model = model;
                self.store = store;
            }
            None => {
                self.model
                    .initialize(&mut self.store, self.start_time, &mut self.logger)
                    .map_err(|e| format!("the model failed to initialize: {e}"))?;
                check_output_sizes::<M>(&self.store)?;
                if is_model_exchange::<M>() {
                    self.model
                        .evaluate(&mut self.store, self.start_time)
                        .map_err(|e| format!("the model failed to evaluate its initial derivatives: {e}"))?;
                }
            }
        }
        // Model exchange starts with the initial event iteration (FMI 2.0 3.2.3, FMI 3.0 3.2).
        self.mode = if is_model_exchange::<M>() { Mode::EventMode } else { Mode::StepMode };
        self.stale = false;
        Ok(())
    }

    /// Advances from `tc` (the importer's time, adopted as is; it must match the FMU's time
    /// up to rounding) to `tc + h`.
    pub fn do_step(&mut self, tc: f64, h: f64) -> Result<(), String> {
        if !tc.is_finite() {
            return Err(format!("currentCommunicationPoint must be finite, got {tc}"));
        }
        if !(h > 0.0 && h.is_finite()) {
            return Err(format!("communicationStepSize must be positive and finite, got {h}"));
        }
        let end = tc + h;
        if !end.is_finite() {
            return Err(format!("the step would end at {end}"));
        }
        let tol = 1e-9 * self.time.abs().max(tc.abs()).max(1.0);
        if (tc - self.time).abs() > tol {
            return Err(format!(
                "currentCommunicationPoint ({tc:?}) differs from the FMU's current time ({:?})",
                self.time
            ));
        }
        if let Some(stop) = self.stop_time {
            if end > stop + 1e-9 * stop.abs().max(1.0) {
                return Err(format!("the step would end at {end:?}, after stopTime ({stop:?})"));
            }
        }
        self.time = tc;
        self.model
            .do_step(&mut self.store, tc, h, &mut self.logger)
            .map_err(|e| format!("the model failed in the step from t={tc:?} with h={h:?}: {e}"))?;
        check_output_sizes::<M>(&self.store)?;
        self.time = end;
        Ok(())
    }

    pub fn terminate(&mut self) {
        self.mode = Mode::Terminated;
    }

    fn snapshot(&self) -> Snapshot<M> {
        Snapshot {
            model: self.model.clone(),
            store: self.store.clone(),
            mode: self.mode,
            time: self.time,
            start_time: self.start_time,
            stop_time: self.stop_time,
            serialized: None,
        }
    }

    /// GetFMUState: a new state, or `existing` (a state of this instance) overwritten.
    pub fn get_state(&mut self, existing: *mut c_void) -> Result<*mut c_void, String> {
        let snap = self.snapshot();
        self.store_state(snap, existing)
    }

    /// `snap` as a new live state, or written over `existing` (a live state of this instance).
    fn store_state(&mut self, snap: Snapshot<M>, existing: *mut c_void) -> Result<*mut c_void, String> {
        if existing.is_null() {
            let p = Box::into_raw(Box::new(snap));
            self.states.push(p);
            return Ok(p.cast());
        }
        let p = self.find_state(existing)?;
        // SAFETY: `p` is a live state of this instance.
        unsafe { *p = snap };
        Ok(existing)
    }

    pub fn set_state(&mut self, state: *mut c_void) -> Result<(), String> {
        let p = self.find_state(state)?;
        // SAFETY: `p` is a live state of this instance.
        let s = unsafe { &*p };
        self.model = s.model.clone();
        self.store = s.store.clone();
        self.mode = s.mode;
        self.time = s.time;
        self.start_time = s.start_time;
        self.stop_time = s.stop_time;
        self.preview = None;
        // Derived values were saved with the store; evaluating again only costs time.
        self.stale = false;
        Ok(())
    }

    pub fn free_state(&mut self, state: *mut c_void) -> Result<(), String> {
        if state.is_null() {
            return Ok(());
        }
        let p = self.find_state(state)?;
        self.states.retain(|&q| q != p);
        // SAFETY: `p` came from Box::into_raw and was just removed from the live list.
        drop(unsafe { Box::from_raw(p) });
        Ok(())
    }

    fn find_state(&self, state: *mut c_void) -> Result<*mut Snapshot<M>, String> {
        if state.is_null() {
            return Err("the FMU state is NULL".into());
        }
        self.states
            .iter()
            .copied()
            .find(|&p| p.cast() == state)
            .ok_or_else(|| format!("{state:p} is not a live FMU state of this instance (freed, foreign or invalid)"))
    }

    /// A live state's serialized form (see [`serial`](crate::serial)), made on first request.
    pub fn serialized_state(&mut self, state: *mut c_void) -> Result<&[u8], String> {
        let p = self.find_state(state)?;
        // SAFETY: `p` is a live state of this instance.
        let snap = unsafe { &mut *p };
        if snap.serialized.is_none() {
            if matches!(snap.mode, Mode::Error | Mode::Fatal) {
                return Err(format!("a state taken in mode {} cannot be serialized", snap.mode.name()));
            }
            let mut model = Vec::new();
            if initialized(snap.mode) {
                snap.model.save_state(&mut model)?;
            }
            let header = serial::Header {
                model: M::NAME.to_string(),
                token: M::TOKEN.to_string(),
                mode: snap.mode,
                time: snap.time,
                start_time: snap.start_time,
                stop_time: snap.stop_time,
                store: snap.store.clone(),
                model_len: model.len() as u64,
            };
            snap.serialized = Some(serial::encode(&header, &model)?);
        }
        Ok(snap.serialized.as_deref().unwrap_or_default())
    }

    /// A new state (or `existing`, a live state, overwritten) from serialized bytes.
    ///
    /// The model's derived parts come from this instance's model when it is initialized
    /// with the very same parameter values, else from initializing a fresh model with the
    /// saved values; then the saved model state is loaded over them.
    pub fn deserialize_state(&mut self, bytes: &[u8], existing: *mut c_void) -> Result<*mut c_void, String> {
        let (h, model_bytes) = serial::decode(bytes)?;
        if h.model != M::NAME || h.token != M::TOKEN {
            return Err(format!(
                "the state belongs to model '{}' (token {}), not to '{}' (token {})",
                h.model,
                h.token,
                M::NAME,
                M::TOKEN
            ));
        }
        check_store::<M>(&h.store)?;
        let model = if initialized(h.mode) {
            let mut model = if initialized(self.mode) && same_parameters::<M>(&self.store, &h.store) {
                self.model.clone()
            } else {
                let mut model =
                    catch_unwind(M::new).map_err(|p| format!("the model panicked in new(): {}", panic_message(&*p)))?;
                model
                    .initialize(&mut h.store.clone(), h.start_time, &mut self.logger)
                    .map_err(|e| format!("the model failed to initialize (rebuilding a deserialized state): {e}"))?;
                model
            };
            model.load_state(model_bytes).map_err(|e| format!("cannot load the model state: {e}"))?;
            model
        } else if model_bytes.is_empty() {
            catch_unwind(M::new).map_err(|p| format!("the model panicked in new(): {}", panic_message(&*p)))?
        } else {
            return Err(format!("corrupt FMU state: model bytes in mode {}", h.mode.name()));
        };
        let snap = Snapshot {
            model,
            store: h.store,
            mode: h.mode,
            time: h.time,
            start_time: h.start_time,
            stop_time: h.stop_time,
            serialized: Some(bytes.to_vec()),
        };
        self.store_state(snap, existing)
    }

    // ---- Model exchange ------------------------------------------------------------------

    /// SetTime: any finite time (an integrator may go back within a rejected step).
    pub fn set_time(&mut self, t: f64) -> Result<(), String> {
        if !t.is_finite() {
            return Err(format!("time must be finite, got {t}"));
        }
        if t.to_bits() != self.time.to_bits() {
            self.time = t;
            self.stale = true;
        }
        Ok(())
    }

    fn check_nx(n: usize, what: &str) -> Result<(), String> {
        let nx = M::CONTINUOUS_STATES.len();
        if n != nx {
            return Err(format!("{what} is {n}, but this FMU has {nx} continuous states"));
        }
        Ok(())
    }

    /// SetContinuousStates: every value finite, else nothing is set.
    pub fn set_continuous_states(&mut self, x: &[f64]) -> Result<(), String> {
        Self::check_nx(x.len(), "nx (nContinuousStates)")?;
        if let Some((k, v)) = x.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(format!("state {k} ({}) is {v}, not finite", M::VARIABLES[M::CONTINUOUS_STATES[k].state].name));
        }
        for (s, &v) in M::CONTINUOUS_STATES.iter().zip(x) {
            self.store.set_f64(s.state, v);
        }
        self.stale = true;
        Ok(())
    }

    /// The store to read continuous values from (the preview in Initialization Mode), up to date.
    fn continuous_view(&mut self) -> Result<&Store, String> {
        self.ensure_view()?;
        Ok(match (&self.preview, self.mode) {
            (Some((_, s)), Mode::InitializationMode) => s,
            _ => &self.store,
        })
    }

    /// GetContinuousStates.
    pub fn continuous_states(&mut self, out: &mut [f64]) -> Result<(), String> {
        Self::check_nx(out.len(), "nx (nContinuousStates)")?;
        let store = self.continuous_view()?;
        for (o, s) in out.iter_mut().zip(M::CONTINUOUS_STATES) {
            *o = store.f64(s.state);
        }
        Ok(())
    }

    /// GetDerivatives / GetContinuousStateDerivatives.
    pub fn derivatives(&mut self, out: &mut [f64]) -> Result<(), String> {
        Self::check_nx(out.len(), "nx (nContinuousStates)")?;
        let store = self.continuous_view()?;
        for (o, s) in out.iter_mut().zip(M::CONTINUOUS_STATES) {
            *o = store.f64(s.derivative);
        }
        if let Some((k, v)) = out.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(format!("the derivative of state {k} is {v} at t={:?}", self.time));
        }
        Ok(())
    }

    /// GetNominalsOfContinuousStates (fixed by the model's declaration).
    pub fn nominals(&self, out: &mut [f64]) -> Result<(), String> {
        Self::check_nx(out.len(), "nx (nContinuousStates)")?;
        for (o, s) in out.iter_mut().zip(M::CONTINUOUS_STATES) {
            *o = s.nominal;
        }
        Ok(())
    }

    /// GetEventIndicators: this layer supports none (numberOfEventIndicators = 0).
    pub fn event_indicators(&self, n: usize) -> Result<(), String> {
        if n != 0 {
            return Err(format!("ni (nEventIndicators) is {n}, but this FMU has no event indicators"));
        }
        Ok(())
    }

    pub fn enter_event_mode(&mut self) {
        self.mode = Mode::EventMode;
    }

    /// NewDiscreteStates / UpdateDiscreteStates: the model handles the events due now.
    pub fn update_discrete_states(&mut self) -> Result<EventInfo, String> {
        self.refresh()?;
        let t = self.time;
        let changed = self
            .model
            .update_discrete_states(&mut self.store, t, &mut self.logger)
            .map_err(|e| format!("the model failed to handle the event at t={t:?}: {e}"))?;
        self.stale = true;
        self.refresh()?;
        let next = self.model.next_event_time(&self.store, t);
        if let Some(te) = next {
            if !(te.is_finite() && te > t) {
                return Err(format!("the model announced its next time event at {te:?}, not after t={t:?}"));
            }
        }
        Ok(EventInfo { values_of_continuous_states_changed: changed, next_event_time: next })
    }

    pub fn enter_continuous_time_mode(&mut self) {
        self.mode = Mode::ContinuousTimeMode;
    }

    /// Number of FMU states not yet freed (for tests).
    pub fn live_states(&self) -> usize {
        self.states.len()
    }
}

/// A model never hands out a Binary output above its declared maxSize: it fails instead.
fn check_output_sizes<M: Model>(store: &Store) -> Result<(), String> {
    for (i, v) in M::VARIABLES.iter().enumerate() {
        if let Value::Binary(b) = store.value(i) {
            if b.len() > v.max_size {
                return Err(format!(
                    "the model produced {} bytes for '{}' (vr {}), above its maxSize of {} bytes",
                    b.len(),
                    v.name,
                    i + 1,
                    v.max_size
                ));
            }
        }
    }
    Ok(())
}

/// Value checks beyond the type: finite floats and the declared range.
fn check_value(var: &Var, value: &Value) -> Result<(), String> {
    let x = match *value {
        Value::Float64(x) => {
            if !x.is_finite() {
                return Err(format!("{x} is not a finite number"));
            }
            x
        }
        Value::Int32(x) => x as f64,
        Value::Int64(x) => x as f64,
        _ => return Ok(()),
    };
    if let Some(min) = var.min {
        if x < min {
            return Err(format!("{x} is below its minimum {min}"));
        }
    }
    if let Some(max) = var.max {
        if x > max {
            return Err(format!("{x} is above its maximum {max}"));
        }
    }
    Ok(())
}
