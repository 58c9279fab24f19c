//! MCAP recording in the ROS 2 profile: `ros2msg` schemas from models/msgs, `cdr` message
//! encoding, `offered_qos_profiles` channel metadata, log time = simulation time. Files made
//! this way open in Foxglove and decode with mcap-ros2-support and rosbags.
//!
//! Chunks are zstd-compressed. The file is written under a temporary name (`NAME.part`)
//! and renamed to its own name when finished: a file under its own name is always complete,
//! and a killed process leaves a `.part` whose chunks up to the last one written an MCAP
//! recovery reader salvages. The writer is finished on drop as well, so a run that stops on
//! an error still leaves a complete, readable file with everything recorded up to the failure.
//! A [`RecordPolicy`] says which messages are kept.

use crate::error::{Context, Result};
use crate::policy::{RecordPolicy, TopicFilter};
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

/// One topic: its handle, type, filter and MCAP channel (created at its first kept message).
struct Topic {
    name: String,
    channel: Channel,
    type_name: String,
    filter: TopicFilter,
    mcap_id: Option<u16>,
    sequence: u32,
}

pub struct Recorder {
    writer: Option<mcap::Writer<BufWriter<File>>>,
    path: PathBuf,
    policy: RecordPolicy,
    schemas: BTreeMap<String, u16>,
    topics: Vec<Topic>,
    by_name: BTreeMap<String, usize>,
}

/// How a recording is cut into compressed chunks. A chunk is written when complete, so a
/// killed run loses at most its last one (a finished or interrupted run loses nothing).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Chunks {
    /// 1 MiB, compressed on the stepping thread: what a stream of small messages (poses,
    /// clouds, joint states) wants; a killed run loses little.
    Small,
    /// 16 MiB (three 1280x720 camera frames), compressed by one zstd worker thread beside the
    /// stepping thread, which hands each message over and waits only when a chunk ends. In
    /// 1 MiB chunks every camera image ended one, so the stepping thread waited for its
    /// compression all the same. zstd's multithreaded output depends on the input and the
    /// worker count alone, never on timing (zstd issue 2327 and its determinism tests), so
    /// logs stay byte-identical run after run.
    Large,
}

/// The temporary name a recording is written under until it is finished.
pub fn part_path(path: &Path) -> PathBuf {
    let mut name = path.file_name().unwrap_or_default().to_os_string();
    name.push(".part");
    path.with_file_name(name)
}

impl Recorder {
    /// Records everything to `path`.
    pub fn create(path: &Path) -> Result<Recorder> {
        Recorder::with_policy(path, RecordPolicy::default())
    }

    /// Records to `path` what `policy` keeps, in [`Chunks::Small`].
    pub fn with_policy(path: &Path, policy: RecordPolicy) -> Result<Recorder> {
        Recorder::with_chunks(path, policy, Chunks::Small)
    }

    /// Records to `path` what `policy` keeps, in `chunks`.
    pub fn with_chunks(path: &Path, policy: RecordPolicy, chunks: Chunks) -> Result<Recorder> {
        policy.validate().map_err(|e| crate::err!("{e}"))?;
        let part = part_path(path);
        let file = File::create(&part).context(|| format!("cannot create {}", part.display()))?;
        // zstd chunks at level 1: level 3, the default, took about a tenth of a camera run's
        // CPU time for files only a few per cent smaller (README, "Sensor rendering speed").
        let (bytes, workers) = match chunks {
            Chunks::Small => (1 << 20, 0),
            Chunks::Large => (16 << 20, 1),
        };
        let options = mcap::WriteOptions::new()
            .profile("ros2")
            .library("agrisim")
            .compression(Some(mcap::Compression::Zstd))
            .compression_level(1)
            .compression_threads(workers)
            .chunk_size(Some(bytes));
        let writer = options.create(BufWriter::new(file)).context(|| format!("cannot start MCAP file {}", path.display()))?;
        Ok(Recorder { writer: Some(writer), path: path.to_path_buf(), policy, schemas: BTreeMap::new(), topics: vec![], by_name: BTreeMap::new() })
    }

    fn writer(&mut self) -> Result<&mut mcap::Writer<BufWriter<File>>> {
        let path = self.path.display().to_string();
        self.writer.as_mut().ok_or_else(|| crate::err!("{path}: recording already finished"))
    }

    /// The channel for `topic` carrying `type_name` (e.g. `nav_msgs/msg/Odometry`), created
    /// on first use. A topic keeps one type: asking for another is an error.
    pub fn channel(&mut self, topic: &str, type_name: &str) -> Result<Channel> {
        if let Some(&i) = self.by_name.get(topic) {
            let t = &self.topics[i];
            if t.type_name != type_name {
                return Err(crate::err!("topic {topic} carries {}, cannot also record {type_name}", t.type_name));
            }
            return Ok(t.channel);
        }
        if agrisim_msgs::ros2msg_schema(type_name).is_none() {
            return Err(crate::err!("no .msg definition for {type_name} (topic {topic}) in models/msgs"));
        }
        let channel = Channel(self.topics.len() as u16);
        let filter = TopicFilter::new(self.policy.rule(topic, type_name));
        self.by_name.insert(topic.to_string(), self.topics.len());
        self.topics.push(Topic { name: topic.to_string(), channel, type_name: type_name.to_string(), filter, mcap_id: None, sequence: 0 });
        Ok(channel)
    }

    /// The MCAP channel of topic `i`, added to the file now if it is not there yet.
    fn mcap_channel(&mut self, i: usize) -> Result<u16> {
        if let Some(id) = self.topics[i].mcap_id {
            return Ok(id);
        }
        let (topic, type_name) = (self.topics[i].name.clone(), self.topics[i].type_name.clone());
        let schema_id = match self.schemas.get(&type_name) {
            Some(id) => *id,
            None => {
                let text = agrisim_msgs::ros2msg_schema(&type_name).expect("checked when the channel was made");
                let id = self.writer()?.add_schema(&type_name, "ros2msg", text.as_bytes()).context(|| format!("MCAP schema {type_name}"))?;
                self.schemas.insert(type_name.clone(), id);
                id
            }
        };
        let metadata = BTreeMap::from([("offered_qos_profiles".to_string(), QOS_VOLATILE.to_string())]);
        let id = self.writer()?.add_channel(schema_id, &topic, "cdr", &metadata).context(|| format!("MCAP channel {topic}"))?;
        self.topics[i].mcap_id = Some(id);
        Ok(id)
    }

    /// Records CDR bytes on a channel at simulation time `time_ns`, if the policy keeps them.
    pub fn write(&mut self, channel: Channel, time_ns: i64, cdr: &[u8]) -> Result<()> {
        let i = channel.0 as usize;
        if !self.topics[i].filter.keep(time_ns) {
            return Ok(());
        }
        let id = self.mcap_channel(i)?;
        let t = &mut self.topics[i];
        t.sequence += 1;
        let header = mcap::records::MessageHeader { channel_id: id, sequence: t.sequence, log_time: time_ns as u64, publish_time: time_ns as u64 };
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
    /// The file gets its own name once complete.
    pub fn finish_in_place(&mut self) -> Result<()> {
        if let Some(mut w) = self.writer.take() {
            w.finish().context(|| format!("finishing {}", self.path.display()))?;
            drop(w);
            let part = part_path(&self.path);
            std::fs::rename(&part, &self.path).context(|| format!("renaming {} to {}", part.display(), self.path.display()))?;
        }
        Ok(())
    }

    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for Recorder {
    /// A recorder dropped unfinished (a run that stopped on an error) still leaves a complete
    /// file under its own name.
    fn drop(&mut self) {
        let _ = self.finish_in_place();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use agrisim_msgs::sensor_msgs::Image;

    /// Images of `n` bytes with contents that compress a little (noise in the low bits).
    fn images(count: usize, n: usize) -> Vec<Image> {
        let mut rng = agrisim_math::Rng::new(0x9e37_79b9_7f4a_7c15);
        (0..count)
            .map(|k| {
                let data = (0..n).map(|i| ((i / 997 + k) as u8).wrapping_add((rng.next_u64() & 7) as u8)).collect();
                Image { height: 1, width: n as u32, encoding: "mono8".into(), step: n as u32, data, ..Default::default() }
            })
            .collect()
    }

    fn record(dir: &Path, name: &str, chunks: Chunks, msgs: &[Image]) -> Vec<u8> {
        let path = dir.join(name);
        let mut r = Recorder::with_chunks(&path, RecordPolicy::default(), chunks).unwrap();
        for (k, m) in msgs.iter().enumerate() {
            r.publish("/camera/image", k as i64 * 100_000_000, m).unwrap();
        }
        r.finish().unwrap();
        std::fs::read(&path).unwrap()
    }

    fn messages(file: &[u8]) -> Vec<(u64, Vec<u8>)> {
        mcap::MessageStream::new(file).unwrap().map(|m| m.unwrap()).map(|m| (m.log_time, m.data.into_owned())).collect()
    }

    /// Large chunks (a zstd worker thread) give the same file every time and the same
    /// messages as small ones; 40 MB of images span several chunks.
    #[test]
    fn large_chunks_are_deterministic_and_lose_nothing() {
        let dir = std::env::temp_dir().join(format!("agrisim-recorder-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let msgs = images(20, 2_000_000);
        let a = record(&dir, "a.mcap", Chunks::Large, &msgs);
        let b = record(&dir, "b.mcap", Chunks::Large, &msgs);
        let small = record(&dir, "c.mcap", Chunks::Small, &msgs);
        std::fs::remove_dir_all(&dir).unwrap();
        assert!(a == b, "two recordings of the same messages differ");
        let got = messages(&a);
        assert_eq!(got.len(), msgs.len());
        assert_eq!(got, messages(&small));
        for (k, (t, cdr)) in got.iter().enumerate() {
            assert_eq!((*t, Image::from_cdr(cdr).unwrap()), (k as u64 * 100_000_000, msgs[k].clone()));
        }
        let chunks = mcap::Summary::read(&a).unwrap().unwrap().chunk_indexes.len();
        assert!((2..=4).contains(&chunks), "{chunks} chunks of 16 MiB for 40 MB");
    }
}
