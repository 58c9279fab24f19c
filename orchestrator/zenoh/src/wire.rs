//! rmw_zenoh's wire format (rmw_zenoh_cpp, ROS 2 Jazzy and later; its docs/design.md and
//! `liveliness_utils`/`attachment_helpers`), written from that description:
//!
//! * a topic's data travel on key `<domain>/<topic without its leading slash>/<DDS type
//!   name>/<REP 2011 type hash>`, e.g. `0/cmd_vel/geometry_msgs::msg::dds_::Twist_/RIHS01_…`;
//!   the payload is the message's CDR with its 4-byte encapsulation header;
//! * each sample's attachment is, in the Zenoh serialization format, the sequence number
//!   (i64), the source timestamp (i64, ns) and the publisher's 16-byte GID as a sequence
//!   (LEB128 length 16, then the bytes): 33 bytes;
//! * each node, publisher and subscription declares a liveliness token
//!   `@ros2_lv/<domain>/<session id>/<node id>/<entity id>/<NN|MP|MS>/<enclave>/<namespace>/<node>`
//!   and, for a publisher or subscription, `/<topic>/<type>/<type hash>/<QoS>`, names with
//!   `/` replaced by `%` (an empty namespace is `%`), the QoS as
//!   `rel:dur:hist,depth:deadline_s,ns:lifespan_s,ns:liveliness,lease_s,ns` where a value
//!   equal to rmw_zenoh's default (reliable, volatile, keep last 42, infinite durations,
//!   automatic liveliness) is left empty.

use agrisim_link::{dds_type, Kind};

/// The admin space of rmw_zenoh's liveliness tokens.
pub const ADMIN_SPACE: &str = "@ros2_lv";

/// A name in a liveliness token: `/` becomes `%`.
pub fn mangle(name: &str) -> String {
    name.replace('/', "%")
}

/// The REP 2011 hash of ROS 2 type `pkg/msg/Type` (computed once for every known type).
pub fn type_hash(ros_type: &str) -> Option<&'static str> {
    agrisim_msgs::type_hash::type_hashes().get(ros_type).map(String::as_str)
}

/// The data key of `topic` (absolute ROS 2 name) of type `ros_type` in `domain`, or an error
/// naming what is wrong.
pub fn topic_key(domain: u32, topic: &str, ros_type: &str) -> Result<String, String> {
    let ty = dds_type(ros_type).ok_or_else(|| format!("topic {topic}: '{ros_type}' is not a pkg/msg/Type name"))?;
    let hash = type_hash(ros_type).ok_or_else(|| format!("topic {topic}: no type hash for {ros_type}"))?;
    let name = topic.trim_matches('/');
    if name.is_empty() || name.split('/').any(|c| c.is_empty() || c.contains(['*', '$', '?', '#', '@'])) {
        return Err(format!("topic '{topic}' is not a ROS 2 topic name Zenoh can carry"));
    }
    Ok(format!("{domain}/{name}/{ty}/{hash}"))
}

/// The parts of a data key: domain, topic (absolute), DDS type name, type hash.
pub fn parse_topic_key(key: &str) -> Option<(u32, String, &str, &str)> {
    let (domain, rest) = key.split_once('/')?;
    let (rest, hash) = rest.rsplit_once('/')?;
    let (topic, ty) = rest.rsplit_once('/')?;
    if topic.is_empty() || ty.is_empty() || hash.is_empty() {
        return None;
    }
    Some((domain.parse().ok()?, format!("/{topic}"), ty, hash))
}

/// The attachment of a sample: sequence number, source timestamp [ns], publisher GID.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Attachment {
    pub sequence: i64,
    pub timestamp_ns: i64,
    pub gid: [u8; 16],
}

impl Attachment {
    /// Its bytes (Zenoh serialization format: i64 LE, i64 LE, LEB128 length, bytes).
    pub fn encode(&self) -> Vec<u8> {
        let mut v = Vec::with_capacity(33);
        v.extend_from_slice(&self.sequence.to_le_bytes());
        v.extend_from_slice(&self.timestamp_ns.to_le_bytes());
        v.push(16); // LEB128 of 16 is one byte.
        v.extend_from_slice(&self.gid);
        v
    }

    /// Reads an attachment; None unless it is exactly this layout.
    pub fn decode(b: &[u8]) -> Option<Attachment> {
        if b.len() != 33 || b[16] != 16 {
            return None;
        }
        Some(Attachment {
            sequence: i64::from_le_bytes(b[..8].try_into().ok()?),
            timestamp_ns: i64::from_le_bytes(b[8..16].try_into().ok()?),
            gid: b[17..].try_into().ok()?,
        })
    }
}

/// A QoS profile as rmw_zenoh writes it in a token (the fields agrisim sets).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Qos {
    pub best_effort: bool,
    pub transient_local: bool,
    /// None: keep all.
    pub keep_last: Option<u32>,
}

/// rmw_zenoh's default history depth (keep last 42).
const DEFAULT_DEPTH: u32 = 42;

impl Qos {
    /// The QoS agrisim's writers of a topic of kind `kind` have (as over DDS).
    pub fn writer(kind: Kind) -> Qos {
        match kind {
            Kind::Sensor => Qos { best_effort: true, transient_local: false, keep_last: Some(5) },
            Kind::Latched => Qos { best_effort: false, transient_local: true, keep_last: Some(1) },
            Kind::Default => Qos { best_effort: false, transient_local: false, keep_last: Some(10) },
        }
    }

    /// The QoS of agrisim's subscriptions to commands: reliable, volatile, keep all.
    pub fn reader() -> Qos {
        Qos { best_effort: false, transient_local: false, keep_last: None }
    }

    /// Its form in a liveliness token (rmw enum values: reliability 2 best effort, durability
    /// 1 transient local, history 2 keep all).
    pub fn to_key(self) -> String {
        let rel = if self.best_effort { "2" } else { "" };
        let dur = if self.transient_local { "1" } else { "" };
        let (hist, depth) = match self.keep_last {
            None => ("2", String::new()),
            Some(d) if d == DEFAULT_DEPTH => ("", String::new()),
            Some(d) => ("", d.to_string()),
        };
        format!("{rel}:{dur}:{hist},{depth}:,:,:,,")
    }
}

/// What a liveliness token announces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Entity<'a> {
    Node,
    Publisher { topic: &'a str, ros_type: &'a str, qos: Qos },
    Subscription { topic: &'a str, ros_type: &'a str, qos: Qos },
}

/// The bridge's node: `/agrisim` (as over DDS), enclave `/`.
pub const NODE_NAMESPACE: &str = "/";
pub const NODE_NAME: &str = "agrisim";

/// The liveliness token of `entity` (number `id` of node 0 of session `zid`) in `domain`.
pub fn token(domain: u32, zid: &str, id: u32, entity: Entity) -> Result<String, String> {
    let kind = match entity {
        Entity::Node => "NN",
        Entity::Publisher { .. } => "MP",
        Entity::Subscription { .. } => "MS",
    };
    let node = format!(
        "{ADMIN_SPACE}/{domain}/{zid}/0/{id}/{kind}/{}/{}/{}",
        mangle("/"),
        mangle(NODE_NAMESPACE),
        mangle(NODE_NAME)
    );
    let (topic, ros_type, qos) = match entity {
        Entity::Node => return Ok(node),
        Entity::Publisher { topic, ros_type, qos } | Entity::Subscription { topic, ros_type, qos } => {
            (topic, ros_type, qos)
        }
    };
    let ty = dds_type(ros_type).ok_or_else(|| format!("topic {topic}: '{ros_type}' is not a pkg/msg/Type name"))?;
    let hash = type_hash(ros_type).ok_or_else(|| format!("topic {topic}: no type hash for {ros_type}"))?;
    Ok(format!("{node}/{}/{}/{hash}/{}", mangle(topic), mangle(&ty), qos.to_key()))
}

/// A token another session declared: its entity kind (`NN`, `MP`, `MS`, `SS`, `SC`) and, for
/// a publisher or subscription, its topic (absolute) and DDS type name; None if it is not an
/// rmw_zenoh token of `domain`.
pub fn parse_token(domain: u32, key: &str) -> Option<(String, Option<(String, String)>)> {
    let parts: Vec<&str> = key.split('/').collect();
    if parts.len() < 9 || parts[0] != ADMIN_SPACE || parts[1].parse::<u32>().ok()? != domain {
        return None;
    }
    let kind = parts[5].to_string();
    if kind == "NN" {
        return Some((kind, None));
    }
    if parts.len() < 13 {
        return None;
    }
    Some((kind, Some((parts[9].replace('%', "/"), parts[10].replace('%', "/")))))
}

/// A 16-byte id of an entity, from its token (FNV-1a, two seeds; rmw_zenoh itself hashes the
/// token with XXH3-128, but peers only compare GIDs, never recompute them).
pub fn gid(token: &str) -> [u8; 16] {
    let fnv = |seed: u64| token.bytes().fold(seed, |h, b| (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3));
    let mut g = [0u8; 16];
    g[..8].copy_from_slice(&fnv(0xcbf2_9ce4_8422_2325).to_le_bytes());
    g[8..].copy_from_slice(&fnv(0x6c62_272e_07bb_0142).to_le_bytes());
    g
}

#[cfg(test)]
mod tests {
    use super::*;

    const TWIST: &str = "RIHS01_9c45bf16fe0983d80e3cfe750d6835843d265a9a6c46bd2e609fcddde6fb8d2a";

    #[test]
    fn topic_keys() {
        assert_eq!(type_hash("geometry_msgs/msg/Twist"), Some(TWIST));
        let k = topic_key(0, "/cmd_vel", "geometry_msgs/msg/Twist").unwrap();
        assert_eq!(k, format!("0/cmd_vel/geometry_msgs::msg::dds_::Twist_/{TWIST}"));
        assert_eq!(parse_topic_key(&k), Some((0, "/cmd_vel".to_string(), "geometry_msgs::msg::dds_::Twist_", TWIST)));
        let k = topic_key(7, "/camera/color/image_raw", "sensor_msgs/msg/Image").unwrap();
        assert!(k.starts_with("7/camera/color/image_raw/sensor_msgs::msg::dds_::Image_/RIHS01_"), "{k}");
        assert_eq!(parse_topic_key(&k).unwrap().1, "/camera/color/image_raw");
        assert!(topic_key(0, "/cmd_vel", "Twist").is_err());
        assert!(topic_key(0, "/cmd_vel", "nope/msg/Nothing").is_err());
        assert!(topic_key(0, "/a//b", "geometry_msgs/msg/Twist").is_err());
        assert!(topic_key(0, "/a/*", "geometry_msgs/msg/Twist").is_err());
        assert_eq!(parse_topic_key("0/cmd_vel"), None);
        assert_eq!(parse_topic_key("x/cmd_vel/T/H"), None);
    }

    #[test]
    fn attachments() {
        let a = Attachment { sequence: 3, timestamp_ns: -2, gid: std::array::from_fn(|i| i as u8) };
        let b = a.encode();
        assert_eq!(b.len(), 33);
        assert_eq!(&b[..8], &[3, 0, 0, 0, 0, 0, 0, 0]);
        assert_eq!(&b[8..16], &[0xfe, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff]);
        assert_eq!(b[16], 0x10);
        assert_eq!(&b[17..], &a.gid);
        assert_eq!(Attachment::decode(&b), Some(a));
        assert_eq!(Attachment::decode(&b[..32]), None);
        let mut bad = b.clone();
        bad[16] = 15;
        assert_eq!(Attachment::decode(&bad), None);
    }

    #[test]
    fn qos_in_tokens() {
        assert_eq!(Qos::writer(Kind::Default).to_key(), "::,10:,:,:,,");
        assert_eq!(Qos::writer(Kind::Sensor).to_key(), "2::,5:,:,:,,");
        assert_eq!(Qos::writer(Kind::Latched).to_key(), ":1:,1:,:,:,,");
        assert_eq!(Qos::reader().to_key(), "::2,:,:,:,,");
        assert_eq!(Qos { best_effort: false, transient_local: false, keep_last: Some(42) }.to_key(), "::,:,:,:,,");
    }

    #[test]
    fn liveliness_tokens() {
        assert_eq!(token(0, "abc1", 0, Entity::Node).unwrap(), "@ros2_lv/0/abc1/0/0/NN/%/%/agrisim");
        let p = Entity::Publisher {
            topic: "/camera/depth",
            ros_type: "sensor_msgs/msg/Image",
            qos: Qos::writer(Kind::Sensor),
        };
        let t = token(3, "abc1", 4, p).unwrap();
        let h = type_hash("sensor_msgs/msg/Image").unwrap();
        assert_eq!(
            t,
            format!("@ros2_lv/3/abc1/0/4/MP/%/%/agrisim/%camera%depth/sensor_msgs::msg::dds_::Image_/{h}/2::,5:,:,:,,")
        );
        // 13 parts, none empty (rmw_zenoh rejects a token with an empty part).
        assert_eq!(t.split('/').count(), 13);
        assert!(t.split('/').all(|p| !p.is_empty()));
        assert_eq!(
            parse_token(3, &t),
            Some(("MP".into(), Some(("/camera/depth".into(), "sensor_msgs::msg::dds_::Image_".into()))))
        );
        assert_eq!(parse_token(0, &t), None);
        let s = Entity::Subscription { topic: "/cmd_vel", ros_type: "geometry_msgs/msg/Twist", qos: Qos::reader() };
        let t = token(0, "abc1", 5, s).unwrap();
        assert!(t.starts_with("@ros2_lv/0/abc1/0/5/MS/%/%/agrisim/%cmd_vel/geometry_msgs::msg::dds_::Twist_/RIHS01_"));
        assert_eq!(parse_token(0, "@ros2_lv/0/z/1/1/NN/%/%/talker"), Some(("NN".into(), None)));
        assert_eq!(parse_token(0, "@ros2_lv/0/z/1/2/MP/%/%/talker"), None);
        assert_ne!(gid(&t), gid("@ros2_lv/0/abc1/0/0/NN/%/%/agrisim"));
    }
}
