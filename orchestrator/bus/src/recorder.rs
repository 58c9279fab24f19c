//! MCAP recording in the ROS 2 profile: `ros2msg` schemas from models/msgs, `cdr` message
//! encoding, `offered_qos_profiles` channel metadata, log time = simulation time. Files made
//! this way open in Foxglove and decode with mcap-ros2-support and rosbags.
//!
//! Chunks are zstd-compressed. The writer is finished on drop as well, so a run that stops on an error still leaves a
//! complete, readable file with everything recorded up to the failure.

use crate::error::{Context, Result};
use agrisim_msgs::Message;
use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// QoS rosbag2 records for an ordinary reliable, volatile topic (history/depth unknown).
const QOS_VOLATILE: &str = "- history: 3\n  depth: 0\n  reliability: 1\n  durability: 2\n  deadline:\n    sec: 2147483647\n    nsec: 4294967295\n  lifespan:\n    sec: 2147483647\n    nsec: 4294967295\n  liveliness: 1\n  liveliness_lease_duration:\n    sec: 2147483647\n    nsec: 4294967295\n  avoid_ros_namespace_conventions: false\n";

/// A channel handle.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct Channel(u16);

pub struct Recorder {
    writer: Option<mcap::Writer<BufWriter<File>>>,
    path: PathBuf,
    schemas: BTreeMap<String, u16>,
    channels: BTreeMap<String, (Channel, String)>,
    sequence: BTreeMap<Channel, u32>,
}

impl Recorder {
    pub fn create(path: &Path) -> Result<Recorder> {
        let file = File::create(path).context(|| format!("cannot create {}", path.display()))?;
        // zstd chunks, single-threaded: point clouds make trials large, and one compression thread
        // keeps the output a pure function of the input (byte-identical logs).
        let options = mcap::WriteOptions::new()
            .profile("ros2")
            .library("agrisim")
            .compression(Some(mcap::Compression::Zstd))
            .compression_threads(0);
        let writer = options.create(BufWriter::new(file)).context(|| format!("cannot start MCAP file {}", path.display()))?;
        Ok(Recorder { writer: Some(writer), path: path.to_path_buf(), schemas: BTreeMap::new(), channels: BTreeMap::new(), sequence: BTreeMap::new() })
    }

    fn writer(&mut self) -> Result<&mut mcap::Writer<BufWriter<File>>> {
        let path = self.path.display().to_string();
        self.writer.as_mut().ok_or_else(|| crate::err!("{path}: recording already finished"))
    }

    /// The channel for `topic` carrying `type_name` (e.g. `nav_msgs/msg/Odometry`), created
    /// on first use. A topic keeps one type: asking for another is an error.
    pub fn channel(&mut self, topic: &str, type_name: &str) -> Result<Channel> {
        if let Some((ch, ty)) = self.channels.get(topic) {
            if ty != type_name {
                return Err(crate::err!("topic {topic} carries {ty}, cannot also record {type_name}"));
            }
            return Ok(*ch);
        }
        let schema_id = match self.schemas.get(type_name) {
            Some(id) => *id,
            None => {
                let text = agrisim_msgs::ros2msg_schema(type_name).ok_or_else(|| crate::err!("no .msg definition for {type_name} (topic {topic}) in models/msgs"))?;
                let id = self.writer()?.add_schema(type_name, "ros2msg", text.as_bytes()).context(|| format!("MCAP schema {type_name}"))?;
                self.schemas.insert(type_name.to_string(), id);
                id
            }
        };
        let metadata = BTreeMap::from([("offered_qos_profiles".to_string(), QOS_VOLATILE.to_string())]);
        let id = self.writer()?.add_channel(schema_id, topic, "cdr", &metadata).context(|| format!("MCAP channel {topic}"))?;
        let ch = Channel(id);
        self.channels.insert(topic.to_string(), (ch, type_name.to_string()));
        Ok(ch)
    }

    /// Records CDR bytes on a channel at simulation time `time_ns`.
    pub fn write(&mut self, channel: Channel, time_ns: i64, cdr: &[u8]) -> Result<()> {
        let seq = self.sequence.entry(channel).or_insert(0);
        *seq += 1;
        let header = mcap::records::MessageHeader { channel_id: channel.0, sequence: *seq, log_time: time_ns as u64, publish_time: time_ns as u64 };
        let path = self.path.display().to_string();
        self.writer()?.write_to_known_channel(&header, cdr).context(|| format!("writing {path}"))
    }

    /// Records a message on `topic` (creating the channel if needed).
    pub fn publish<M: Message>(&mut self, topic: &str, time_ns: i64, msg: &M) -> Result<()> {
        let ch = self.channel(topic, M::TYPE_NAME)?;
        self.write(ch, time_ns, &msg.to_cdr())
    }

    /// A metadata record (run settings: scenario, seed, parameters), sorted by key.
    pub fn metadata(&mut self, name: &str, entries: BTreeMap<String, String>) -> Result<()> {
        let m = mcap::records::Metadata { name: name.to_string(), metadata: entries };
        self.writer()?.write_metadata(&m).context(|| format!("MCAP metadata {name}"))
    }

    /// Writes the summary and footer. Also done on drop; calling it reports errors.
    pub fn finish(mut self) -> Result<()> {
        self.finish_in_place()
    }

    /// [`Recorder::finish`] for a recorder owned by something else; later writes are errors.
    pub fn finish_in_place(&mut self) -> Result<()> {
        if let Some(mut w) = self.writer.take() {
            w.finish().context(|| format!("finishing {}", self.path.display()))?;
        }
        Ok(())
    }

    pub fn path(&self) -> &Path {
        &self.path
    }
}
