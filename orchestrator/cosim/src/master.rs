//! The master algorithm: fixed step on integer ticks, Jacobi exchange in a fixed order, each
//! route at its own integer decimation of the step (physics every step, messages at their
//! connection's period), and a message instant for the algorithm layer.
//!
//! One communication point k (time t_k = k * step):
//!   1. FMU outputs due at k that go to system connectors reach the [`Hooks`] (messages only
//!      when their counter moved);
//!   2. [`Hooks::exchange`] runs (the algorithm layer's nodes, at message instants);
//!   3. routes into FMU inputs due at k are written (system connectors read from the hooks);
//!   4. [`Hooks::point`] closes the point (recording);
//!   5. every FMU steps from t_k to t_k+1, in system-file order.
//!
//! Nothing here reads a clock or iterates a hash map, so a run is a pure function of its
//! inputs and of what the hooks answer.

use crate::error::Result;
use crate::system::{Port, System};
use crate::value::{self, Value};

/// What the engine exchanges with the program around it at each communication point: the
/// system's own connectors (no component), and every message it moves.
pub trait Hooks {
    /// A message left an FMU on route `route` (an index into `system.routes`) at `t_ns`
    /// (bound for a system connector, or for another FMU: then it is shown here too, on the
    /// route's topic). An error stops the run.
    fn message(&mut self, _system: &System, _route: usize, _t_ns: i64, _bytes: &[u8]) -> Result<()> {
        Ok(())
    }
    /// A scalar FMU output reached system connector `connector`.
    fn scalar(&mut self, _connector: &str, _value: f64) {}
    /// Between outputs and inputs of point `t_ns`; `message_instant` at the message rate.
    fn exchange(&mut self, _t_ns: i64, _message_instant: bool) -> Result<()> {
        Ok(())
    }
    /// The newest message on system connector `connector` if its sequence number is above
    /// `*seen` (then `*seen` is updated).
    fn message_input(&mut self, _connector: &str, _seen: &mut i64) -> Option<Vec<u8>> {
        None
    }
    /// The current value of scalar system connector `connector`, if it has one.
    fn scalar_input(&self, _connector: &str) -> Option<f64> {
        None
    }
    /// The point `t_ns` is complete (inputs written, FMUs not yet stepped).
    fn point(&mut self, _system: &mut System, _t_ns: i64) -> Result<()> {
        Ok(())
    }
}

/// Hooks for a system run on its own: system connectors stay unconnected.
pub struct NoHooks;

impl Hooks for NoHooks {}

pub struct Master {
    pub system: System,
    step_ns: i64,
    message_ticks: u64,
    /// The next communication point.
    tick: u64,
}

fn time_of(tick: u64, step_ns: i64) -> f64 {
    (tick as i64 * step_ns) as f64 / 1e9
}

impl Master {
    pub fn new(system: System, step: f64, message_period: f64) -> Result<Master> {
        let step_ns = (step * 1e9).round() as i64;
        if step_ns <= 0 || ((step_ns as f64 / 1e9) - step).abs() > 1e-12 {
            return Err(crate::err!("step {step} s is not a positive whole number of nanoseconds"));
        }
        let message_ticks = crate::system::ticks_of(message_period, step, "message rate")?;
        Ok(Master { system, step_ns, message_ticks, tick: 0 })
    }

    /// Simulation time of the next communication point [s].
    pub fn time(&self) -> f64 {
        time_of(self.tick, self.step_ns)
    }

    /// The next communication point, in steps.
    pub fn tick(&self) -> u64 {
        self.tick
    }

    /// Simulation time of the next communication point [ns].
    pub fn time_ns(&self) -> i64 {
        self.tick as i64 * self.step_ns
    }

    /// Initializes every FMU at t = 0.
    pub fn initialize(&mut self) -> Result<()> {
        for c in &mut self.system.components {
            c.instance.enter_initialization_mode(0.0, None)?;
        }
        // Consistent start: scalar FMU-to-FMU connections are propagated in initialization
        // mode, once per component so chains (lift -> chassis -> world) settle, so that no
        // FMU starts from its default inputs (e.g. the world from a base at the origin).
        for _ in 0..self.system.components.len() {
            for r in 0..self.system.routes.len() {
                let route = &self.system.routes[r];
                let (Port::Fmu { comp: src, var: sv, seq: None }, Port::Fmu { comp: dst, var: dv, seq: None }) = (&route.from, &route.to) else { continue };
                let (src, dst, sv, dv) = (*src, *dst, sv.clone(), dv.clone());
                let v = value::get(&mut self.system.components[src].instance, &sv)?;
                value::set(&mut self.system.components[dst].instance, &dv, &v)?;
            }
        }
        for c in &mut self.system.components {
            c.instance.exit_initialization_mode()?;
        }
        Ok(())
    }

    /// One communication point and one step of every FMU. Callers that drive the master
    /// step by step call [`Master::finish_point`] at the end.
    pub fn advance(&mut self, hooks: &mut dyn Hooks) -> Result<()> {
        self.communicate(hooks)?;
        self.step_all()
    }

    /// True when the next communication point is a message instant (nodes run there).
    pub fn at_message_instant(&self) -> bool {
        self.tick % self.message_ticks == 0
    }

    /// Final point: outputs of the last step reach the hooks, and the point is closed.
    pub fn finish_point(&mut self, hooks: &mut dyn Hooks) -> Result<()> {
        self.collect_outputs(self.tick, hooks)?;
        let t_ns = self.time_ns();
        hooks.point(&mut self.system, t_ns)
    }

    fn communicate(&mut self, hooks: &mut dyn Hooks) -> Result<()> {
        let k = self.tick;
        let t_ns = self.time_ns();
        self.collect_outputs(k, hooks)?;
        hooks.exchange(t_ns, k % self.message_ticks == 0)?;
        self.deliver_inputs(k, hooks)?;
        hooks.point(&mut self.system, t_ns)
    }

    /// Step 1: routes from FMU outputs to system connectors read their source here.
    fn collect_outputs(&mut self, k: u64, hooks: &mut dyn Hooks) -> Result<()> {
        let t_ns = k as i64 * self.step_ns;
        for r in 0..self.system.routes.len() {
            let route = &self.system.routes[r];
            if k % route.period_ticks != 0 || !matches!(route.to, Port::Bus { .. }) {
                continue;
            }
            match &route.from {
                Port::Fmu { seq: Some(_), .. } => {
                    if let Some(bytes) = self.take_message(r)? {
                        hooks.message(&self.system, r, t_ns, &bytes)?;
                    }
                }
                Port::Fmu { comp, var, seq: None } => {
                    let Port::Bus { topic } = &route.to else { unreachable!("checked above") };
                    if let Some(x) = value::get(&mut self.system.components[*comp].instance, var)?.as_f64() {
                        hooks.scalar(topic, x);
                    }
                }
                Port::Bus { .. } => {}
            }
        }
        Ok(())
    }

    /// Step 3: routes into FMU inputs. FMU-to-FMU values are read now: every FMU is between
    /// steps, so this is a Jacobi exchange whatever the order.
    fn deliver_inputs(&mut self, k: u64, hooks: &mut dyn Hooks) -> Result<()> {
        let t_ns = k as i64 * self.step_ns;
        for r in 0..self.system.routes.len() {
            let route = &self.system.routes[r];
            if k % route.period_ticks != 0 || !matches!(route.to, Port::Fmu { .. }) {
                continue;
            }
            let value = match &route.from {
                Port::Bus { topic } => match &route.to {
                    Port::Fmu { seq: Some(_), .. } => {
                        let mut seen = route.seen;
                        let bytes = hooks.message_input(topic, &mut seen);
                        self.system.routes[r].seen = seen;
                        bytes.map(Value::Bin)
                    }
                    Port::Fmu { var, .. } => hooks.scalar_input(topic).map(|x| value::scalar_from_f64(var, x).map_err(|e| crate::err!("{}: {e}", route.label))).transpose()?,
                    Port::Bus { .. } => None,
                },
                Port::Fmu { seq: Some(_), .. } => match self.take_message(r)? {
                    Some(bytes) => {
                        hooks.message(&self.system, r, t_ns, &bytes)?;
                        Some(Value::Bin(bytes))
                    }
                    None => None,
                },
                Port::Fmu { comp, var, seq: None } => Some(value::get(&mut self.system.components[*comp].instance, var)?),
            };
            let Some(value) = value else { continue };
            let System { routes, components, .. } = &mut self.system;
            let route = &mut routes[r];
            let Port::Fmu { comp: dst, var: dst_var, seq: dst_seq } = &route.to else { unreachable!("checked above") };
            let inst = &mut components[*dst].instance;
            value::set(inst, dst_var, &value)?;
            if let Some(seq) = dst_seq {
                route.written += 1;
                value::set(inst, seq, &Value::I64(route.written))?;
            }
        }
        Ok(())
    }

    /// The new message of route `r`'s FMU source, if its counter moved since the route last
    /// looked.
    fn take_message(&mut self, r: usize) -> Result<Option<Vec<u8>>> {
        let System { routes, components, .. } = &mut self.system;
        let route = &mut routes[r];
        let Port::Fmu { comp, var, seq: Some(seq) } = &route.from else { return Ok(None) };
        let inst = &mut components[*comp].instance;
        let Value::I64(n) = value::get(inst, seq)? else { unreachable!("counter is Int64") };
        if n == route.seen {
            return Ok(None);
        }
        let Value::Bin(bytes) = value::get(inst, var)? else { unreachable!("message port is Binary") };
        route.seen = n;
        Ok(Some(bytes))
    }

    fn step_all(&mut self) -> Result<()> {
        let (t, h) = (self.time(), self.step_ns as f64 / 1e9);
        for c in &mut self.system.components {
            let r = c.instance.do_step(t, h)?;
            if r.terminate_simulation {
                return Err(crate::err!("FMU '{}' asked to terminate the simulation at t={t}", c.name));
            }
        }
        self.tick += 1;
        Ok(())
    }
}
