//! Model exchange: the master integrates an ME FMU's continuous states itself, so the FMU
//! steps like a co-simulation one. [`Integrated`] wraps an FMI 2 or FMI 3 ME instance and
//! implements [`FmuInstance`]: one classic explicit Runge-Kutta (RK4) step per system step,
//! cut at time events.
//!
//! Events:
//! - time events (the FMU's `nextEventTime`): the step is split there, the event is handled
//!   in Event Mode, and integration goes on from the updated states;
//! - step events (`completedIntegratorStep` asks for Event Mode): handled at the end of the
//!   step;
//! - state events (event indicators changing sign) are not located: a sign change is an
//!   error naming the FMU and the indicator, rather than a silently wrong result.

use std::collections::BTreeMap;

use crate::fmu::{FmiError, FmiErrorInfo, FmuInstance, FmuState, InstanceState, LogMessage, StepResult, Vr};
use crate::model_description::{FmiVersion, Interface, ModelExchangeInfo};

/// What one pass of event iteration returned (`fmi2NewDiscreteStates`,
/// `fmi3UpdateDiscreteStates`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EventUpdate {
    /// Another pass is needed.
    pub again: bool,
    pub terminate: bool,
    /// The continuous states were changed (re-read them).
    pub states_changed: bool,
    pub next_event_time: Option<f64>,
}

/// The model-exchange calls the integrator needs, on top of the common ones.
pub trait ModelExchange: FmuInstance {
    fn enter_event_mode(&mut self) -> Result<(), FmiError>;
    fn update_discrete_states(&mut self) -> Result<EventUpdate, FmiError>;
    fn enter_continuous_time_mode(&mut self) -> Result<(), FmiError>;
    /// (enter event mode, terminate simulation).
    fn completed_integrator_step(&mut self) -> Result<(bool, bool), FmiError>;
    fn set_time(&mut self, t: f64) -> Result<(), FmiError>;
    fn set_continuous_states(&mut self, x: &[f64]) -> Result<(), FmiError>;
    fn get_continuous_states(&mut self, x: &mut [f64]) -> Result<(), FmiError>;
    fn get_derivatives(&mut self, dx: &mut [f64]) -> Result<(), FmiError>;
    fn get_event_indicators(&mut self, z: &mut [f64]) -> Result<(), FmiError>;
    /// Sets the wrapper's view of the state machine (the integrator moves it).
    fn set_wrapper_state(&mut self, s: InstanceState);
}

/// Most event-iteration passes before the FMU is deemed stuck.
const MAX_EVENT_PASSES: usize = 100;

/// An ME instance stepped by fixed-step RK4 (see the module doc).
pub struct Integrated<I: ModelExchange> {
    inner: I,
    needs_completed: bool,
    x: Vec<f64>,
    k: [Vec<f64>; 4],
    probe: Vec<f64>,
    z: Vec<f64>,
    z_new: Vec<f64>,
    next_event: Option<f64>,
    /// Where the FMU's time stands (the next step must start here).
    time: f64,
    /// The integrator's own state per saved FMU state slot.
    saved: BTreeMap<usize, (Option<f64>, Vec<f64>, f64)>,
}

impl<I: ModelExchange> Integrated<I> {
    pub fn new(inner: I, info: &ModelExchangeInfo) -> Integrated<I> {
        let n = info.states.len();
        Integrated {
            inner,
            needs_completed: info.needs_completed_integrator_step,
            x: vec![0.0; n],
            k: std::array::from_fn(|_| vec![0.0; n]),
            probe: vec![0.0; n],
            z: vec![0.0; info.number_of_event_indicators],
            z_new: vec![0.0; info.number_of_event_indicators],
            next_event: None,
            time: 0.0,
            saved: BTreeMap::new(),
        }
    }

    pub fn inner(&mut self) -> &mut I {
        &mut self.inner
    }

    fn error(&self, function: &str, detail: String) -> FmiError {
        FmiErrorInfo {
            instance: self.inner.name().to_string(),
            model: self.inner.model_name().to_string(),
            function: function.to_string(),
            context: None,
            variables: vec![],
            status: None,
            detail: Some(detail),
            messages: vec![],
            step: None,
        }
        .into()
    }

    /// Event Mode until the FMU needs no more passes, then back to Continuous-Time Mode.
    /// Returns whether the FMU asked to terminate.
    fn handle_event(&mut self, enter: bool) -> Result<bool, FmiError> {
        if enter {
            self.inner.enter_event_mode()?;
        }
        let mut terminate = false;
        let mut states_changed = false;
        for pass in 0.. {
            if pass == MAX_EVENT_PASSES {
                return Err(self.error(
                    "event iteration",
                    format!("the FMU still needed new discrete states after {MAX_EVENT_PASSES} passes"),
                ));
            }
            let u = self.inner.update_discrete_states()?;
            terminate |= u.terminate;
            states_changed |= u.states_changed;
            self.next_event = u.next_event_time;
            if !u.again || terminate {
                break;
            }
        }
        self.inner.enter_continuous_time_mode()?;
        self.inner.set_wrapper_state(InstanceState::StepMode);
        if states_changed || !self.x.is_empty() {
            self.inner.get_continuous_states(&mut self.x)?;
        }
        if !self.z.is_empty() {
            self.inner.get_event_indicators(&mut self.z)?;
        }
        Ok(terminate)
    }

    /// Derivatives at (t, x + a * k[from]) into k[to] (`from` None: at x).
    fn slope(&mut self, t: f64, a: f64, from: Option<usize>, to: usize) -> Result<(), FmiError> {
        match from {
            None => self.probe.copy_from_slice(&self.x),
            Some(j) => {
                for i in 0..self.x.len() {
                    self.probe[i] = self.x[i] + a * self.k[j][i];
                }
            }
        }
        self.inner.set_time(t)?;
        self.inner.set_continuous_states(&self.probe)?;
        let mut k = std::mem::take(&mut self.k[to]);
        let r = self.inner.get_derivatives(&mut k);
        self.k[to] = k;
        r
    }

    /// One RK4 step of length h from t; leaves the FMU at (t + h, x(t + h)).
    fn rk4(&mut self, t: f64, h: f64) -> Result<(), FmiError> {
        if !self.x.is_empty() {
            self.slope(t, 0.0, None, 0)?;
            self.slope(t + h / 2.0, h / 2.0, Some(0), 1)?;
            self.slope(t + h / 2.0, h / 2.0, Some(1), 2)?;
            self.slope(t + h, h, Some(2), 3)?;
            for i in 0..self.x.len() {
                self.x[i] += h / 6.0 * (self.k[0][i] + 2.0 * self.k[1][i] + 2.0 * self.k[2][i] + self.k[3][i]);
            }
        }
        self.inner.set_time(t + h)?;
        if !self.x.is_empty() {
            self.inner.set_continuous_states(&self.x)?;
        }
        Ok(())
    }

    /// Refuses a state event: an indicator changed sign during the step.
    fn check_state_events(&mut self, t: f64) -> Result<(), FmiError> {
        if self.z.is_empty() {
            return Ok(());
        }
        self.inner.get_event_indicators(&mut self.z_new)?;
        if let Some(i) = (0..self.z.len()).find(|&i| (self.z[i] > 0.0) != (self.z_new[i] > 0.0)) {
            return Err(self.error(
                "state event",
                format!(
                    "event indicator {i} changed sign before t={t} ({} -> {}): agrisim's fixed-step integrator does not locate state events; use a co-simulation build of this model",
                    self.z[i], self.z_new[i]
                ),
            ));
        }
        std::mem::swap(&mut self.z, &mut self.z_new);
        Ok(())
    }
}

impl<I: ModelExchange> FmuInstance for Integrated<I> {
    fn name(&self) -> &str {
        self.inner.name()
    }
    fn model_name(&self) -> &str {
        self.inner.model_name()
    }
    fn fmi_version(&self) -> FmiVersion {
        self.inner.fmi_version()
    }
    fn interface(&self) -> Interface {
        Interface::ModelExchange
    }
    fn state(&self) -> InstanceState {
        self.inner.state()
    }
    fn take_log(&mut self) -> Vec<LogMessage> {
        self.inner.take_log()
    }
    fn log_count(&self) -> u64 {
        self.inner.log_count()
    }
    fn set_debug_logging(&mut self, on: bool, categories: &[&str]) -> Result<(), FmiError> {
        self.inner.set_debug_logging(on, categories)
    }
    fn enter_initialization_mode(&mut self, start_time: f64, stop_time: Option<f64>) -> Result<(), FmiError> {
        self.inner.enter_initialization_mode(start_time, stop_time)?;
        self.time = start_time;
        Ok(())
    }

    /// Leaves Initialization Mode into Event Mode, runs the initial event iteration and
    /// enters Continuous-Time Mode.
    fn exit_initialization_mode(&mut self) -> Result<(), FmiError> {
        self.inner.exit_initialization_mode()?;
        if self.handle_event(false)? {
            return Err(self.error("initial event iteration", "the FMU asked to terminate at initialization".into()));
        }
        Ok(())
    }

    fn do_step(&mut self, t: f64, h: f64) -> Result<StepResult, FmiError> {
        if self.inner.state() != InstanceState::StepMode {
            return Err(self.error(
                "do_step (model exchange)",
                format!("refused: not allowed in state {:?} (not called)", self.inner.state()),
            ));
        }
        let end = t + h;
        // Events closer than this to a step end coincide with it (steps are whole ns).
        let eps = 1e-12 * end.abs().max(1.0);
        // As a co-simulation FMU would: a step starts where the last one ended, and is
        // positive and finite.
        if !(t.is_finite() && h.is_finite() && h > 0.0 && (t - self.time).abs() <= eps) {
            return Err(self.error(
                "do_step (model exchange)",
                format!("refused: a step from t={t} with h={h}; the FMU is at t={} (not called)", self.time),
            ));
        }
        let mut now = t;
        let mut result = StepResult {
            event_handling_needed: false,
            terminate_simulation: false,
            early_return: false,
            last_successful_time: end,
        };
        while now < end - eps {
            let stop = match self.next_event {
                Some(te) if te > now + eps && te < end - eps => te,
                _ => end,
            };
            self.rk4(now, stop - now)?;
            now = stop;
            self.check_state_events(now)?;
            let (step_event, terminate) =
                if self.needs_completed { self.inner.completed_integrator_step()? } else { (false, false) };
            let time_event = self.next_event.is_some_and(|te| te <= now + eps);
            let mut stop_now = terminate;
            if step_event || time_event {
                stop_now |= self.handle_event(true)?;
            }
            if stop_now {
                result.terminate_simulation = true;
                result.last_successful_time = now;
                break;
            }
        }
        self.time = result.last_successful_time;
        Ok(result)
    }

    fn terminate(&mut self) -> Result<(), FmiError> {
        self.inner.terminate()
    }
    fn reset(&mut self) -> Result<(), FmiError> {
        self.next_event = None;
        self.time = 0.0;
        self.inner.reset()
    }
    fn set_f64(&mut self, vrs: &[Vr], values: &[f64]) -> Result<(), FmiError> {
        self.inner.set_f64(vrs, values)
    }
    fn get_f64(&mut self, vrs: &[Vr], values: &mut [f64]) -> Result<(), FmiError> {
        self.inner.get_f64(vrs, values)
    }
    fn set_i32(&mut self, vrs: &[Vr], values: &[i32]) -> Result<(), FmiError> {
        self.inner.set_i32(vrs, values)
    }
    fn get_i32(&mut self, vrs: &[Vr], values: &mut [i32]) -> Result<(), FmiError> {
        self.inner.get_i32(vrs, values)
    }
    fn set_i64(&mut self, vrs: &[Vr], values: &[i64]) -> Result<(), FmiError> {
        self.inner.set_i64(vrs, values)
    }
    fn get_i64(&mut self, vrs: &[Vr], values: &mut [i64]) -> Result<(), FmiError> {
        self.inner.get_i64(vrs, values)
    }
    fn set_bool(&mut self, vrs: &[Vr], values: &[bool]) -> Result<(), FmiError> {
        self.inner.set_bool(vrs, values)
    }
    fn get_bool(&mut self, vrs: &[Vr], values: &mut [bool]) -> Result<(), FmiError> {
        self.inner.get_bool(vrs, values)
    }
    fn set_string(&mut self, vr: Vr, value: &str) -> Result<(), FmiError> {
        self.inner.set_string(vr, value)
    }
    fn get_string(&mut self, vr: Vr) -> Result<String, FmiError> {
        self.inner.get_string(vr)
    }
    fn set_binary(&mut self, vr: Vr, value: &[u8]) -> Result<(), FmiError> {
        self.inner.set_binary(vr, value)
    }
    fn get_binary_ref(&mut self, vr: Vr) -> Result<&[u8], FmiError> {
        self.inner.get_binary_ref(vr)
    }
    /// The FMU's state and the integrator's (next time event, indicator signs) with it.
    fn get_state(&mut self) -> Result<FmuState, FmiError> {
        let s = self.inner.get_state()?;
        self.saved.insert(s.slot, (self.next_event, self.z.clone(), self.time));
        Ok(s)
    }
    fn set_state(&mut self, state: &FmuState) -> Result<(), FmiError> {
        self.inner.set_state(state)?;
        if let Some((next, z, time)) = self.saved.get(&state.slot) {
            self.next_event = *next;
            self.z.clone_from(z);
            self.time = *time;
        }
        if !self.x.is_empty() {
            self.inner.get_continuous_states(&mut self.x)?;
        }
        Ok(())
    }
    fn serialize_state(&mut self, state: &FmuState) -> Result<(Vec<u8>, InstanceState), FmiError> {
        Err(self.error(
            "serialize_state (model exchange)",
            format!("refused for FMU state slot {}: the integrator's own state is not serialized", state.slot),
        ))
    }
    fn deserialize_state(&mut self, _bytes: &[u8], _saved_in: InstanceState) -> Result<FmuState, FmiError> {
        Err(self.error("deserialize_state (model exchange)", "refused: see serialize_state".into()))
    }
    fn free_state(&mut self, state: FmuState) -> Result<(), FmiError> {
        self.saved.remove(&state.slot);
        self.inner.free_state(state)
    }
}
