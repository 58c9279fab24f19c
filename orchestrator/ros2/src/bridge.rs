//! The DDS transport of the live link: the bridge's participant, its writers (made from the
//! start for the system's message outputs, on the fly for the rest) and its readers of the
//! inbound topics. What it does at each message instant (pacing, lockstep, checks, stats) is
//! agrisim-link's [`Link`], shared with the Zenoh link.

use crate::announce::{self, Announcer};
use crate::confine;
use crate::graph::{self, Distro};
use crate::names::{dds_topic, dds_type, Remap};
use crate::qos;
use crate::raw::{RawAdapter, RawCdr};
use agrisim_bus::{Bus, Node};
use agrisim_error::{err, Result};
use agrisim_link::{Arrival, Link, Topics, Transport};
pub use agrisim_link::{Mode, Stats};
use rustdds::no_key::{DataReader, DataWriter};
use rustdds::{DomainParticipant, DomainParticipantBuilder, Publisher, RTPSEntity, Subscriber, TopicKind};
use std::collections::{BTreeMap, BTreeSet};
use std::net::{IpAddr, Ipv4Addr};
use std::sync::{Arc, Mutex};
use std::time::Duration;

#[derive(Clone, Debug)]
pub struct BridgeConfig {
    /// DDS domain (ROS_DOMAIN_ID).
    pub domain: u16,
    /// What crosses and how time is kept (shared with the Zenoh link).
    pub topics: Topics,
    /// Advertise and talk on the loopback interface only and hear only this machine (the
    /// default; see [`confine`]); false: every interface.
    pub loopback_only: bool,
    /// The distro whose graph-information layout `ros_discovery_info` follows.
    pub distro: Distro,
}

struct Reader {
    /// Its index in the link's inbound list.
    index: usize,
    reader: DataReader<RawCdr, RawAdapter>,
}

/// The DDS side of the bridge.
pub struct Dds {
    publisher: Publisher,
    remap: Remap,
    participant: DomainParticipant,
    writers: BTreeMap<String, DataWriter<RawCdr, RawAdapter>>,
    readers: Vec<Reader>,
    /// The writer of `ros_discovery_info` (see [`graph`]).
    graph: DataWriter<RawCdr, RawAdapter>,
    distro: Distro,
    /// Loopback only: the participant's announcements repeated to this machine's LAN
    /// addresses (see [`announce`]).
    _announcer: Option<Announcer>,
}

/// The bridge node: [`Link`] over [`Dds`].
pub struct Ros2Bridge(Link<Dds>);

fn dds_err(what: &str, e: impl std::fmt::Debug) -> agrisim_error::Error {
    err!("ROS 2 bridge: {what}: {e:?}")
}

impl Ros2Bridge {
    /// Joins DDS domain `config.domain` and subscribes to the inbound topics. The returned
    /// handle's [`Stats`] fill in as the run goes.
    pub fn new(config: BridgeConfig) -> Result<(Ros2Bridge, Arc<Mutex<Stats>>)> {
        let link = config.topics.link("ROS 2 bridge", "ros2_bridge")?;
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
        let mut readers = vec![];
        for (index, i) in link.inbound.iter().enumerate() {
            let ty = dds_type(&i.ros_type)
                .ok_or_else(|| err!("ROS 2 bridge: topic {}: '{}' is not a pkg/msg/Type name", i.topic, i.ros_type))?;
            let name = dds_topic(config.topics.remap.apply(&i.topic));
            let t = participant
                .create_topic(name.clone(), ty, &qos::reader(), TopicKind::NoKey)
                .map_err(|e| dds_err(&format!("topic {name}"), e))?;
            let reader = subscriber
                .create_datareader_no_key::<RawCdr, RawAdapter>(&t, Some(qos::reader()))
                .map_err(|e| dds_err(&format!("reader of {name}"), e))?;
            readers.push(Reader { index, reader });
        }
        let q = qos::writer(qos::Kind::Latched);
        let t = participant
            .create_topic(graph::TOPIC.to_string(), graph::TYPE.to_string(), &q, TopicKind::NoKey)
            .map_err(|e| dds_err(graph::TOPIC, e))?;
        let graph = publisher
            .create_datawriter_no_key::<RawCdr, RawAdapter>(&t, Some(q))
            .map_err(|e| dds_err(&format!("writer of {}", graph::TOPIC), e))?;
        let mut dds = Dds {
            publisher,
            remap: config.topics.remap.clone(),
            participant,
            writers: BTreeMap::new(),
            readers,
            graph,
            distro: config.distro,
            _announcer: announcer,
        };
        for (t, ty) in config.topics.writers() {
            dds.add_writer(&t, &ty)?;
        }
        dds.announce()?;
        let (link, stats) = Link::new(dds, link)?;
        Ok((Ros2Bridge(link), stats))
    }
}

impl Dds {
    /// Publishes the bridge's node with its readers and writers on `ros_discovery_info`.
    fn announce(&mut self) -> Result<()> {
        let readers: Vec<[u8; 16]> = self.readers.iter().map(|r| r.reader.guid().to_bytes()).collect();
        let writers: Vec<[u8; 16]> = self.writers.values().map(|w| w.guid().to_bytes()).collect();
        let cdr = graph::participant_info(self.distro, self.participant.guid().to_bytes(), &readers, &writers);
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
            let name = dds_topic(self.remap.apply(topic));
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
}

impl Transport for Dds {
    fn write(&mut self, topic: &str, ros_type: &str, cdr: &[u8]) -> Result<()> {
        self.writer(topic, ros_type)?;
        self.writers[topic].write(RawCdr(cdr.to_vec()), None).map_err(|e| dds_err(&format!("publishing on {topic}"), e))
    }

    /// DDS orders messages per writer only: a peer could see this instant's /clock before
    /// the instant's messages on other topics. In lockstep, every reliable message is
    /// acknowledged by its readers before /clock goes out, so a peer that acts on /clock has
    /// them all (best-effort sensor streams carry no such promise).
    fn flush(&mut self, topics: &BTreeSet<String>, timeout: Duration) {
        for topic in topics {
            if let Some(w) = self.writers.get(topic) {
                let _ = w.wait_for_acknowledgments(timeout);
            }
        }
    }

    fn poll(&mut self, out: &mut Vec<Arrival>) {
        for r in &mut self.readers {
            loop {
                match r.reader.take_next_sample() {
                    Ok(Some(s)) => {
                        let sender = format!("{:?}", s.sample_info().writer_guid());
                        out.push(Arrival::Sample { index: r.index, sender, cdr: s.into_value().0 });
                    }
                    Ok(None) => break,
                    Err(e) => {
                        out.push(Arrival::Rejected(format!("a sample that could not be taken from DDS: {e:?}")));
                        break;
                    }
                }
            }
        }
    }

    fn prepare(&mut self, topics: &[(String, String)]) -> Result<()> {
        for (t, ty) in topics {
            self.writer(t, ty)?;
        }
        Ok(())
    }

    fn peers_ready(&mut self, lockstep: &[String]) -> bool {
        let wanted: Vec<String> = lockstep.iter().map(|t| dds_topic(self.remap.apply(t))).collect();
        let writers: BTreeSet<String> =
            self.participant.discovered_writers().into_iter().map(|w| w.publication_topic_data.topic_name).collect();
        let clock = dds_topic(self.remap.apply("/clock"));
        let clock_heard =
            self.participant.discovered_readers().iter().any(|r| r.subscription_topic_data.topic_name() == &clock);
        clock_heard && wanted.iter().all(|t| writers.contains(t))
    }

    /// The peers' readers of our other topics are announced with the same discovery round;
    /// give their acknowledgements a moment.
    fn settle(&mut self) {
        std::thread::sleep(Duration::from_millis(200));
    }
}

impl Node for Ros2Bridge {
    fn name(&self) -> &str {
        self.0.name()
    }

    fn step(&mut self, t_ns: i64, bus: &mut Bus) -> Result<()> {
        self.0.step(t_ns, bus)
    }
}
