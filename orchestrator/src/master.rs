//! The master algorithm: fixed step on integer ticks, Jacobi exchange in a fixed order, each
//! route at its own integer decimation of the step (physics every step, messages at 10 Hz),
//! algorithm-layer nodes at the message rate, and everything recorded as it is exchanged.
//!
//! One communication point k (time t_k = k * step):
//!   1. FMU outputs due at k reach the bus (messages only when their counter moved);
//!   2. at message instants the nodes run;
//!   3. routes into FMU inputs due at k are written;
//!   4. published messages, /clock and every FMU's scalar signals are recorded at t_k;
//!   5. every FMU steps from t_k to t_k+1, in system-file order.
//! Nothing here reads a clock or iterates a hash map, so a run is a pure function of its inputs.

use crate::bus::Bus;
use crate::error::{Error, Result};
use crate::nodes::Node;
use crate::recorder::Recorder;
use crate::system::{Port, System};
use crate::value::{self, Value};
use agrisim_msgs::agrisim::{FmuStatus, Signals};
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::rosgraph_msgs::Clock;
use agrisim_msgs::std_msgs::Header;

pub const STATUS_TOPIC: &str = "/agrisim/status";
/// Scalar system connectors (set by nodes or FMU outputs) recorded every step.
pub const SCALARS_TOPIC: &str = "/agrisim/scalars";

pub struct Master {
    pub system: System,
    pub bus: Bus,
    pub nodes: Vec<Box<dyn Node>>,
    pub recorder: Recorder,
    step_ns: i64,
    message_ticks: u64,
    /// The next communication point.
    tick: u64,
}

fn time_of(tick: u64, step_ns: i64) -> f64 {
    (tick as i64 * step_ns) as f64 / 1e9
}

impl Master {
    pub fn new(system: System, nodes: Vec<Box<dyn Node>>, recorder: Recorder, step: f64, message_period: f64) -> Result<Master> {
        let step_ns = (step * 1e9).round() as i64;
        if step_ns <= 0 || ((step_ns as f64 / 1e9) - step).abs() > 1e-12 {
            return Err(crate::err!("step {step} s is not a positive whole number of nanoseconds"));
        }
        let message_ticks = crate::system::ticks_of(message_period, step, "message rate")?;
        Ok(Master { system, bus: Bus::default(), nodes, recorder, step_ns, message_ticks, tick: 0 })
    }

    pub fn time(&self) -> f64 {
        time_of(self.tick, self.step_ns)
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

    /// Runs `ticks` communication steps. On an error, it is recorded on /agrisim/status
    /// (the MCAP stays complete and readable) and returned.
    pub fn run(&mut self, ticks: u64, mut progress: impl FnMut(u64)) -> Result<()> {
        let result = (|| {
            for _ in 0..ticks {
                self.advance()?;
                progress(self.tick);
            }
            self.finish_point()
        })();
        if let Err(e) = &result {
            self.record_failure(e);
        }
        result
    }

    /// One communication point and one step of every FMU. Callers that drive the master
    /// step by step (benchmarks deciding when a trial ends) call [`Master::finish_point`]
    /// at the end, and [`Master::record_failure`] on an error.
    pub fn advance(&mut self) -> Result<()> {
        self.communicate()?;
        self.step_all()
    }

    /// True when the next communication point is a message instant (nodes run there).
    pub fn at_message_instant(&self) -> bool {
        self.tick % self.message_ticks == 0
    }

    /// Final point: outputs of the last step reach the bus and the log.
    pub fn finish_point(&mut self) -> Result<()> {
        self.collect_outputs(self.tick)?;
        self.record_point()
    }

    fn communicate(&mut self) -> Result<()> {
        let k = self.tick;
        self.collect_outputs(k)?;
        if k % self.message_ticks == 0 {
            let t_ns = k as i64 * self.step_ns;
            for n in &mut self.nodes {
                n.step(t_ns, &mut self.bus).map_err(|e| crate::err!("node {} at t={}: {e}", n.name(), time_of(k, self.step_ns)))?;
            }
        }
        self.deliver_inputs(k)?;
        self.record_point()
    }

    /// Step 1: routes from FMU outputs to the bus or to FMU inputs read their source here;
    /// bus-bound values are published now, FMU-bound ones wait in `pending`.
    fn collect_outputs(&mut self, k: u64) -> Result<()> {
        let t_ns = k as i64 * self.step_ns;
        for r in 0..self.system.routes.len() {
            let route = &self.system.routes[r];
            if k % route.period_ticks != 0 {
                continue;
            }
            let (Port::Fmu { comp, var, seq }, Port::Bus { topic }) = (&route.from, &route.to) else { continue };
            let (comp, var, is_message, topic) = (*comp, var.clone(), seq.is_some(), topic.clone());
            if is_message {
                if let Some((ty, bytes)) = self.take_message(r, t_ns)? {
                    self.bus.publish_raw(&topic, &ty, t_ns, bytes);
                }
            } else if let Some(x) = value::get(&mut self.system.components[comp].instance, &var)?.as_f64() {
                self.bus.set_scalar(&topic, x);
            }
        }
        Ok(())
    }

    /// Step 3: routes into FMU inputs. FMU-to-FMU values are read now: every FMU is between
    /// steps, so this is a Jacobi exchange whatever the order.
    fn deliver_inputs(&mut self, k: u64) -> Result<()> {
        let t_ns = k as i64 * self.step_ns;
        for r in 0..self.system.routes.len() {
            let route = &self.system.routes[r];
            if k % route.period_ticks != 0 {
                continue;
            }
            let Port::Fmu { comp: dst, var: dst_var, seq: dst_seq } = route.to.clone() else { continue };
            let value = match route.from.clone() {
                Port::Bus { topic } => match (&dst_seq, self.bus.latest(&topic)) {
                    (Some(_), Some(sample)) if sample.seq as i64 > route.seen => {
                        self.system.routes[r].seen = sample.seq as i64;
                        Some(Value::Bin(sample.cdr.clone()))
                    }
                    (None, _) => self.bus.scalar(&topic).map(|x| scalar_for(&dst_var, x)).transpose()?,
                    _ => None,
                },
                Port::Fmu { comp: src, var, seq } => match seq {
                    // FMU-to-FMU messages are recorded on their route's topic too.
                    Some(_) => match self.take_message(r, t_ns)? {
                        Some((ty, bytes)) => {
                            let topic = self.system.routes[r].topic.clone();
                            self.bus.publish_raw(&topic, &ty, t_ns, bytes.clone());
                            Some(Value::Bin(bytes))
                        }
                        None => None,
                    },
                    None => Some(value::get(&mut self.system.components[src].instance, &var)?),
                },
            };
            let Some(value) = value else { continue };
            let inst = &mut self.system.components[dst].instance;
            value::set(inst, &dst_var, &value)?;
            if let Some(seq) = dst_seq {
                let n = self.system.routes[r].written + 1;
                self.system.routes[r].written = n;
                value::set(inst, &seq, &Value::I64(n))?;
            }
        }
        Ok(())
    }

    /// The new message of route `r`'s FMU source, if its counter moved since the route last
    /// looked, checked against the port's ROS 2 type: (type, CDR bytes).
    fn take_message(&mut self, r: usize, t_ns: i64) -> Result<Option<(String, Vec<u8>)>> {
        let route = &self.system.routes[r];
        let Port::Fmu { comp, var, seq: Some(seq) } = &route.from else { return Ok(None) };
        let (comp, var, seq) = (*comp, var.clone(), seq.clone());
        let inst = &mut self.system.components[comp].instance;
        let Value::I64(n) = value::get(inst, &seq)? else { unreachable!("counter is Int64") };
        if n == route.seen {
            return Ok(None);
        }
        let Value::Bin(bytes) = value::get(inst, &var)? else { unreachable!("message port is Binary") };
        let ty = route.message_type.clone().expect("message route has a type");
        self.system.routes[r].seen = n;
        check_message(&self.system.components[comp].name, &var.name, &ty, &bytes, t_ns)?;
        Ok(Some((ty, bytes)))
    }

    /// Step 4: records everything published since the last point, /clock and the signals.
    fn record_point(&mut self) -> Result<()> {
        let t_ns = self.tick as i64 * self.step_ns;
        for m in self.bus.drain() {
            let ch = self.recorder.channel(&m.topic, &m.type_name)?;
            self.recorder.write(ch, m.time_ns, &m.cdr)?;
        }
        self.recorder.publish("/clock", t_ns, &Clock { clock: Time::from_nanos(t_ns) })?;
        if !self.bus.scalars().is_empty() {
            let (names, values) = self.bus.scalars().iter().map(|(k, v)| (k.clone(), *v)).unzip();
            let msg = Signals { header: Header { stamp: Time::from_nanos(t_ns), frame_id: String::new() }, names, values };
            self.recorder.publish(SCALARS_TOPIC, t_ns, &msg)?;
        }
        for c in &mut self.system.components {
            let mut values = Vec::new();
            c.read_signals(&mut values)?;
            let msg = Signals { header: Header { stamp: Time::from_nanos(t_ns), frame_id: String::new() }, names: c.signals.iter().map(|v| v.name.clone()).collect(), values };
            self.recorder.publish(&format!("/fmu/{}/signals", c.name), t_ns, &msg)?;
        }
        Ok(())
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

    /// Finishes the MCAP (summary, footer). Dropping the master does it too, silently.
    pub fn recorder_finish(&mut self) -> Result<()> {
        self.recorder.finish_in_place()
    }

    /// Records an error on /agrisim/status (the MCAP stays complete and readable).
    pub fn record_failure(&mut self, e: &Error) {
        let t_ns = self.tick as i64 * self.step_ns;
        let msg = FmuStatus { header: Header { stamp: Time::from_nanos(t_ns), frame_id: String::new() }, instance: String::new(), status: "error".into(), message: e.to_string() };
        let _ = self.recorder.publish(STATUS_TOPIC, t_ns, &msg);
    }
}

/// A message leaving an FMU must decode as the type its port declares.
fn check_message(comp: &str, var: &str, ty: &str, bytes: &[u8], t_ns: i64) -> Result<()> {
    match agrisim_msgs::check_cdr(ty, bytes) {
        Some(Err(e)) => Err(crate::err!("FMU '{comp}': output '{var}' at t={} is not a valid {ty} message ({} bytes): {e}", t_ns as f64 / 1e9, bytes.len())),
        _ => Ok(()),
    }
}

fn scalar_for(var: &crate::model_description::ModelVariable, x: f64) -> Result<Value> {
    use crate::model_description::VarType;
    Ok(match var.ty {
        VarType::Float64 => Value::F64(x),
        VarType::Int32 => Value::I32(x as i32),
        VarType::Int64 => Value::I64(x as i64),
        VarType::Boolean => Value::Bool(x != 0.0),
        other => return Err(crate::err!("variable {} of type {} cannot take a scalar", var.name, other.name())),
    })
}
