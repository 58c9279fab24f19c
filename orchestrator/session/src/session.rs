//! A session: the engine's system coupled to the message bus, the algorithm nodes and the
//! MCAP recorder. This is where the two lower layers meet; neither knows the other.
//!
//! At each communication point the engine hands every message it moves to the session,
//! which checks it against the ROS 2 type its port declares and publishes it on the bus;
//! nodes run at message instants; the point's messages, /clock, the scalar system inputs and
//! every FMU's scalar signals are recorded at the point's time.

use agrisim_bus::check::{check_message, message_type};
use agrisim_bus::{Bus, Node, Reader, Recorder};
use agrisim_cosim::{Hooks, Master, Port, System};
use agrisim_error::{err, Error, Result};
use agrisim_msgs::agrisim::{FmuStatus, Signals};
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::rosgraph_msgs::Clock;
use agrisim_msgs::std_msgs::Header;
use std::collections::BTreeMap;

pub const STATUS_TOPIC: &str = "/agrisim/status";
/// Scalar system connectors (set by nodes or FMU outputs) recorded every step.
pub const SCALARS_TOPIC: &str = "/agrisim/scalars";

pub struct Session {
    pub master: Master,
    pub bus: Bus,
    pub nodes: Vec<Box<dyn Node>>,
    pub recorder: Recorder,
    /// The ROS 2 type of each route's messages (None: a scalar route).
    types: Vec<Option<String>>,
    /// Per route: an FMU-to-FMU route whose messages an earlier route of the same output
    /// already put on the bus (one output wired to several FMUs: the world's moved_objects to
    /// every sensor). Its copies are delivered, not published again.
    fan_out: Vec<bool>,
    /// Wall time of each node's last step \[s\]: a speed statistic for reports, never an input.
    node_wall: Vec<f64>,
    /// What is recorded every point, built once: per FMU its signals topic and message (the
    /// values and stamp change), and the scalar system inputs' message.
    signals: Vec<(String, Signals)>,
    scalars: Signals,
    /// Per route from a system connector into an FMU message input: its reader of the topic.
    readers: BTreeMap<usize, Reader>,
}

/// The ROS 2 message type of every route of `system`, from its ports' mimeTypes; an error
/// names the system file and connection whose mimeType names no ROS 2 type.
pub fn message_types(system: &System) -> Result<Vec<Option<String>>> {
    let file = system.structure.path.display().to_string();
    system.routes.iter().map(|r| r.mime_type.as_deref().map(|m| message_type(m, &file, &r.label)).transpose()).collect()
}

impl Session {
    /// `types`: [`message_types`] of `master.system`.
    pub fn new(master: Master, nodes: Vec<Box<dyn Node>>, recorder: Recorder, types: Vec<Option<String>>) -> Session {
        let node_wall = vec![0.0; nodes.len()];
        let signals = master
            .system
            .components
            .iter()
            .map(|c| {
                (
                    format!("/fmu/{}/signals", c.name),
                    Signals {
                        header: Header::default(),
                        names: c.signals.iter().map(|v| v.name.clone()).collect(),
                        values: Vec::new(),
                    },
                )
            })
            .collect();
        let routes = &master.system.routes;
        let fan_out = (0..routes.len())
            .map(|i| {
                let fmu_to_fmu =
                    |r: &agrisim_cosim::Route| matches!((&r.from, &r.to), (Port::Fmu { .. }, Port::Fmu { .. }));
                fmu_to_fmu(&routes[i]) && routes[..i].iter().any(|r| fmu_to_fmu(r) && r.topic == routes[i].topic)
            })
            .collect();
        Session {
            master,
            fan_out,
            bus: Bus::default(),
            nodes,
            recorder,
            types,
            node_wall,
            signals,
            scalars: Signals::default(),
            readers: BTreeMap::new(),
        }
    }

    pub fn time(&self) -> f64 {
        self.master.time()
    }

    pub fn system(&mut self) -> &mut System {
        &mut self.master.system
    }

    /// The index of component `name`, or an error saying who needed it.
    pub fn component(&self, name: &str, who: &str) -> Result<usize> {
        self.master.system.component_index(name).ok_or_else(|| err!("{who}: the system has no component '{name}'"))
    }

    /// A numeric FMU variable (ground truth a judge reads; nodes never see it).
    pub fn number(&mut self, comp: usize, name: &str) -> Result<f64> {
        self.master.system.number(comp, name)
    }

    /// Wall time of the last step of node `name` \[s\] (for speed statistics only).
    pub fn node_wall(&self, name: &str) -> Option<f64> {
        self.nodes.iter().position(|n| n.name() == name).map(|i| self.node_wall[i])
    }

    fn split(&mut self) -> (&mut Master, Link<'_>) {
        (
            &mut self.master,
            Link {
                bus: &mut self.bus,
                nodes: &mut self.nodes,
                recorder: &mut self.recorder,
                types: &self.types,
                fan_out: &self.fan_out,
                node_wall: &mut self.node_wall,
                signals: &mut self.signals,
                scalars: &mut self.scalars,
                readers: &mut self.readers,
            },
        )
    }

    /// One communication point and one step of every FMU. Callers that drive the session
    /// step by step (benchmarks deciding when a trial ends) call [`Session::finish_point`]
    /// at the end, and [`Session::record_failure`] on an error.
    /// A stop request ([`crate::interrupt`]) ends the run here, between two steps, with the
    /// error [`crate::interrupt::INTERRUPTED`].
    pub fn advance(&mut self) -> Result<()> {
        if crate::interrupt::requested() {
            return Err(err!("{} at t={} s", crate::interrupt::INTERRUPTED, self.master.time()));
        }
        let (master, mut link) = self.split();
        master.advance(&mut link)
    }

    /// Final point: outputs of the last step reach the bus and the log.
    pub fn finish_point(&mut self) -> Result<()> {
        let (master, mut link) = self.split();
        master.finish_point(&mut link)
    }

    /// Runs `ticks` communication steps. On an error, it is recorded on /agrisim/status
    /// (the MCAP stays complete and readable) and returned.
    pub fn run(&mut self, ticks: u64, mut progress: impl FnMut(u64)) -> Result<()> {
        let result = (|| {
            for _ in 0..ticks {
                self.advance()?;
                progress(self.master.tick());
            }
            self.finish_point()
        })();
        if let Err(e) = &result {
            self.record_failure(e);
        }
        result
    }

    /// Finishes the MCAP (summary, footer). Dropping the session does it too, silently.
    pub fn recorder_finish(&mut self) -> Result<()> {
        self.recorder.finish_in_place()
    }

    /// Records an error on /agrisim/status (the MCAP stays complete and readable).
    pub fn record_failure(&mut self, e: &Error) {
        let t_ns = self.master.time_ns();
        let msg = FmuStatus {
            header: Header { stamp: Time::from_nanos(t_ns), frame_id: String::new() },
            instance: String::new(),
            status: "error".into(),
            message: e.to_string(),
        };
        let _ = self.recorder.publish(STATUS_TOPIC, t_ns, &msg);
    }
}

/// A session's state at a communication point: the engine's (every FMU, the master's tick
/// and route positions) and the message bus's (latest messages, queues, readers).
pub struct SessionSnapshot {
    engine: agrisim_cosim::Snapshot,
    bus: Bus,
    readers: BTreeMap<usize, Reader>,
}

impl Session {
    /// Saves the session for [`Session::restore`]. Nodes keep their memory in themselves, so
    /// only a session without nodes (driven from outside: Python, a gymnasium environment)
    /// can be saved and restored exactly; one with nodes is refused. The recording goes on
    /// (a restored run records its messages again, at their simulated times).
    pub fn snapshot(&mut self) -> Result<SessionSnapshot> {
        if let Some(n) = self.nodes.first() {
            return Err(err!(
                "cannot snapshot a session with nodes (node '{}' keeps state the snapshot would not hold)",
                n.name()
            ));
        }
        Ok(SessionSnapshot { engine: self.master.snapshot()?, bus: self.bus.clone(), readers: self.readers.clone() })
    }

    /// Returns the session to `snapshot` (taken from this session).
    pub fn restore(&mut self, snapshot: &SessionSnapshot) -> Result<()> {
        self.master.restore(&snapshot.engine)?;
        self.bus = snapshot.bus.clone();
        self.readers = snapshot.readers.clone();
        Ok(())
    }

    /// Frees a snapshot's FMU states now (otherwise they go with the instances).
    pub fn free_snapshot(&mut self, snapshot: SessionSnapshot) -> Result<()> {
        self.master.free_snapshot(snapshot.engine)
    }
}

/// The session's side of the engine's [`Hooks`].
struct Link<'a> {
    bus: &'a mut Bus,
    nodes: &'a mut Vec<Box<dyn Node>>,
    recorder: &'a mut Recorder,
    types: &'a [Option<String>],
    fan_out: &'a [bool],
    node_wall: &'a mut [f64],
    signals: &'a mut [(String, Signals)],
    scalars: &'a mut Signals,
    readers: &'a mut BTreeMap<usize, Reader>,
}

impl Hooks for Link<'_> {
    fn message(&mut self, system: &System, route: usize, t_ns: i64, bytes: &[u8]) -> Result<()> {
        let r = &system.routes[route];
        if self.fan_out[route] {
            return Ok(());
        }
        let ty = self.types[route].as_deref().expect("message routes have a type (message_types)");
        if let Port::Fmu { comp, var, .. } = &r.from {
            check_message(&system.components[*comp].name, &var.name, ty, bytes, t_ns)?;
        }
        self.bus.publish_raw(&r.topic, ty, t_ns, bytes);
        Ok(())
    }

    fn scalar(&mut self, connector: &str, value: f64) {
        self.bus.set_scalar(connector, value);
    }

    fn exchange(&mut self, t_ns: i64, message_instant: bool) -> Result<()> {
        if message_instant {
            for (n, wall) in self.nodes.iter_mut().zip(self.node_wall.iter_mut()) {
                let start = std::time::Instant::now();
                self.bus.set_reader(Some(n.name()));
                let stepped = n.step(t_ns, self.bus);
                self.bus.set_reader(None);
                stepped.map_err(|e| err!("node {} at t={}: {e}", n.name(), t_ns as f64 / 1e9))?;
                if let Some(b) = self.bus.take_breaches().into_iter().next() {
                    return Err(err!(
                        "at t={} s {b}: ground truth is sealed in this run (the algorithm layer never sees it)",
                        t_ns as f64 / 1e9
                    ));
                }
                *wall = start.elapsed().as_secs_f64();
            }
        }
        Ok(())
    }

    fn message_input(&mut self, route: usize, connector: &str, out: &mut Vec<(i64, Vec<u8>)>) -> Result<()> {
        let reader = self.readers.entry(route).or_insert_with(|| Reader::new(connector));
        out.extend(reader.take_samples(self.bus).into_iter().map(|s| (s.time_ns, s.cdr.to_vec())));
        Ok(())
    }

    fn scalar_input(&self, connector: &str) -> Option<f64> {
        self.bus.scalar(connector)
    }

    fn point(&mut self, system: &mut System, t_ns: i64) -> Result<()> {
        // Warnings of the point (a refused command, a message a node could not decode): on
        // stderr and in the log, and the run goes on.
        let header = Header { stamp: Time::from_nanos(t_ns), frame_id: String::new() };
        for c in &mut system.components {
            for m in c.instance.take_log().into_iter().filter(|m| m.status >= agrisim_cosim::fmi3::Status::Warning) {
                let msg = FmuStatus {
                    header: header.clone(),
                    instance: c.name.clone(),
                    status: "warning".into(),
                    message: m.message,
                };
                self.recorder.publish(STATUS_TOPIC, t_ns, &msg)?;
            }
        }
        for reason in self.bus.take_rejected() {
            eprintln!("warning: {reason}");
            let msg = FmuStatus {
                header: header.clone(),
                instance: String::new(),
                status: "warning".into(),
                message: reason,
            };
            self.recorder.publish(STATUS_TOPIC, t_ns, &msg)?;
        }
        for m in self.bus.drain() {
            let ch = self.recorder.channel(&m.topic, &m.type_name)?;
            self.recorder.write(ch, m.time_ns, m.cdr)?;
        }
        self.recorder.publish("/clock", t_ns, &Clock { clock: Time::from_nanos(t_ns) })?;
        let stamp = Header { stamp: Time::from_nanos(t_ns), frame_id: String::new() };
        let scalars = self.bus.scalars();
        if !scalars.is_empty() {
            // Scalar connectors are only ever added, so the same count means the same names.
            if self.scalars.names.len() != scalars.len() {
                self.scalars.names = scalars.keys().cloned().collect();
            }
            self.scalars.values.clear();
            self.scalars.values.extend(scalars.values());
            self.scalars.header = stamp.clone();
            self.recorder.publish(SCALARS_TOPIC, t_ns, &*self.scalars)?;
        }
        for (c, (topic, msg)) in system.components.iter_mut().zip(self.signals.iter_mut()) {
            c.read_signals(&mut msg.values)?;
            msg.header = stamp.clone();
            self.recorder.publish(topic, t_ns, msg)?;
        }
        Ok(())
    }
}
