//! The master algorithm: fixed step on integer ticks, Gauss-Seidel in the order of
//! [`crate::order`] (a one-step delay only on the connections that close a loop), each route
//! at its own integer decimation of the step (physics every step, messages at their
//! connection's period), and a message instant for the algorithm layer.
//!
//! One communication point k (time t_k = k * step):
//!   1. FMU outputs due at k that go to system connectors reach the [`Hooks`]: every message
//!      the port produced since the route last read it, each at its own stamp;
//!   2. [`Hooks::exchange`] runs (the algorithm layer's nodes, at message instants);
//!   3. routes from system connectors into FMU inputs due at k are written;
//!   4. [`Hooks::point`] closes the point (recording);
//!   5. the components step from t_k to t_k+1 in order; before each steps, its FMU-to-FMU
//!      inputs are read from their sources: at t_k+1 from a source that has already stepped,
//!      at t_k from one that has not (a delayed connection).
//!      With [`Algorithm::Jacobi`], every FMU-to-FMU input is read first, all from the
//!      sources' values at t_k, and then every component steps (what libcosim's fixed-step
//!      algorithm and other parallel masters compute).
//!
//! Message ports lose nothing: a framed port ([`agrisim_frames`]) holds every message of its
//! FMU's `port_window`, and a route takes each one once, in order; a jump in the sequence
//! numbers (the route reads less often than the window) is an error naming the FMU and port.
//!
//! Nothing here reads a clock or iterates a hash map, so a run is a pure function of its
//! inputs and of what the hooks answer.

use crate::error::Result;
use crate::order::{self, Order};
use crate::system::{Port, System};
use crate::value::{self, Value};
use agrisim_frames::Frame;

/// What the engine exchanges with the program around it at each communication point: the
/// system's own connectors (no component), and every message it moves.
pub trait Hooks {
    /// A message left an FMU on route `route` (an index into `system.routes`), stamped
    /// `t_ns` (bound for a system connector, or for another FMU: then it is shown here too,
    /// on the route's topic). An error stops the run.
    fn message(&mut self, _system: &System, _route: usize, _t_ns: i64, _bytes: &[u8]) -> Result<()> {
        Ok(())
    }
    /// A scalar FMU output reached system connector `connector`.
    fn scalar(&mut self, _connector: &str, _value: f64) {}
    /// Between outputs and inputs of point `t_ns`; `message_instant` at the message rate.
    fn exchange(&mut self, _t_ns: i64, _message_instant: bool) -> Result<()> {
        Ok(())
    }
    /// Every message on system connector `connector` that route `route` has not delivered
    /// yet, oldest first, as (stamp \[ns\], CDR bytes), appended to `out`.
    fn message_input(&mut self, _route: usize, _connector: &str, _out: &mut Vec<(i64, Vec<u8>)>) -> Result<()> {
        Ok(())
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

/// The whole system's state between two communication points: every FMU's state
/// (fmi3GetFMUState) and the master's own (its time and where each route stands). Restoring
/// it and stepping gives exactly what stepping on from the snapshot gave. The program around
/// the engine (its hooks: bus, nodes, recorder) keeps its own state.
pub struct Snapshot {
    pub(crate) fmus: Vec<crate::fmu::FmuState>,
    pub(crate) tick: u64,
    pub(crate) routes: Vec<(agrisim_frames::Cursor, i64)>,
}

impl Snapshot {
    /// Simulation time of the next communication point after a restore, in steps.
    pub fn tick(&self) -> u64 {
        self.tick
    }
}

/// How the components step within one communication step.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Algorithm {
    /// In the order of [`crate::order`]: a component reads its FMU-to-FMU inputs just before it
    /// steps, at t_k+1 from the sources that have stepped already (only the connections that
    /// close a loop are read one step late). The default: the world sees the base where it is.
    #[default]
    GaussSeidel,
    /// Every FMU-to-FMU input is read from its source's value at t_k, before any component
    /// steps; then all step (each connection one step late). This is what libcosim's
    /// `fixed_step_algorithm` computes (it steps all simulators, then transfers every output
    /// to the inputs used by the next step), so the same FMI 2 system gives the same values
    /// in both masters. Initialization is the same as with [`Algorithm::GaussSeidel`].
    Jacobi,
}

/// Most fixed-point passes initialization makes through a loop before giving up.
const INIT_PASSES: usize = 50;

pub struct Master {
    pub system: System,
    order: Order,
    /// FMU-to-FMU routes into each component, in route order.
    inputs_of: Vec<Vec<usize>>,
    /// Per route: delayed (read before its source steps).
    delayed: Vec<bool>,
    step_ns: i64,
    message_ticks: u64,
    algorithm: Algorithm,
    /// The next communication point.
    tick: u64,
    /// Reused buffers.
    inbound: Vec<(i64, Vec<u8>)>,
    framed: Vec<u8>,
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
        let order = order::plan(&system);
        let mut inputs_of = vec![vec![]; system.components.len()];
        let mut delayed = vec![false; system.routes.len()];
        for r in 0..system.routes.len() {
            if let Some((_, b)) = order::fmu_link(&system, r) {
                inputs_of[b].push(r);
            }
        }
        for &r in &order.delayed {
            delayed[r] = true;
        }
        Ok(Master {
            system,
            order,
            inputs_of,
            delayed,
            step_ns,
            message_ticks,
            algorithm: Algorithm::default(),
            tick: 0,
            inbound: vec![],
            framed: vec![],
        })
    }

    /// The master with `algorithm` (Gauss-Seidel unless chosen otherwise); set before the first
    /// step.
    pub fn with_algorithm(mut self, algorithm: Algorithm) -> Master {
        self.algorithm = algorithm;
        self
    }

    /// How the components step within one communication step.
    pub fn algorithm(&self) -> Algorithm {
        self.algorithm
    }

    /// The stepping order and the delayed connections.
    pub fn order(&self) -> &Order {
        &self.order
    }

    /// The order in words (`agrisim run --explain`).
    pub fn explain(&self) -> String {
        let text = order::explain(&self.system, &self.order);
        match self.algorithm {
            Algorithm::GaussSeidel => text,
            Algorithm::Jacobi => format!(
                "Algorithm: Jacobi (every component reads its FMU inputs from the values at the start of the \
                 step, then all step: every connection is one step late; the order below is only the order of \
                 the calls and of initialization)\n{text}"
            ),
        }
    }

    /// Simulation time of the next communication point \[s\].
    pub fn time(&self) -> f64 {
        time_of(self.tick, self.step_ns)
    }

    /// The next communication point, in steps.
    pub fn tick(&self) -> u64 {
        self.tick
    }

    /// Simulation time of the next communication point \[ns\].
    pub fn time_ns(&self) -> i64 {
        self.tick as i64 * self.step_ns
    }

    /// Initializes every FMU at t = 0: one pass in the step order, each component's inputs
    /// from the FMUs before it set before its own outputs are read (so each model computes
    /// its initial state once), then passes over every scalar FMU-to-FMU connection until
    /// none changes (only a loop through a delayed connection makes a second pass change
    /// anything).
    pub fn initialize(&mut self) -> Result<()> {
        for c in &mut self.system.components {
            c.instance.enter_initialization_mode(0.0, None)?;
        }
        let mut last: Vec<Option<Value>> = vec![None; self.system.routes.len()];
        for i in 0..self.order.step.len() {
            let c = self.order.step[i];
            for j in 0..self.inputs_of[c].len() {
                let r = self.inputs_of[c][j];
                if !self.delayed[r] {
                    self.propagate_initial(r, &mut last)?;
                }
            }
        }
        let mut converged = false;
        for _ in 0..INIT_PASSES {
            let mut changed = vec![];
            for i in 0..self.order.step.len() {
                let c = self.order.step[i];
                for j in 0..self.inputs_of[c].len() {
                    let r = self.inputs_of[c][j];
                    if self.propagate_initial(r, &mut last)? {
                        changed.push(r);
                    }
                }
            }
            if changed.is_empty() {
                converged = true;
                break;
            }
        }
        if !converged {
            let labels: Vec<&str> =
                self.order.init_loops.iter().map(|&r| self.system.routes[r].label.as_str()).collect();
            return Err(crate::err!(
                "initialization did not converge in {INIT_PASSES} passes through the loop(s) {}",
                labels.join(", ")
            ));
        }
        for c in &mut self.system.components {
            c.instance.exit_initialization_mode()?;
        }
        Ok(())
    }

    /// Copies a scalar FMU-to-FMU route's source value to its destination in Initialization
    /// Mode if it differs from what was last written there; returns whether it did.
    fn propagate_initial(&mut self, r: usize, last: &mut [Option<Value>]) -> Result<bool> {
        let route = &self.system.routes[r];
        let (Port::Fmu { comp: src, var: sv, seq: None }, Port::Fmu { comp: dst, var: dv, seq: None }) =
            (&route.from, &route.to)
        else {
            return Ok(false);
        };
        let (src, dst) = (*src, *dst);
        let v = value::get(self.system.components[src].instance.as_mut(), sv)?;
        if last[r].as_ref().is_some_and(|l| l.identical(&v)) {
            return Ok(false);
        }
        let out = route.transfer_value(v.clone())?;
        value::set(self.system.components[dst].instance.as_mut(), dv, &out)?;
        last[r] = Some(v);
        Ok(true)
    }

    /// Saves the whole system's state (every FMU needs canGetAndSetFMUState).
    pub fn snapshot(&mut self) -> Result<Snapshot> {
        let mut fmus = Vec::with_capacity(self.system.components.len());
        for c in &mut self.system.components {
            fmus.push(c.instance.get_state().map_err(|e| crate::err!("snapshot of FMU '{}': {e}", c.name))?);
        }
        let routes = self.system.routes.iter().map(|r| (r.cursor, r.written)).collect();
        Ok(Snapshot { fmus, tick: self.tick, routes })
    }

    /// Returns the whole system to `snapshot` (taken from this master).
    pub fn restore(&mut self, snapshot: &Snapshot) -> Result<()> {
        if snapshot.fmus.len() != self.system.components.len() || snapshot.routes.len() != self.system.routes.len() {
            return Err(crate::err!(
                "snapshot of another system ({} FMUs, {} routes; this one has {} and {})",
                snapshot.fmus.len(),
                snapshot.routes.len(),
                self.system.components.len(),
                self.system.routes.len()
            ));
        }
        for (c, s) in self.system.components.iter_mut().zip(&snapshot.fmus) {
            c.instance.set_state(s).map_err(|e| crate::err!("restoring FMU '{}': {e}", c.name))?;
        }
        for (r, (cursor, written)) in self.system.routes.iter_mut().zip(&snapshot.routes) {
            r.cursor = *cursor;
            r.written = *written;
        }
        self.tick = snapshot.tick;
        Ok(())
    }

    /// Frees a snapshot's FMU states now (otherwise they go with the instances).
    pub fn free_snapshot(&mut self, snapshot: Snapshot) -> Result<()> {
        for (c, s) in self.system.components.iter_mut().zip(snapshot.fmus) {
            c.instance.free_state(s)?;
        }
        Ok(())
    }

    /// One communication point and one step of every FMU. Callers that drive the master
    /// step by step call [`Master::finish_point`] at the end.
    pub fn advance(&mut self, hooks: &mut dyn Hooks) -> Result<()> {
        self.communicate(hooks)?;
        self.step_all(hooks)
    }

    /// True when the next communication point is a message instant (nodes run there).
    pub fn at_message_instant(&self) -> bool {
        self.tick.is_multiple_of(self.message_ticks)
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
        hooks.exchange(t_ns, k.is_multiple_of(self.message_ticks))?;
        self.deliver_bus_inputs(k, hooks)?;
        hooks.point(&mut self.system, t_ns)
    }

    /// Step 1: routes from FMU outputs to system connectors read their source here.
    fn collect_outputs(&mut self, k: u64, hooks: &mut dyn Hooks) -> Result<()> {
        let t_ns = k as i64 * self.step_ns;
        for r in 0..self.system.routes.len() {
            let route = &self.system.routes[r];
            if !k.is_multiple_of(route.period_ticks) || !matches!(route.to, Port::Bus { .. }) {
                continue;
            }
            match &route.from {
                Port::Fmu { seq: Some(_), .. } => {
                    self.take_messages(r, t_ns, &mut |system, frame| {
                        hooks.message(system, r, frame.stamp_ns, frame.payload)
                    })?;
                }
                Port::Fmu { comp, var, seq: None } => {
                    let Port::Bus { topic } = &route.to else { unreachable!("checked above") };
                    let v = value::get(self.system.components[*comp].instance.as_mut(), var)?;
                    if let Some(x) = route.transfer_value(v)?.as_f64() {
                        hooks.scalar(topic, x);
                    }
                }
                Port::Bus { .. } => {}
            }
        }
        Ok(())
    }

    /// Step 3: routes from system connectors into FMU inputs.
    fn deliver_bus_inputs(&mut self, k: u64, hooks: &mut dyn Hooks) -> Result<()> {
        for r in 0..self.system.routes.len() {
            let route = &self.system.routes[r];
            if !k.is_multiple_of(route.period_ticks) {
                continue;
            }
            let (Port::Bus { topic }, Port::Fmu { var, seq, .. }) = (&route.from, &route.to) else { continue };
            if seq.is_some() {
                let mut inbound = std::mem::take(&mut self.inbound);
                inbound.clear();
                hooks.message_input(r, topic, &mut inbound)?;
                let res = self.write_messages(r, inbound.iter().map(|(t, b)| (*t, b.as_slice())));
                self.inbound = inbound;
                res?;
            } else if let Some(x) = hooks.scalar_input(topic) {
                let v = value::scalar_from_f64(var, x).map_err(|e| crate::err!("{}: {e}", route.label))?;
                let v = route.transfer_value(v)?;
                let Port::Fmu { comp, var, .. } = &self.system.routes[r].to else { unreachable!("matched above") };
                value::set(self.system.components[*comp].instance.as_mut(), var, &v)?;
            }
        }
        Ok(())
    }

    /// Writes `messages` (stamp, CDR) to route `r`'s destination message port: as a frame
    /// list numbered on from the route's last one, or, for a port that takes one bare
    /// message, the newest of them; the port's counter then names the newest.
    fn write_messages<'a>(&mut self, r: usize, messages: impl ExactSizeIterator<Item = (i64, &'a [u8])>) -> Result<()> {
        if messages.len() == 0 {
            return Ok(());
        }
        let System { routes, components, .. } = &mut self.system;
        let route = &mut routes[r];
        let Port::Fmu { comp, var, seq: Some(seq) } = &route.to else {
            return Err(crate::err!("{}: not a message input", route.label));
        };
        let inst = components[*comp].instance.as_mut();
        let first = route.written as u64 + 1;
        let n = messages.len() as u64;
        if route.framed_to {
            self.framed.clear();
            agrisim_frames::encode_into(
                &mut self.framed,
                messages.enumerate().map(|(i, (stamp_ns, payload))| Frame { seq: first + i as u64, stamp_ns, payload }),
            );
            inst.set_binary(var.value_reference, &self.framed)?;
        } else {
            let (_, newest) = messages.last().expect("not empty");
            inst.set_binary(var.value_reference, newest)?;
        }
        route.written += n as i64;
        value::set(inst, seq, &Value::I64(route.written))?;
        Ok(())
    }

    /// The messages of route `r`'s FMU source port that the route has not taken yet, each
    /// passed to `each` in order. A framed port yields its new frames (a sequence gap is an
    /// error naming the FMU and port); a plain port yields its one message, stamped `t_ns`,
    /// when its counter moved by one (by more: messages were lost, an error too).
    fn take_messages(&mut self, r: usize, t_ns: i64, each: &mut dyn FnMut(&System, Frame) -> Result<()>) -> Result<()> {
        let route = &self.system.routes[r];
        let Port::Fmu { comp, var, seq: Some(seq) } = &route.from else { return Ok(()) };
        let comp = *comp;
        let inst = self.system.components[comp].instance.as_mut();
        let Value::I64(n) = value::get(inst, seq)? else { unreachable!("counter is Int64") };
        let n = n.max(0) as u64;
        if n == route.cursor.last {
            return Ok(());
        }
        // Borrowed, not copied (a camera image is megabytes). SAFETY: the bytes stay valid
        // until the FMU's next call; nothing below calls any FMU (`each` sees the system by
        // shared reference, and every FMU call needs the instance by `&mut`).
        let bytes: *const [u8] = inst.get_binary_ref(var.value_reference)?;
        let bytes = unsafe { &*bytes };
        let lost = |system: &System, e: agrisim_frames::Error| {
            let route = &system.routes[r];
            let Port::Fmu { var, .. } = &route.from else { unreachable!("FMU source") };
            let hint = match e {
                agrisim_frames::Error::Gap { .. } => format!(
                    ": the route reads it every {} step(s); read it at least every port_window of the FMU, or lengthen that window",
                    route.period_ticks
                ),
                agrisim_frames::Error::Malformed(_) => String::new(),
            };
            crate::err!(
                "FMU '{}': message port '{}' at t={} s: {e}{hint} (route {})",
                system.components[comp].name,
                var.name,
                t_ns as f64 / 1e9,
                route.label
            )
        };
        let mut cursor = route.cursor;
        if route.framed_from {
            let frames = cursor.take(bytes, n).map_err(|e| lost(&self.system, e));
            self.system.routes[r].cursor = cursor;
            for f in frames? {
                each(&self.system, f)?;
            }
        } else {
            let skipped = n > cursor.last + 1;
            let first = cursor.last + 1;
            cursor.last = n;
            self.system.routes[r].cursor = cursor;
            if skipped {
                return Err(lost(&self.system, agrisim_frames::Error::Gap { first, last: n - 1 }));
            }
            each(&self.system, Frame { seq: n, stamp_ns: t_ns, payload: bytes })?;
        }
        Ok(())
    }

    /// Step 5: every component steps in order, its FMU-to-FMU inputs read just before
    /// (Gauss-Seidel); or every input is read at t_k first and then every component steps
    /// (Jacobi).
    fn step_all(&mut self, hooks: &mut dyn Hooks) -> Result<()> {
        let k = self.tick;
        let (t, h) = (self.time(), self.step_ns as f64 / 1e9);
        let jacobi = self.algorithm == Algorithm::Jacobi;
        if jacobi {
            // Every source at t_k, before any component steps.
            for i in 0..self.order.step.len() {
                let c = self.order.step[i];
                for j in 0..self.inputs_of[c].len() {
                    let r = self.inputs_of[c][j];
                    if k.is_multiple_of(self.system.routes[r].period_ticks) {
                        self.propagate(r, k, hooks)?;
                    }
                }
            }
        }
        for i in 0..self.order.step.len() {
            let c = self.order.step[i];
            // Gauss-Seidel: read just before stepping; a source that has stepped is at t_k+1.
            let gauss_seidel_inputs = if jacobi { 0 } else { self.inputs_of[c].len() };
            for j in 0..gauss_seidel_inputs {
                let r = self.inputs_of[c][j];
                let at = if self.delayed[r] { k } else { k + 1 };
                if at % self.system.routes[r].period_ticks == 0 {
                    self.propagate(r, at, hooks)?;
                }
            }
            let comp = &mut self.system.components[c];
            let res = comp.instance.do_step(t, h)?;
            if res.terminate_simulation {
                return Err(crate::err!("FMU '{}' asked to terminate the simulation at t={t}", comp.name));
            }
        }
        self.tick += 1;
        Ok(())
    }

    /// Moves FMU-to-FMU route `r`'s value (its source at tick `at`) to its destination.
    fn propagate(&mut self, r: usize, at: u64, hooks: &mut dyn Hooks) -> Result<()> {
        let route = &self.system.routes[r];
        match (&route.from, &route.to) {
            (Port::Fmu { seq: Some(_), .. }, _) => {
                let mut taken: Vec<(i64, Vec<u8>)> = vec![];
                self.take_messages(r, at as i64 * self.step_ns, &mut |system, f| {
                    hooks.message(system, r, f.stamp_ns, f.payload)?;
                    taken.push((f.stamp_ns, f.payload.to_vec()));
                    Ok(())
                })?;
                self.write_messages(r, taken.iter().map(|(t, b)| (*t, b.as_slice())))
            }
            (Port::Fmu { comp: src, var: sv, seq: None }, Port::Fmu { .. }) => {
                let v = value::get(self.system.components[*src].instance.as_mut(), sv)?;
                let System { routes, components, .. } = &mut self.system;
                let v = routes[r].transfer_value(v)?;
                let Port::Fmu { comp: dst, var: dv, .. } = &routes[r].to else { unreachable!("matched above") };
                value::set(components[*dst].instance.as_mut(), dv, &v)
            }
            _ => Ok(()),
        }
    }
}
