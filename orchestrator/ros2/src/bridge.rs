//! The bridge node. At each message instant it publishes every message the bus got since the
//! last one (FMU outputs and the built-in nodes' messages) and `/clock`, then, in lockstep,
//! waits until every lockstep topic has answered (or a timeout passes), or, in real time,
//! waits for the wall clock; then it puts what the peers sent on the bus, after checking
//! each message against its topic's type. It runs last among the nodes, so the commands it
//! brings reach the FMUs at this very instant, as a built-in node's would.

use crate::announce::{self, Announcer};
use crate::confine;
use crate::graph::{self, Distro};
use crate::names::{dds_topic, dds_type, Remap};
use crate::qos;
use crate::raw::{RawAdapter, RawCdr};
use agrisim_bus::{Bus, Node, Tap};
use agrisim_error::{err, Result};
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::rosgraph_msgs::Clock;
use agrisim_msgs::std_msgs::Float64;
use agrisim_msgs::Message;
use rustdds::no_key::{DataReader, DataWriter};
use rustdds::{DomainParticipant, DomainParticipantBuilder, Publisher, RTPSEntity, Subscriber, TopicKind};
use std::collections::{BTreeMap, BTreeSet};
use std::net::{IpAddr, Ipv4Addr};
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

#[derive(Clone, Debug)]
pub struct BridgeConfig {
    /// DDS domain (ROS_DOMAIN_ID).
    pub domain: u16,
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
    /// Advertise and talk on the loopback interface only and hear only this machine (the
    /// default; see [`confine`]); false: every interface.
    pub loopback_only: bool,
    /// Lockstep: before the first instant, wait this long at most for the peers (a writer on
    /// every lockstep topic, a reader of /clock), so nothing is sent before they listen.
    pub startup_timeout: Duration,
    /// The distro whose graph-information layout `ros_discovery_info` follows.
    pub distro: Distro,
}

/// What crossed the bridge (for reports and benchmarks).
#[derive(Clone, Debug, Default)]
pub struct Stats {
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

struct Inbound {
    topic: String,
    ros_type: String,
    /// A scalar connector: its Float64 messages set the bus's scalar.
    scalar: bool,
    reader: DataReader<RawCdr, RawAdapter>,
    /// Taken from DDS since the last delivery: sender and bytes.
    pending: Vec<(String, Vec<u8>)>,
}

pub struct Ros2Bridge {
    publisher: Publisher,
    config: BridgeConfig,
    participant: DomainParticipant,
    writers: BTreeMap<String, DataWriter<RawCdr, RawAdapter>>,
    inbound: Vec<Inbound>,
    inbound_topics: BTreeSet<String>,
    tap: Tap,
    /// The writer of `ros_discovery_info` (see [`graph`]).
    graph: DataWriter<RawCdr, RawAdapter>,
    /// Wall time and simulated time of the first instant (real-time pacing).
    start: Option<(Instant, i64)>,
    stats: Arc<Mutex<Stats>>,
    warned_timeout: bool,
    started: bool,
    /// Loopback only: the participant's announcements repeated to this machine's LAN
    /// addresses (see [`announce`]).
    _announcer: Option<Announcer>,
}

fn dds_err(what: &str, e: impl std::fmt::Debug) -> agrisim_error::Error {
    err!("ROS 2 bridge: {what}: {e:?}")
}

impl Ros2Bridge {
    /// Joins DDS domain `config.domain` and subscribes to the inbound topics. The returned
    /// handle's [`Stats`] fill in as the run goes.
    pub fn new(config: BridgeConfig) -> Result<(Ros2Bridge, Arc<Mutex<Stats>>)> {
        let mut b = DomainParticipantBuilder::new(config.domain);
        // Loopback only: the repeater's socket first (it must catch the first announcement),
        // then the participant's sockets, each filtered to traffic from this machine.
        let (catch, before) = if config.loopback_only {
            b = b.with_only_networks([IpAddr::V4(Ipv4Addr::LOCALHOST)]);
            (announce::listen(config.domain), Some(confine::udp_sockets()?))
        } else {
            (None, None)
        };
        let participant = b.build().map_err(|e| dds_err(&format!("cannot join DDS domain {}", config.domain), e))?;
        if let Some(before) = before {
            confine::confine_new(&before)?;
        }
        let targets = if catch.is_some() { announce::lan_addresses() } else { vec![] };
        let announcer = match catch {
            Some(socket) if !targets.is_empty() => {
                let guid = participant.guid().to_bytes();
                let prefix: [u8; 12] = guid[..12].try_into().expect("a GUID has a 12-byte prefix");
                Some(Announcer::start(socket, config.domain, prefix, targets)?)
            }
            _ => None,
        };
        let publisher =
            participant.create_publisher(&qos::writer(qos::Kind::Default)).map_err(|e| dds_err("publisher", e))?;
        let subscriber: Subscriber =
            participant.create_subscriber(&qos::reader()).map_err(|e| dds_err("subscriber", e))?;
        for t in &config.lockstep {
            if !config.inbound.iter().any(|(i, _)| i == t) {
                return Err(err!("ROS 2 bridge: lockstep topic {t} is not an inbound topic"));
            }
        }
        let mut inbound = vec![];
        let scalars = config.inbound_scalars.iter().map(|t| (t, Float64::TYPE_NAME));
        for (topic, ros_type) in config.inbound.iter().map(|(t, ty)| (t, ty.as_str())).chain(scalars) {
            let ty = dds_type(ros_type)
                .ok_or_else(|| err!("ROS 2 bridge: topic {topic}: '{ros_type}' is not a pkg/msg/Type name"))?;
            let name = dds_topic(config.remap.apply(topic));
            let t = participant
                .create_topic(name.clone(), ty, &qos::reader(), TopicKind::NoKey)
                .map_err(|e| dds_err(&format!("topic {name}"), e))?;
            let reader = subscriber
                .create_datareader_no_key::<RawCdr, RawAdapter>(&t, Some(qos::reader()))
                .map_err(|e| dds_err(&format!("reader of {name}"), e))?;
            let scalar = config.inbound_scalars.contains(topic);
            inbound.push(Inbound {
                topic: topic.clone(),
                ros_type: ros_type.to_string(),
                scalar,
                pending: vec![],
                reader,
            });
        }
        let inbound_topics =
            config.inbound.iter().map(|(t, _)| t.clone()).chain(config.inbound_scalars.iter().cloned()).collect();
        let stats = Arc::new(Mutex::new(Stats::default()));
        let q = qos::writer(qos::Kind::Latched);
        let t = participant
            .create_topic(graph::TOPIC.to_string(), graph::TYPE.to_string(), &q, TopicKind::NoKey)
            .map_err(|e| dds_err(graph::TOPIC, e))?;
        let graph = publisher
            .create_datawriter_no_key::<RawCdr, RawAdapter>(&t, Some(q))
            .map_err(|e| dds_err(&format!("writer of {}", graph::TOPIC), e))?;
        let mut bridge = Ros2Bridge {
            publisher,
            config,
            participant,
            writers: BTreeMap::new(),
            inbound,
            inbound_topics,
            tap: Tap::default(),
            graph,
            start: None,
            stats: stats.clone(),
            warned_timeout: false,
            started: false,
            _announcer: announcer,
        };
        let outbound: Vec<(String, String)> =
            bridge.config.outbound.iter().filter(|(t, _)| !bridge.inbound_topics.contains(t)).cloned().collect();
        for (t, ty) in outbound.iter().chain([&("/clock".to_string(), Clock::TYPE_NAME.to_string())]) {
            bridge.add_writer(t, ty)?;
        }
        bridge.announce()?;
        Ok((bridge, stats))
    }

    /// Publishes the bridge's node with its readers and writers on `ros_discovery_info`.
    fn announce(&mut self) -> Result<()> {
        let readers: Vec<[u8; 16]> = self.inbound.iter().map(|i| i.reader.guid().to_bytes()).collect();
        let writers: Vec<[u8; 16]> = self.writers.values().map(|w| w.guid().to_bytes()).collect();
        let cdr = graph::participant_info(self.config.distro, self.participant.guid().to_bytes(), &readers, &writers);
        self.graph.write(RawCdr(cdr), None).map_err(|e| dds_err(&format!("publishing on {}", graph::TOPIC), e))
    }

    /// A writer for `topic` made on the fly, announced to the graph.
    fn writer(&mut self, topic: &str, ros_type: &str) -> Result<()> {
        if !self.writers.contains_key(topic) {
            self.add_writer(topic, ros_type)?;
            self.announce()?;
        }
        Ok(())
    }

    fn add_writer(&mut self, topic: &str, ros_type: &str) -> Result<()> {
        if !self.writers.contains_key(topic) {
            let ty = dds_type(ros_type)
                .ok_or_else(|| err!("ROS 2 bridge: topic {topic}: '{ros_type}' is not a pkg/msg/Type name"))?;
            let name = dds_topic(self.config.remap.apply(topic));
            let q = qos::writer(qos::kind_of(topic, ros_type));
            let t = self
                .participant
                .create_topic(name.clone(), ty, &q, TopicKind::NoKey)
                .map_err(|e| dds_err(&format!("topic {name}"), e))?;
            let w = self
                .publisher
                .create_datawriter_no_key::<RawCdr, RawAdapter>(&t, Some(q))
                .map_err(|e| dds_err(&format!("writer of {name}"), e))?;
            self.writers.insert(topic.to_string(), w);
        }
        Ok(())
    }

    fn write(&mut self, topic: &str, ros_type: &str, cdr: Vec<u8>) -> Result<()> {
        self.writer(topic, ros_type)?;
        let len = cdr.len() as u64;
        self.writers[topic].write(RawCdr(cdr), None).map_err(|e| dds_err(&format!("publishing on {topic}"), e))?;
        let mut s = self.stats.lock().expect("stats lock");
        s.published += 1;
        s.published_bytes += len;
        let e = s.topics.entry(topic.to_string()).or_default();
        e.0 += 1;
        e.1 += len;
        Ok(())
    }

    /// Takes what DDS has received into the pending lists.
    fn poll(&mut self) {
        let mut failed = 0;
        for i in &mut self.inbound {
            loop {
                match i.reader.take_next_sample() {
                    Ok(Some(s)) => {
                        let sender = format!("{:?}", s.sample_info().writer_guid());
                        i.pending.push((sender, s.into_value().0));
                    }
                    Ok(None) => break,
                    Err(_) => {
                        failed += 1;
                        break;
                    }
                }
            }
        }
        if failed > 0 {
            self.stats.lock().expect("stats lock").rejected += failed;
        }
    }

    /// Lockstep start: writers for what the bus has now, then wait until the peers are there
    /// (a writer on every lockstep topic, a reader of /clock) or the startup timeout passes.
    fn await_peers(&mut self, bus: &mut Bus) -> Result<()> {
        let topics: Vec<(String, String)> = bus
            .topics()
            .filter(|(t, _)| !self.inbound_topics.contains(*t))
            .map(|(t, ty)| (t.to_string(), ty.to_string()))
            .collect();
        for (t, ty) in &topics {
            self.writer(t, ty)?;
        }
        self.writer("/clock", Clock::TYPE_NAME)?;
        let wanted: Vec<String> = self.config.lockstep.iter().map(|t| dds_topic(self.config.remap.apply(t))).collect();
        let deadline = Instant::now() + self.config.startup_timeout;
        loop {
            let writers: BTreeSet<String> = self
                .participant
                .discovered_writers()
                .into_iter()
                .map(|w| w.publication_topic_data.topic_name)
                .collect();
            let clock = dds_topic(self.config.remap.apply("/clock"));
            let clock_heard =
                self.participant.discovered_readers().iter().any(|r| r.subscription_topic_data.topic_name() == &clock);
            if clock_heard && wanted.iter().all(|t| writers.contains(t)) {
                // The peers' readers of our other topics are announced with the same
                // discovery round; give their acknowledgements a moment.
                std::thread::sleep(Duration::from_millis(200));
                return Ok(());
            }
            if Instant::now() >= deadline {
                bus.reject(format!(
                    "ROS 2 bridge: no peer after {:?} (wanted writers on {}, a reader of /clock); starting anyway",
                    self.config.startup_timeout,
                    self.config.lockstep.join(", ")
                ));
                return Ok(());
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    }

    fn answered(&self) -> bool {
        self.config.lockstep.iter().all(|t| self.inbound.iter().any(|i| &i.topic == t && !i.pending.is_empty()))
    }
}

impl Node for Ros2Bridge {
    fn name(&self) -> &str {
        "ros2_bridge"
    }

    fn step(&mut self, t_ns: i64, bus: &mut Bus) -> Result<()> {
        if !self.started {
            self.started = true;
            if matches!(self.config.mode, Mode::Lockstep { .. }) && !self.config.lockstep.is_empty() {
                self.await_peers(bus)?;
            }
        }
        // Everything new on the bus, topic by topic in name order, oldest first.
        let inbound = &self.inbound_topics;
        let mut reliable_written = BTreeSet::new();
        for (topic, ty, s) in self.tap.take(bus, |t| !inbound.contains(t)) {
            if qos::kind_of(&topic, &ty) != qos::Kind::Sensor {
                reliable_written.insert(topic.clone());
            }
            self.write(&topic, &ty, s.cdr.to_vec())?;
        }
        if let Mode::Lockstep { timeout } = self.config.mode {
            // DDS orders messages per writer only: a peer could see this instant's /clock
            // before the instant's messages on other topics. In lockstep, every reliable
            // message is acknowledged by its readers before /clock goes out, so a peer that
            // acts on /clock has them all (best-effort sensor streams carry no such promise).
            for topic in &reliable_written {
                let _ = self.writers[topic].wait_for_acknowledgments(timeout);
            }
        }
        let scalars: Vec<(String, f64)> = bus
            .scalars()
            .iter()
            .filter(|(t, _)| !self.inbound_topics.contains(*t))
            .map(|(t, v)| (t.clone(), *v))
            .collect();
        for (topic, data) in scalars {
            self.write(&topic, Float64::TYPE_NAME, Float64 { data }.to_cdr())?;
        }
        self.write("/clock", Clock::TYPE_NAME, Clock { clock: Time::from_nanos(t_ns) }.to_cdr())?;
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
                            bus.reject(format!("ROS 2 bridge: at t={} s no answer on {} within {:?} (lockstep goes on; further timeouts are counted, not reported)", t_ns as f64 * 1e-9, self.config.lockstep.join(", "), timeout));
                        }
                        break;
                    }
                    // Polling the peers: wall-clock waiting, never an input to results.
                    std::thread::sleep(Duration::from_micros(100));
                }
            }
        }
        let waited = published.elapsed().as_secs_f64();
        let mut rejected = 0;
        let mut received = 0;
        for i in &mut self.inbound {
            for (sender, cdr) in i.pending.drain(..) {
                match agrisim_msgs::check_cdr(&i.ros_type, &cdr) {
                    Some(Ok(())) if i.scalar => match Float64::from_cdr(&cdr) {
                        Ok(Float64 { data }) if data.is_finite() => {
                            received += 1;
                            bus.set_scalar(&i.topic, data);
                        }
                        _ => {
                            rejected += 1;
                            bus.reject(format!("ROS 2 bridge: scalar {} from writer {sender}: not a finite number; rejected (the last valid value stays in force)", i.topic));
                        }
                    },
                    Some(Ok(())) => {
                        received += 1;
                        bus.publish_raw(&i.topic, &i.ros_type, t_ns, cdr);
                    }
                    Some(Err(e)) => {
                        rejected += 1;
                        bus.reject(format!("ROS 2 bridge: topic {} from writer {sender}: {} bytes are not a valid {}: {e}; rejected (the last valid message stays in force)", i.topic, cdr.len(), i.ros_type));
                    }
                    None => {
                        rejected += 1;
                        bus.reject(format!("ROS 2 bridge: topic {}: unknown type {}", i.topic, i.ros_type));
                    }
                }
            }
        }
        let mut s = self.stats.lock().expect("stats lock");
        s.instants += 1;
        s.waited += waited;
        s.received += received;
        s.rejected += rejected;
        Ok(())
    }
}
