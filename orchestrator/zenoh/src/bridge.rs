//! The Zenoh transport of the live link: one Zenoh session (peer mode by default, TCP,
//! multicast scouting off, listening on loopback), a publisher per outbound topic, a
//! subscriber per inbound topic, liveliness tokens for the node and each of them. What it
//! does at each message instant (pacing, lockstep, checks, stats) is agrisim-link's [`Link`],
//! shared with the DDS bridge.
//!
//! Transient-local topics (those agrisim-link's [`kind_of`] calls [`Kind::Latched`], the
//! same decision the DDS bridge takes: /robot_description, /tf_static, /map, the scene's
//! markers) are published as rmw_zenoh publishes for a TRANSIENT_LOCAL publisher, so a
//! viewer started after the run (RViz over rmw_zenoh) still gets them; see [`Writer`].

use crate::wire::{self, Attachment, Entity, Qos};
use agrisim_bus::{Bus, Node};
use agrisim_error::{err, Result};
use agrisim_link::{dds_type, kind_of, Arrival, Kind, Link, Remap, Topics, Transport};
pub use agrisim_link::{Mode, Stats};
use std::collections::{BTreeMap, BTreeSet};
use std::sync::{Arc, Mutex};
use std::time::{Duration, SystemTime};
use zenoh::handlers::FifoChannelHandler;
use zenoh::liveliness::LivelinessToken;
use zenoh::pubsub::{Publisher, Subscriber};
use zenoh::qos::CongestionControl;
use zenoh::sample::{Sample, SampleKind};
use zenoh::{Session, Wait};
use zenoh_ext::{AdvancedPublisher, AdvancedPublisherBuilderExt, CacheConfig, MissDetectionConfig};

/// Where the session listens by default: loopback, rmw_zenoh's router port.
pub const DEFAULT_LISTEN: &str = "tcp/127.0.0.1:7447";

#[derive(Clone, Debug)]
pub struct ZenohConfig {
    /// ROS_DOMAIN_ID: the first chunk of every key.
    pub domain: u32,
    /// What crosses and how time is kept (shared with the DDS bridge).
    pub topics: Topics,
    /// Zenoh endpoints to listen on (`tcp/127.0.0.1:7447`); may be empty.
    pub listen: Vec<String>,
    /// Zenoh endpoints to connect to (a router such as rmw_zenohd, another peer).
    pub connect: Vec<String>,
    /// Zenoh session mode: `peer` (the default), `client` or `router`.
    pub session_mode: String,
    /// Multicast scouting (finds peers on the LAN); off unless asked for.
    pub multicast_scouting: bool,
}

/// How a topic's samples leave: a plain publisher, or, for a transient-local topic, a
/// zenoh-ext AdvancedPublisher that keeps the topic's last `depth` samples for late joiners.
///
/// This follows rmw_zenoh_cpp's `PublisherData::make` in
/// `rmw_zenoh_cpp/src/detail/rmw_publisher_data.cpp` (ros2/rmw_zenoh, rolling at commit
/// 3e19ec7: zenoh-cpp 1.x, `session->ext().declare_advanced_publisher`): for
/// durability TRANSIENT_LOCAL it turns on publisher detection (a liveliness token under
/// `<key>/@adv/pub/...` that AdvancedSubscribers with `detect_late_publishers` watch), a cache
/// of `depth` samples (the QoS history depth) that answers their history queries, and, when
/// the publisher is RELIABLE too, sample miss detection with a sporadic heartbeat every
/// 500 ms (its SAMPLE_MISS_DETECTION_HEARTBEAT_PERIOD), which also gives the samples the
/// per-publisher sequence numbers the subscribers order history by (so the session needs no
/// timestamping). Its subscriptions of TRANSIENT_LOCAL topics (rmw_subscription_data.cpp)
/// are AdvancedSubscribers with history (`max_samples` = depth, late publisher detection)
/// and, when reliable, heartbeat recovery. Older rmw_zenoh (rolling in October 2024, commit
/// bfc065f) declared a publication cache and querying subscribers instead; this is the newer
/// scheme. Volatile topics keep a plain publisher (rmw_zenoh's advanced publisher with every
/// option off is one), so sensor streams pay nothing for it.
enum Outlet {
    Plain(Publisher<'static>),
    Cached(AdvancedPublisher<'static>),
}

/// rmw_zenoh's heartbeat period of a reliable transient-local publisher's sample miss
/// detection (rmw_publisher_data.cpp, SAMPLE_MISS_DETECTION_HEARTBEAT_PERIOD).
const MISS_DETECTION_HEARTBEAT: Duration = Duration::from_millis(500);

struct Writer {
    publisher: Outlet,
    gid: [u8; 16],
    sequence: i64,
    _token: LivelinessToken,
}

struct Reader {
    index: usize,
    topic: String,
    /// The DDS type name and type hash a sample's key must carry.
    dds_type: String,
    hash: &'static str,
    subscriber: Subscriber<FifoChannelHandler<Sample>>,
    _token: LivelinessToken,
}

/// The Zenoh side of the bridge.
pub struct Zenoh {
    session: Session,
    zid: String,
    domain: u32,
    remap: Remap,
    /// Sensor streams are dropped under congestion (best effort) unless the run waits for
    /// peers in lockstep; everything else blocks until sent.
    lockstep: bool,
    writers: BTreeMap<String, Writer>,
    readers: Vec<Reader>,
    /// Entity ids (the node is 0).
    next_id: u32,
    /// The live tokens of other sessions (key expressions), from the liveliness subscriber.
    peers: Subscriber<FifoChannelHandler<Sample>>,
    alive: BTreeSet<String>,
    _node: LivelinessToken,
}

/// The bridge node: [`Link`] over [`Zenoh`].
pub struct ZenohBridge(Link<Zenoh>);

fn z_err(what: &str, e: impl std::fmt::Display) -> agrisim_error::Error {
    err!("Zenoh bridge: {what}: {e}")
}

/// Fails with a clear error if a `tcp/HOST:PORT` listen endpoint's port is taken (Zenoh's
/// own error does not say so plainly).
fn check_port(endpoint: &str) -> Result<()> {
    let Some(addr) = endpoint.strip_prefix("tcp/") else { return Ok(()) };
    let addr = addr.split('#').next().unwrap_or(addr);
    let Ok(sock) = addr.parse::<std::net::SocketAddr>() else { return Ok(()) };
    match std::net::TcpListener::bind(sock) {
        Ok(_) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::AddrInUse => Err(err!(
            "Zenoh bridge: cannot listen on {endpoint}: port {} is in use (another run, or a Zenoh router such as rmw_zenohd? connect to it with --zenoh-connect {endpoint} --zenoh-listen none, or listen on another port)",
            sock.port()
        )),
        Err(e) => Err(err!("Zenoh bridge: cannot listen on {endpoint}: {e}")),
    }
}

fn json_list(items: &[String]) -> String {
    let quoted: Vec<String> = items.iter().map(|s| format!("{s:?}")).collect();
    format!("[{}]", quoted.join(","))
}

fn now_ns() -> i64 {
    // The attachment's source timestamp is wall time, as rmw_zenoh's (never an input).
    SystemTime::now().duration_since(SystemTime::UNIX_EPOCH).map_or(0, |d| d.as_nanos() as i64)
}

impl ZenohBridge {
    /// Opens the Zenoh session, subscribes to the inbound topics and declares the tokens. The
    /// returned handle's [`Stats`] fill in as the run goes.
    pub fn new(config: ZenohConfig) -> Result<(ZenohBridge, Arc<Mutex<Stats>>)> {
        let link = config.topics.link("Zenoh bridge", "zenoh_bridge")?;
        if !["peer", "client", "router"].contains(&config.session_mode.as_str()) {
            return Err(err!("Zenoh bridge: session mode '{}': expected peer, client or router", config.session_mode));
        }
        for e in &config.listen {
            check_port(e)?;
        }
        let mut zc = zenoh::Config::default();
        let set = |zc: &mut zenoh::Config, key: &str, value: String| {
            zc.insert_json5(key, &value).map_err(|e| z_err(&format!("configuration {key} = {value}"), e))
        };
        set(&mut zc, "mode", format!("{:?}", config.session_mode))?;
        set(&mut zc, "listen/endpoints", json_list(&config.listen))?;
        set(&mut zc, "connect/endpoints", json_list(&config.connect))?;
        set(&mut zc, "scouting/multicast/enabled", config.multicast_scouting.to_string())?;
        let session = zenoh::open(zc).wait().map_err(|e| match e.to_string() {
            m if m.contains("in use") => {
                err!("Zenoh bridge: cannot listen on {}: a port is in use ({m})", config.listen.join(", "))
            }
            m => err!(
                "Zenoh bridge: cannot open a session (listen {:?}, connect {:?}): {m}",
                config.listen,
                config.connect
            ),
        })?;
        let zid = session.zid().to_string();
        let domain = config.domain;
        let node_key = wire::token(domain, &zid, 0, Entity::Node).map_err(|e| err!("Zenoh bridge: {e}"))?;
        let node = session.liveliness().declare_token(node_key.clone()).wait().map_err(|e| z_err(&node_key, e))?;
        let peers_key = format!("{}/{domain}/**", wire::ADMIN_SPACE);
        let peers = session
            .liveliness()
            .declare_subscriber(peers_key.clone())
            .history(true)
            .wait()
            .map_err(|e| z_err(&format!("liveliness subscriber {peers_key}"), e))?;
        let mut z = Zenoh {
            session,
            zid,
            domain,
            remap: config.topics.remap.clone(),
            lockstep: matches!(config.topics.mode, Mode::Lockstep { .. }) && !config.topics.lockstep.is_empty(),
            writers: BTreeMap::new(),
            readers: vec![],
            next_id: 1,
            peers,
            alive: BTreeSet::new(),
            _node: node,
        };
        for (index, i) in link.inbound.iter().enumerate() {
            z.add_reader(index, &i.topic, &i.ros_type)?;
        }
        for (t, ty) in config.topics.writers() {
            z.writer(&t, &ty)?;
        }
        let (link, stats) = Link::new(z, link)?;
        Ok((ZenohBridge(link), stats))
    }
}

impl Zenoh {
    fn token(&mut self, entity: Entity) -> Result<(String, LivelinessToken)> {
        let key = wire::token(self.domain, &self.zid, self.next_id, entity).map_err(|e| err!("Zenoh bridge: {e}"))?;
        self.next_id += 1;
        let t = self.session.liveliness().declare_token(key.clone()).wait().map_err(|e| z_err(&key, e))?;
        Ok((key, t))
    }

    fn add_reader(&mut self, index: usize, topic: &str, ros_type: &str) -> Result<()> {
        let name = self.remap.apply(topic).to_string();
        // Any type on the topic's name: a sample with another type or hash is rejected (and
        // reported), not silently unheard.
        let key = wire::topic_key(self.domain, &name, ros_type).map_err(|e| err!("Zenoh bridge: {e}"))?;
        let (prefix, _) =
            key.rsplit_once('/').and_then(|(p, _)| p.rsplit_once('/')).expect("a topic key has four parts");
        let wild = format!("{prefix}/*/*");
        let subscriber = self
            .session
            .declare_subscriber(wild.clone())
            .wait()
            .map_err(|e| z_err(&format!("subscriber {wild}"), e))?;
        let entity = Entity::Subscription { topic: &name, ros_type, qos: Qos::reader() };
        let (_, token) = self.token(entity)?;
        self.readers.push(Reader {
            index,
            topic: name,
            dds_type: dds_type(ros_type).expect("checked by topic_key"),
            hash: wire::type_hash(ros_type).expect("checked by topic_key"),
            subscriber,
            _token: token,
        });
        Ok(())
    }

    /// The publisher of `topic` (made on the first use) and its token.
    fn writer(&mut self, topic: &str, ros_type: &str) -> Result<&mut Writer> {
        if !self.writers.contains_key(topic) {
            let name = self.remap.apply(topic).to_string();
            let key = wire::topic_key(self.domain, &name, ros_type).map_err(|e| err!("Zenoh bridge: {e}"))?;
            let kind = kind_of(topic, ros_type);
            let congestion =
                if kind == Kind::Sensor && !self.lockstep { CongestionControl::Drop } else { CongestionControl::Block };
            let qos = Qos::writer(kind);
            let builder = self.session.declare_publisher(key.clone()).congestion_control(congestion);
            let publisher = if qos.transient_local {
                // Keep last N (N from the QoS); a keep-all transient-local writer would keep
                // everything, which agrisim has none of.
                let depth = qos.keep_last.unwrap_or(1).max(1) as usize;
                let mut b = builder.cache(CacheConfig::default().max_samples(depth)).publisher_detection();
                if !qos.best_effort {
                    b = b.sample_miss_detection(
                        MissDetectionConfig::default().sporadic_heartbeat(MISS_DETECTION_HEARTBEAT),
                    );
                }
                b.wait().map(Outlet::Cached)
            } else {
                builder.wait().map(Outlet::Plain)
            }
            .map_err(|e| z_err(&format!("publisher {key}"), e))?;
            let (token_key, token) = self.token(Entity::Publisher { topic: &name, ros_type, qos })?;
            self.writers.insert(
                topic.to_string(),
                Writer { publisher, gid: wire::gid(&token_key), sequence: 0, _token: token },
            );
        }
        Ok(self.writers.get_mut(topic).expect("just made"))
    }

    /// Takes the liveliness changes into `alive`.
    fn update_peers(&mut self) {
        while let Ok(Some(s)) = self.peers.try_recv() {
            let key = s.key_expr().as_str().to_string();
            match s.kind() {
                SampleKind::Put => self.alive.insert(key),
                SampleKind::Delete => self.alive.remove(&key),
            };
        }
    }
}

impl Transport for Zenoh {
    fn write(&mut self, topic: &str, ros_type: &str, cdr: &[u8]) -> Result<()> {
        let w = self.writer(topic, ros_type)?;
        w.sequence += 1;
        let att = Attachment { sequence: w.sequence, timestamp_ns: now_ns(), gid: w.gid };
        match &w.publisher {
            Outlet::Plain(p) => p.put(cdr.to_vec()).attachment(att.encode()).wait(),
            Outlet::Cached(p) => p.put(cdr.to_vec()).attachment(att.encode()).wait(),
        }
        .map_err(|e| z_err(&format!("publishing on {topic}"), e))
    }

    fn poll(&mut self, out: &mut Vec<Arrival>) {
        for r in &self.readers {
            while let Ok(Some(s)) = r.subscriber.try_recv() {
                let key = s.key_expr().as_str();
                let sender = match s.attachment().map(|a| Attachment::decode(&a.to_bytes())) {
                    Some(Some(a)) => a.gid.iter().map(|b| format!("{b:02x}")).collect::<String>(),
                    _ => {
                        out.push(Arrival::Rejected(format!(
                            "topic {}: a sample on {key} without an rmw_zenoh attachment (sequence number, timestamp, GID); rejected",
                            r.topic
                        )));
                        continue;
                    }
                };
                match wire::parse_topic_key(key) {
                    Some((_, _, ty, hash)) if ty == r.dds_type && hash == r.hash => {
                        out.push(Arrival::Sample { index: r.index, sender, cdr: s.payload().to_bytes().into_owned() })
                    }
                    Some((_, _, ty, hash)) => out.push(Arrival::Rejected(format!(
                        "topic {} from writer {sender}: type {ty} with hash {hash}, expected {} with hash {} (another definition of the type); rejected",
                        r.topic, r.dds_type, r.hash
                    ))),
                    None => out.push(Arrival::Rejected(format!(
                        "topic {}: a sample on {key}, not a key <domain>/<topic>/<type>/<hash>; rejected",
                        r.topic
                    ))),
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
        self.update_peers();
        let own = format!("{}/{}/{}/", wire::ADMIN_SPACE, self.domain, self.zid);
        let mut publishers = BTreeSet::new();
        let mut clock_heard = false;
        let clock = self.remap.apply("/clock");
        for key in self.alive.iter().filter(|k| !k.starts_with(&own)) {
            if let Some((kind, Some((topic, _)))) = wire::parse_token(self.domain, key) {
                match kind.as_str() {
                    "MP" => {
                        publishers.insert(topic);
                    }
                    "MS" if topic == clock => clock_heard = true,
                    _ => {}
                }
            }
        }
        clock_heard && lockstep.iter().all(|t| publishers.contains(self.remap.apply(t)))
    }

    /// The peers' subscriptions are declared with their tokens; give the declarations a
    /// moment to reach this session.
    fn settle(&mut self) {
        std::thread::sleep(Duration::from_millis(200));
    }
}

impl Drop for Zenoh {
    /// Closes the session now (its listener, tokens and declarations go with it), so the next
    /// trial's bridge can listen on the same port.
    fn drop(&mut self) {
        let _ = self.session.close().wait();
    }
}

impl Node for ZenohBridge {
    fn name(&self) -> &str {
        self.0.name()
    }

    fn step(&mut self, t_ns: i64, bus: &mut Bus) -> Result<()> {
        self.0.step(t_ns, bus)
    }
}
