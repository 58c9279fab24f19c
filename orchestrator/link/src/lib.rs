//! agrisim-link: what the live ROS 2 links share, whatever carries the bytes (DDS in
//! agrisim-ros2, Zenoh in agrisim-zenoh). A link is a [`Transport`] (writes raw CDR on a
//! topic, hands over what the peers sent) driven by [`Link`], the bus node that, at each
//! message instant:
//!
//! 1. publishes every message the bus got since the last instant, the scalars as
//!    `std_msgs/Float64`, and `/clock`;
//! 2. in lockstep, waits until every lockstep topic has answered (or a timeout passes); in
//!    real time, waits for the wall clock;
//! 3. puts what the peers sent on the bus, after checking each message against its topic's
//!    type: a bad one is rejected, counted and reported on `/agrisim/status`; the run goes on.
//!
//! It runs last among the nodes, so the commands it brings reach the FMUs at this very
//! instant, as a built-in node's would.

use agrisim_bus::ground_truth::is_ground_truth;
use agrisim_bus::{Bus, Node, Tap};
use agrisim_error::Result;
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::rosgraph_msgs::Clock;
use agrisim_msgs::std_msgs::Float64;
use agrisim_msgs::Message;
use std::collections::{BTreeMap, BTreeSet};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// How simulated time relates to the peers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Mode {
    /// At each message instant, wait until every lockstep topic has answered or `timeout`
    /// (wall time) passes. Deterministic with a deterministic peer that answers in time.
    Lockstep { timeout: Duration },
    /// Paced to the wall clock: simulated time runs at `rate` x real time (1.0 = as the paper
    /// ran); nobody is waited for.
    Realtime { rate: f64 },
}

/// What crossed the link (for reports and benchmarks).
#[derive(Clone, Debug, Default)]
pub struct Stats {
    /// Which link: its label ("ROS 2 bridge", "Zenoh bridge").
    pub link: &'static str,
    pub published: u64,
    pub published_bytes: u64,
    pub received: u64,
    pub rejected: u64,
    pub instants: u64,
    pub lockstep_timeouts: u64,
    /// Wall time spent waiting for peers (lockstep) or for the clock (real time) [s].
    pub waited: f64,
    /// Per topic: messages and bytes published.
    pub topics: BTreeMap<String, (u64, u64)>,
    /// Per message instant: wall time from publishing until every lockstep topic answered [s]
    /// (the round trip sim -> peer -> sim); only instants that were answered in time.
    pub round_trips: Vec<f64>,
}

/// What kind of stream a topic is (the QoS a ROS 2 user expects of it, rclcpp's profiles).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Best effort, keep last 5 (rclcpp SensorDataQoS): camera and LiDAR streams.
    Sensor,
    /// Reliable, transient local, keep last 1: late joiners get the last message.
    Latched,
    /// Reliable, volatile, keep last 10 (rclcpp's default).
    Default,
}

/// The kind of `topic` carrying `ros_type`.
pub fn kind_of(topic: &str, ros_type: &str) -> Kind {
    if agrisim_bus::is_latched(topic) {
        return Kind::Latched;
    }
    match ros_type {
        "sensor_msgs/msg/Image"
        | "sensor_msgs/msg/PointCloud2"
        | "sensor_msgs/msg/Imu"
        | "sensor_msgs/msg/LaserScan" => Kind::Sensor,
        _ => Kind::Default,
    }
}

/// The DDS type name of ROS 2 type `pkg/msg/Type` (`pkg::msg::dds_::Type_`, the name the rmw
/// layers give it on DDS and rmw_zenoh in its keys), or None for another form.
pub fn dds_type(ros_type: &str) -> Option<String> {
    match ros_type.split('/').collect::<Vec<_>>().as_slice() {
        [pkg, "msg", ty] if !pkg.is_empty() && !ty.is_empty() => Some(format!("{pkg}::msg::dds_::{ty}_")),
        _ => None,
    }
}

/// Topic remapping (`--ros2-remap /cmd_vel:=/robot/cmd_vel`): bus name -> ROS 2 name.
#[derive(Clone, Debug, Default)]
pub struct Remap(BTreeMap<String, String>);

impl Remap {
    /// Parses `FROM:=TO` rules; both must be absolute topic names.
    pub fn parse(rules: &[String]) -> std::result::Result<Remap, String> {
        let mut map = BTreeMap::new();
        for r in rules {
            let (from, to) = r.split_once(":=").ok_or_else(|| format!("remap rule '{r}': expected FROM:=TO"))?;
            for n in [from, to] {
                if !n.starts_with('/') || n.len() < 2 || n.contains(char::is_whitespace) {
                    return Err(format!("remap rule '{r}': '{n}' is not an absolute topic name"));
                }
            }
            map.insert(from.to_string(), to.to_string());
        }
        Ok(Remap(map))
    }

    /// The ROS 2 name of bus topic `topic`.
    pub fn apply<'a>(&'a self, topic: &'a str) -> &'a str {
        self.0.get(topic).map_or(topic, |s| s.as_str())
    }
}

/// A topic taken from the peers onto the bus.
#[derive(Clone, Debug)]
pub struct Inbound {
    pub topic: String,
    /// Its ROS 2 type, `pkg/msg/Type`.
    pub ros_type: String,
    /// A scalar connector: its `std_msgs/Float64` messages set the bus's scalar.
    pub scalar: bool,
}

/// What a transport took from the peers.
#[derive(Debug)]
pub enum Arrival {
    /// Bytes on inbound topic number `index` (in [`LinkConfig::inbound`]) from `sender`.
    Sample { index: usize, sender: String, cdr: Vec<u8> },
    /// Something that could not be taken (a transport error, a sample on the topic with a
    /// wrong type or type hash): why, reported and counted as rejected.
    Rejected(String),
}

/// What carries the bytes.
pub trait Transport {
    /// Writes `cdr` (raw CDR with its encapsulation header) on `topic` of type `ros_type`.
    fn write(&mut self, topic: &str, ros_type: &str, cdr: &[u8]) -> Result<()>;
    /// Lockstep, before `/clock` goes out: make sure the peers have this instant's messages
    /// on the reliable `topics` (a transport that keeps order across topics does nothing).
    fn flush(&mut self, _topics: &BTreeSet<String>, _timeout: Duration) {}
    /// Appends what the peers sent since the last call.
    fn poll(&mut self, out: &mut Vec<Arrival>);
    /// Lockstep start: writers for `topics` (what the bus has now), so peers can match them.
    fn prepare(&mut self, topics: &[(String, String)]) -> Result<()>;
    /// Lockstep start: are the peers there (a writer on every one of `lockstep`, a reader of
    /// `/clock`)? Polled until true or the startup timeout passes.
    fn peers_ready(&mut self, lockstep: &[String]) -> bool;
    /// After [`peers_ready`](Transport::peers_ready): a moment for the peers' other readers.
    fn settle(&mut self) {}
}

/// What a link carries and how it keeps time, whatever the transport (part of each bridge's
/// configuration).
#[derive(Clone, Debug)]
pub struct Topics {
    pub mode: Mode,
    /// Topics taken from ROS 2 peers onto the bus, with their ROS 2 types (`pkg/msg/Type`).
    /// They are not published back.
    pub inbound: Vec<(String, String)>,
    /// Scalar connectors taken from peers as `std_msgs/msg/Float64` (a lift set-point).
    /// The bus's other scalars are published as Float64 at each instant.
    pub inbound_scalars: Vec<String>,
    /// Topics known to be published (the system's message outputs): their writers exist from
    /// the start, so peers match them before the first message (a reliable, volatile writer
    /// made on the fly loses what it sends before its readers have matched it).
    pub outbound: Vec<(String, String)>,
    /// In lockstep: the inbound topics that must answer at each message instant.
    pub lockstep: Vec<String>,
    pub remap: Remap,
    /// Lockstep: before the first instant, wait this long at most for the peers (a writer on
    /// every lockstep topic, a reader of /clock), so nothing is sent before they listen.
    pub startup_timeout: Duration,
}

impl Topics {
    /// The inbound topics, then the scalar connectors.
    pub fn inbound(&self) -> Vec<Inbound> {
        let topics =
            self.inbound.iter().map(|(t, ty)| Inbound { topic: t.clone(), ros_type: ty.clone(), scalar: false });
        let scalars = self.inbound_scalars.iter().map(|t| Inbound {
            topic: t.clone(),
            ros_type: Float64::TYPE_NAME.to_string(),
            scalar: true,
        });
        topics.chain(scalars).collect()
    }

    /// The writers a link makes from the start: the outbound topics that are not inbound,
    /// and /clock.
    pub fn writers(&self) -> Vec<(String, String)> {
        let inbound: BTreeSet<&String> =
            self.inbound.iter().map(|(t, _)| t).chain(self.inbound_scalars.iter()).collect();
        let mut w: Vec<(String, String)> =
            self.outbound.iter().filter(|(t, _)| !inbound.contains(t)).cloned().collect();
        w.push(("/clock".to_string(), Clock::TYPE_NAME.to_string()));
        w
    }

    /// The link's configuration, its messages labelled `label`, its bus node `node_name`.
    pub fn link(&self, label: &'static str, node_name: &'static str) -> Result<LinkConfig> {
        let c = LinkConfig {
            label,
            node_name,
            mode: self.mode,
            inbound: self.inbound(),
            lockstep: self.lockstep.clone(),
            startup_timeout: self.startup_timeout,
        };
        c.validate()?;
        Ok(c)
    }
}

/// The transport-agnostic part of a link's configuration.
#[derive(Clone, Debug)]
pub struct LinkConfig {
    /// How messages are named in reports: "ROS 2 bridge", "Zenoh bridge".
    pub label: &'static str,
    /// The bus node's name.
    pub node_name: &'static str,
    pub mode: Mode,
    /// Topics (and scalar connectors) taken from the peers; not published back.
    pub inbound: Vec<Inbound>,
    /// In lockstep: the inbound topics that must answer at each message instant.
    pub lockstep: Vec<String>,
    /// Lockstep: before the first instant, wait this long at most for the peers.
    pub startup_timeout: Duration,
}

impl LinkConfig {
    /// Checks the lockstep topics are inbound topics.
    pub fn validate(&self) -> Result<()> {
        for t in &self.lockstep {
            if !self.inbound.iter().any(|i| &i.topic == t && !i.scalar) {
                return Err(agrisim_error::err!("{}: lockstep topic {t} is not an inbound topic", self.label));
            }
        }
        Ok(())
    }
}

/// The bus node of a live link over transport `T`.
pub struct Link<T: Transport> {
    pub transport: T,
    config: LinkConfig,
    inbound_topics: BTreeSet<String>,
    /// Per inbound topic: taken since the last delivery (sender, bytes).
    pending: Vec<Vec<(String, Vec<u8>)>>,
    arrivals: Vec<Arrival>,
    /// Reasons of rejections the transport reported since the last delivery.
    refused: Vec<String>,
    tap: Tap,
    /// Wall time and simulated time of the first instant (real-time pacing).
    start: Option<(Instant, i64)>,
    stats: Arc<Mutex<Stats>>,
    warned_timeout: bool,
    started: bool,
}

impl<T: Transport> Link<T> {
    /// The link; the returned handle's [`Stats`] fill in as the run goes.
    pub fn new(transport: T, config: LinkConfig) -> Result<(Link<T>, Arc<Mutex<Stats>>)> {
        config.validate()?;
        let stats = Arc::new(Mutex::new(Stats { link: config.label, ..Stats::default() }));
        let link = Link {
            transport,
            inbound_topics: config.inbound.iter().map(|i| i.topic.clone()).collect(),
            pending: vec![vec![]; config.inbound.len()],
            arrivals: vec![],
            refused: vec![],
            config,
            tap: Tap::default(),
            start: None,
            stats: stats.clone(),
            warned_timeout: false,
            started: false,
        };
        Ok((link, stats))
    }

    /// Is `topic` taken from the peers (and so not published to them)?
    pub fn is_inbound(&self, topic: &str) -> bool {
        self.inbound_topics.contains(topic)
    }

    fn write(&mut self, topic: &str, ros_type: &str, cdr: &[u8]) -> Result<()> {
        self.transport.write(topic, ros_type, cdr)?;
        let len = cdr.len() as u64;
        let mut s = self.stats.lock().expect("stats lock");
        s.published += 1;
        s.published_bytes += len;
        let e = s.topics.entry(topic.to_string()).or_default();
        e.0 += 1;
        e.1 += len;
        Ok(())
    }

    /// Takes what the transport has received into the pending lists.
    fn poll(&mut self) {
        self.transport.poll(&mut self.arrivals);
        for a in self.arrivals.drain(..) {
            match a {
                Arrival::Sample { index, sender, cdr } => self.pending[index].push((sender, cdr)),
                Arrival::Rejected(why) => self.refused.push(why),
            }
        }
    }

    /// Lockstep start: writers for what the bus has now, then wait until the peers are there
    /// or the startup timeout passes.
    fn await_peers(&mut self, bus: &mut Bus) -> Result<()> {
        let mut topics: Vec<(String, String)> = bus
            .topics()
            .filter(|(t, _)| !self.inbound_topics.contains(*t))
            .map(|(t, ty)| (t.to_string(), ty.to_string()))
            .collect();
        topics.push(("/clock".to_string(), Clock::TYPE_NAME.to_string()));
        self.transport.prepare(&topics)?;
        let deadline = Instant::now() + self.config.startup_timeout;
        loop {
            if self.transport.peers_ready(&self.config.lockstep) {
                self.transport.settle();
                return Ok(());
            }
            if Instant::now() >= deadline {
                bus.reject(format!(
                    "{}: no peer after {:?} (wanted writers on {}, a reader of /clock); starting anyway",
                    self.config.label,
                    self.config.startup_timeout,
                    self.config.lockstep.join(", ")
                ));
                return Ok(());
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    }

    fn answered(&self) -> bool {
        self.config
            .lockstep
            .iter()
            .all(|t| self.config.inbound.iter().zip(&self.pending).any(|(i, p)| &i.topic == t && !p.is_empty()))
    }

    /// Puts what the peers sent on the bus, checked against its topic's type.
    fn deliver(&mut self, t_ns: i64, bus: &mut Bus) -> (u64, u64) {
        let label = self.config.label;
        let (mut received, mut rejected) = (0, 0);
        for why in self.refused.drain(..) {
            rejected += 1;
            bus.reject(format!("{label}: {why}"));
        }
        for (i, pending) in self.config.inbound.iter().zip(&mut self.pending) {
            for (sender, cdr) in pending.drain(..) {
                match agrisim_msgs::check_cdr(&i.ros_type, &cdr) {
                    Some(Ok(())) if i.scalar => match Float64::from_cdr(&cdr) {
                        Ok(Float64 { data }) if data.is_finite() => {
                            received += 1;
                            bus.set_scalar(&i.topic, data);
                        }
                        _ => {
                            rejected += 1;
                            bus.reject(format!("{label}: scalar {} from writer {sender}: not a finite number; rejected (the last valid value stays in force)", i.topic));
                        }
                    },
                    Some(Ok(())) => {
                        received += 1;
                        bus.publish_raw(&i.topic, &i.ros_type, t_ns, cdr);
                    }
                    Some(Err(e)) => {
                        rejected += 1;
                        bus.reject(format!("{label}: topic {} from writer {sender}: {} bytes are not a valid {}: {e}; rejected (the last valid message stays in force)", i.topic, cdr.len(), i.ros_type));
                    }
                    None => {
                        rejected += 1;
                        bus.reject(format!("{label}: topic {}: unknown type {}", i.topic, i.ros_type));
                    }
                }
            }
        }
        (received, rejected)
    }
}

impl<T: Transport> Node for Link<T> {
    fn name(&self) -> &str {
        self.config.node_name
    }

    fn step(&mut self, t_ns: i64, bus: &mut Bus) -> Result<()> {
        if !self.started {
            self.started = true;
            if matches!(self.config.mode, Mode::Lockstep { .. }) && !self.config.lockstep.is_empty() {
                self.await_peers(bus)?;
            }
        }
        // Everything new on the bus, topic by topic in name order, oldest first. On a bus
        // sealed from ground truth (a harvest by sight) the world's answers stay in: a peer
        // may be an external algorithm node, which must not read them either.
        let inbound = &self.inbound_topics;
        let sealed = bus.is_sealed();
        let held = |t: &str| inbound.contains(t) || (sealed && is_ground_truth(t));
        let mut reliable_written = BTreeSet::new();
        for (topic, ty, s) in self.tap.take(bus, |t| !held(t)) {
            if kind_of(&topic, &ty) != Kind::Sensor {
                reliable_written.insert(topic.clone());
            }
            self.write(&topic, &ty, &s.cdr)?;
        }
        if let Mode::Lockstep { timeout } = self.config.mode {
            self.transport.flush(&reliable_written, timeout);
        }
        let scalars: Vec<(String, f64)> = bus
            .scalars()
            .iter()
            .filter(|(t, _)| !self.inbound_topics.contains(*t))
            .map(|(t, v)| (t.clone(), *v))
            .collect();
        for (topic, data) in scalars {
            self.write(&topic, Float64::TYPE_NAME, &Float64 { data }.to_cdr())?;
        }
        self.write("/clock", Clock::TYPE_NAME, &Clock { clock: Time::from_nanos(t_ns) }.to_cdr())?;
        let published = Instant::now();
        match self.config.mode {
            Mode::Realtime { rate } => {
                let (wall0, t0) = *self.start.get_or_insert((published, t_ns));
                let due = wall0 + Duration::from_secs_f64(((t_ns - t0) as f64 * 1e-9 / rate).max(0.0));
                if let Some(wait) = due.checked_duration_since(Instant::now()) {
                    std::thread::sleep(wait);
                }
                self.poll();
            }
            Mode::Lockstep { timeout } => {
                let deadline = published + timeout;
                loop {
                    self.poll();
                    if self.answered() {
                        let rt = published.elapsed().as_secs_f64();
                        self.stats.lock().expect("stats lock").round_trips.push(rt);
                        break;
                    }
                    if Instant::now() >= deadline {
                        self.stats.lock().expect("stats lock").lockstep_timeouts += 1;
                        if !self.warned_timeout {
                            self.warned_timeout = true;
                            bus.reject(format!("{}: at t={} s no answer on {} within {:?} (lockstep goes on; further timeouts are counted, not reported)", self.config.label, t_ns as f64 * 1e-9, self.config.lockstep.join(", "), timeout));
                        }
                        break;
                    }
                    // Polling the peers: wall-clock waiting, never an input to results.
                    std::thread::sleep(Duration::from_micros(100));
                }
            }
        }
        let waited = published.elapsed().as_secs_f64();
        let (received, rejected) = self.deliver(t_ns, bus);
        let mut s = self.stats.lock().expect("stats lock");
        s.instants += 1;
        s.waited += waited;
        s.received += received;
        s.rejected += rejected;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kinds_and_remap() {
        assert_eq!(kind_of("/points", "sensor_msgs/msg/PointCloud2"), Kind::Sensor);
        assert_eq!(kind_of("/camera/color/image_raw", "sensor_msgs/msg/Image"), Kind::Sensor);
        assert_eq!(kind_of("/tf_static", "tf2_msgs/msg/TFMessage"), Kind::Latched);
        assert_eq!(kind_of("/tf", "tf2_msgs/msg/TFMessage"), Kind::Default);
        assert_eq!(kind_of("/cmd_vel", "geometry_msgs/msg/Twist"), Kind::Default);
        let r = Remap::parse(&["/cmd_vel:=/robot/cmd_vel".into()]).unwrap();
        assert_eq!(r.apply("/cmd_vel"), "/robot/cmd_vel");
        assert_eq!(r.apply("/odom"), "/odom");
        assert!(Remap::parse(&["cmd_vel:=/x".into()]).is_err());
        assert!(Remap::parse(&["/a=/b".into()]).is_err());
    }

    /// A transport in memory: records what is written; answers each /clock with `answer`.
    struct Loop {
        written: Vec<(String, Vec<u8>)>,
        answer: Option<Vec<u8>>,
        queued: Vec<Arrival>,
    }

    impl Transport for Loop {
        fn write(&mut self, topic: &str, _ros_type: &str, cdr: &[u8]) -> Result<()> {
            self.written.push((topic.to_string(), cdr.to_vec()));
            if topic == "/clock" {
                if let Some(a) = &self.answer {
                    self.queued.push(Arrival::Sample { index: 0, sender: "peer".into(), cdr: a.clone() });
                }
            }
            Ok(())
        }
        fn poll(&mut self, out: &mut Vec<Arrival>) {
            out.append(&mut self.queued);
        }
        fn prepare(&mut self, _topics: &[(String, String)]) -> Result<()> {
            Ok(())
        }
        fn peers_ready(&mut self, _lockstep: &[String]) -> bool {
            true
        }
    }

    fn link(answer: Option<Vec<u8>>) -> Link<Loop> {
        let config = LinkConfig {
            label: "test link",
            node_name: "test_link",
            mode: Mode::Lockstep { timeout: Duration::from_millis(20) },
            inbound: vec![Inbound {
                topic: "/cmd_vel".into(),
                ros_type: "geometry_msgs/msg/Twist".into(),
                scalar: false,
            }],
            lockstep: vec!["/cmd_vel".into()],
            startup_timeout: Duration::ZERO,
        };
        Link::new(Loop { written: vec![], answer, queued: vec![] }, config).unwrap().0
    }

    #[test]
    fn lockstep_delivers_checked_answers_and_rejects_bad_ones() {
        use agrisim_msgs::geometry_msgs::Twist;
        let good = Twist::default().to_cdr();
        let mut l = link(Some(good.clone()));
        let mut bus = Bus::default();
        l.step(1_000_000, &mut bus).unwrap();
        assert_eq!(l.transport.written.last().unwrap().0, "/clock");
        assert_eq!(l.stats.lock().unwrap().received, 1);
        assert_eq!(l.stats.lock().unwrap().round_trips.len(), 1);
        assert!(bus.topics().any(|(t, _)| t == "/cmd_vel"));
        // A truncated Twist: rejected and reported, the step still succeeds.
        let mut l = link(Some(good[..10].to_vec()));
        let mut bus = Bus::default();
        l.step(1_000_000, &mut bus).unwrap();
        let s = l.stats.lock().unwrap().clone();
        assert_eq!((s.received, s.rejected), (0, 1));
        assert!(bus.take_rejected().iter().any(|r| r.contains("/cmd_vel") && r.contains("not a valid")));
        // A sealed bus (a harvest by sight): ground truth is not sent to the peers.
        let mut l = link(Some(good.clone()));
        let mut bus = Bus::default();
        bus.seal_ground_truth();
        let pose = agrisim_msgs::geometry_msgs::PoseArray::default();
        bus.publish("/fruits", 1, &pose);
        bus.publish("/perception/fruit_map_poses", 1, &pose);
        l.step(1_000_000, &mut bus).unwrap();
        let sent: Vec<&str> = l.transport.written.iter().map(|(t, _)| t.as_str()).collect();
        assert!(sent.contains(&"/perception/fruit_map_poses") && !sent.contains(&"/fruits"), "{sent:?}");
        // No answer: a counted timeout, reported once.
        let mut l = link(None);
        let mut bus = Bus::default();
        l.step(1_000_000, &mut bus).unwrap();
        assert_eq!(l.stats.lock().unwrap().lockstep_timeouts, 1);
        assert!(bus.take_rejected().iter().any(|r| r.contains("no answer")));
    }
}
