//! MCAP recording in the ROS 2 profile: `ros2msg` schemas from models/msgs, `cdr` message
//! encoding, `offered_qos_profiles` channel metadata, log time = simulation time. Files made
//! this way open in Foxglove and decode with mcap-ros2-support and rosbags.
//!
//! Chunks are zstd-compressed, on a writer thread of the recorder's: the stepping thread
//! hands each kept message over (bytes shared with the bus are not copied) and goes on. The
//! file is written under a temporary name (`NAME.part`)
//! and renamed to its own name when finished: a file under its own name is always complete,
//! and a killed process leaves a `.part` whose chunks up to the last one written an MCAP
//! recovery reader salvages. The writer is finished on drop as well, so a run that stops on
//! an error still leaves a complete, readable file with everything recorded up to the failure.
//! A [`RecordPolicy`] says which messages are kept.

use crate::error::{Context, Result};
use crate::policy::{RecordPolicy, TopicFilter};
use crate::record_queue::{FailOnPanic, Queue, Weight};
use agrisim_msgs::Message;
use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::thread::JoinHandle;

/// QoS rosbag2 records for an ordinary reliable, volatile topic (history/depth unknown).
/// QoS rosbag2 records for a latched topic ([`crate::LATCHED_TOPICS`]): reliable, transient
/// local, keep last 1, so `ros2 bag play` offers the last message to late subscribers.
const QOS_LATCHED: &str = "- history: 1\n  depth: 1\n  reliability: 1\n  durability: 1\n  deadline:\n    sec: 2147483647\n    nsec: 4294967295\n  lifespan:\n    sec: 2147483647\n    nsec: 4294967295\n  liveliness: 1\n  liveliness_lease_duration:\n    sec: 2147483647\n    nsec: 4294967295\n  avoid_ros_namespace_conventions: false\n";
const QOS_VOLATILE: &str = "- history: 3\n  depth: 0\n  reliability: 1\n  durability: 2\n  deadline:\n    sec: 2147483647\n    nsec: 4294967295\n  lifespan:\n    sec: 2147483647\n    nsec: 4294967295\n  liveliness: 1\n  liveliness_lease_duration:\n    sec: 2147483647\n    nsec: 4294967295\n  avoid_ros_namespace_conventions: false\n";

/// Most bytes of messages waiting for the writer thread (about three 1280x720 RGB-D frames):
/// beyond it the stepping thread waits.
const QUEUE_BYTES: usize = 32 << 20;

/// A channel handle.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct Channel(u16);

/// A message's CDR bytes as handed to the recorder: shared with the bus (no copy) or owned.
#[derive(Clone, Debug)]
pub enum Payload {
    Shared(Arc<[u8]>),
    Owned(Vec<u8>),
}

impl Payload {
    fn as_slice(&self) -> &[u8] {
        match self {
            Payload::Shared(b) => b,
            Payload::Owned(b) => b,
        }
    }
}

impl From<Arc<[u8]>> for Payload {
    fn from(b: Arc<[u8]>) -> Payload {
        Payload::Shared(b)
    }
}

impl From<Vec<u8>> for Payload {
    fn from(b: Vec<u8>) -> Payload {
        Payload::Owned(b)
    }
}

impl From<&[u8]> for Payload {
    fn from(b: &[u8]) -> Payload {
        Payload::Owned(b.to_vec())
    }
}

/// One topic as the stepping thread knows it: its handle, type and filter.
struct Topic {
    channel: Channel,
    type_name: String,
    filter: TopicFilter,
}

/// Records ROS 2 messages to an MCAP file. The stepping thread only decides what is kept and
/// queues it; a writer thread of the recorder frames, compresses and writes, so the
/// stepping thread never waits for zstd or the disk unless the queue is full.
pub struct Recorder {
    writer: Option<WriterThread>,
    path: PathBuf,
    policy: RecordPolicy,
    topics: Vec<Topic>,
    by_name: BTreeMap<String, usize>,
}

/// How a recording is cut into compressed chunks. A chunk is written when complete, so a
/// killed run loses at most its last one and the messages queued for the writer thread (a
/// finished or interrupted run loses nothing).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Chunks {
    /// 1 MiB, compressed on the writer thread: what a stream of small messages (poses,
    /// clouds, joint states) wants; a killed run loses little.
    Small,
    /// 16 MiB (three 1280x720 camera frames), compressed by one zstd worker thread beside the
    /// writer thread. In 1 MiB chunks every camera image ended one. zstd's multithreaded
    /// output depends on the input and the worker count alone, never on timing (zstd issue
    /// 2327 and its determinism tests), so logs stay byte-identical run after run.
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
        let writer =
            options.create(BufWriter::new(file)).context(|| format!("cannot start MCAP file {}", path.display()))?;
        let writer = WriterThread::start(Sink {
            writer,
            path: path.display().to_string(),
            schemas: BTreeMap::new(),
            topics: vec![],
        })
        .context(|| format!("cannot start the writer thread of {}", path.display()))?;
        Ok(Recorder {
            writer: Some(writer),
            path: path.to_path_buf(),
            policy,
            topics: vec![],
            by_name: BTreeMap::new(),
        })
    }

    /// Queues `cmd` for the writer thread; an error the writer met since is reported here.
    fn send(&mut self, cmd: Cmd) -> Result<()> {
        let w =
            self.writer.as_ref().ok_or_else(|| crate::err!("{}: recording already finished", self.path.display()))?;
        w.queue.push(cmd).map_err(|e| crate::err!("{e}"))
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
        self.send(Cmd::Topic { name: topic.to_string(), type_name: type_name.to_string() })?;
        self.by_name.insert(topic.to_string(), self.topics.len());
        self.topics.push(Topic { channel, type_name: type_name.to_string(), filter });
        Ok(channel)
    }

    /// Records CDR bytes on a channel at simulation time `time_ns`, if the policy keeps them.
    /// Bytes shared with the bus ([`Payload::Shared`]) are not copied.
    pub fn write(&mut self, channel: Channel, time_ns: i64, cdr: impl Into<Payload>) -> Result<()> {
        let i = channel.0 as usize;
        if !self.topics[i].filter.keep(time_ns) {
            return Ok(());
        }
        self.send(Cmd::Message { topic: channel.0, time_ns, cdr: cdr.into() })
    }

    /// Records a message on `topic` (creating the channel if needed).
    pub fn publish<M: Message>(&mut self, topic: &str, time_ns: i64, msg: &M) -> Result<()> {
        let ch = self.channel(topic, M::TYPE_NAME)?;
        self.write(ch, time_ns, msg.to_cdr())
    }

    /// A metadata record (run settings: scenario, seed, parameters), sorted by key.
    pub fn metadata(&mut self, name: &str, entries: BTreeMap<String, String>) -> Result<()> {
        self.send(Cmd::Metadata(mcap::records::Metadata { name: name.to_string(), metadata: entries }))
    }

    /// Writes the summary and footer. Also done on drop; calling it reports errors.
    pub fn finish(mut self) -> Result<()> {
        self.finish_in_place()
    }

    /// [`Recorder::finish`] for a recorder owned by something else; later writes are errors.
    /// Waits for the writer thread to write what is queued. The file gets its own name once
    /// complete.
    pub fn finish_in_place(&mut self) -> Result<()> {
        let Some(w) = self.writer.take() else { return Ok(()) };
        let (failure, finished) = w.finish();
        if finished.is_ok() {
            let part = part_path(&self.path);
            std::fs::rename(&part, &self.path)
                .context(|| format!("renaming {} to {}", part.display(), self.path.display()))?;
        }
        match failure {
            Some(e) => Err(crate::err!("{e}")),
            None => finished.map_err(|e| crate::err!("{e}")),
        }
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

/// What the stepping thread asks of the writer thread, in order.
enum Cmd {
    /// A topic was named (its MCAP channel is added at its first message).
    Topic {
        name: String,
        type_name: String,
    },
    Message {
        topic: u16,
        time_ns: i64,
        cdr: Payload,
    },
    Metadata(mcap::records::Metadata),
}

impl Weight for Cmd {
    fn bytes(&self) -> usize {
        match self {
            Cmd::Message { cdr, .. } => cdr.as_slice().len(),
            _ => 0,
        }
    }
}

/// The writer thread and its queue.
struct WriterThread {
    queue: Arc<Queue<Cmd>>,
    thread: JoinHandle<std::result::Result<(), String>>,
}

impl WriterThread {
    fn start(mut sink: Sink) -> std::io::Result<WriterThread> {
        let queue = Arc::new(Queue::new(QUEUE_BYTES));
        let q = queue.clone();
        let thread = std::thread::Builder::new().name("mcap-writer".into()).spawn(move || {
            let _unblock = FailOnPanic::new(q.clone(), "the MCAP writer thread panicked");
            // After a failure the rest is dropped unwritten; the file is still finished (what
            // was written stays readable) and the failure reported.
            while let Some(cmd) = q.pop() {
                if q.failure().is_none() {
                    if let Err(e) = sink.apply(cmd) {
                        q.fail(e);
                    }
                }
            }
            sink.writer.finish().map(|_| ()).map_err(|e| format!("finishing {}: {}", sink.path, chain(&e)))
        })?;
        Ok(WriterThread { queue, thread })
    }

    /// Closes the queue and waits for the file to be finished: the first failure of the
    /// writing, and how finishing went.
    fn finish(self) -> (Option<String>, std::result::Result<(), String>) {
        self.queue.close();
        let finished = self.thread.join().unwrap_or_else(|_| Err("the MCAP writer thread panicked".into()));
        (self.queue.failure(), finished)
    }
}

/// An error with its causes ("I/O error ...: No space left on device"): the MCAP writer's
/// errors name the cause only as their source.
fn chain(e: &dyn std::error::Error) -> String {
    let mut s = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        s += &format!(": {c}");
        cause = c.source();
    }
    s
}

/// The writer thread's side: the MCAP writer and the channels added to it.
struct Sink {
    writer: mcap::Writer<BufWriter<File>>,
    path: String,
    schemas: BTreeMap<String, u16>,
    topics: Vec<SinkTopic>,
}

struct SinkTopic {
    name: String,
    type_name: String,
    mcap_id: Option<u16>,
    sequence: u32,
}

impl Sink {
    fn apply(&mut self, cmd: Cmd) -> std::result::Result<(), String> {
        match cmd {
            Cmd::Topic { name, type_name } => {
                self.topics.push(SinkTopic { name, type_name, mcap_id: None, sequence: 0 });
                Ok(())
            }
            Cmd::Message { topic, time_ns, cdr } => {
                let i = topic as usize;
                let id = self.mcap_channel(i)?;
                let t = &mut self.topics[i];
                t.sequence += 1;
                let header = mcap::records::MessageHeader {
                    channel_id: id,
                    sequence: t.sequence,
                    log_time: time_ns as u64,
                    publish_time: time_ns as u64,
                };
                self.writer
                    .write_to_known_channel(&header, cdr.as_slice())
                    .map_err(|e| format!("writing {}: {}", self.path, chain(&e)))
            }
            Cmd::Metadata(m) => self
                .writer
                .write_metadata(&m)
                .map_err(|e| format!("{}: MCAP metadata {}: {}", self.path, m.name, chain(&e))),
        }
    }

    /// The MCAP channel of topic `i`, added to the file now if it is not there yet.
    fn mcap_channel(&mut self, i: usize) -> std::result::Result<u16, String> {
        if let Some(id) = self.topics[i].mcap_id {
            return Ok(id);
        }
        let (topic, type_name) = (&self.topics[i].name, &self.topics[i].type_name);
        let schema_id = match self.schemas.get(type_name) {
            Some(id) => *id,
            None => {
                let text = agrisim_msgs::ros2msg_schema(type_name).expect("checked when the channel was made");
                let id = self
                    .writer
                    .add_schema(type_name, "ros2msg", text.as_bytes())
                    .map_err(|e| format!("{}: MCAP schema {type_name}: {}", self.path, chain(&e)))?;
                self.schemas.insert(type_name.clone(), id);
                id
            }
        };
        let qos = if crate::is_latched(topic) { QOS_LATCHED } else { QOS_VOLATILE };
        let metadata = BTreeMap::from([("offered_qos_profiles".to_string(), qos.to_string())]);
        let id = self
            .writer
            .add_channel(schema_id, topic, "cdr", &metadata)
            .map_err(|e| format!("{}: MCAP channel {topic}: {}", self.path, chain(&e)))?;
        self.topics[i].mcap_id = Some(id);
        Ok(id)
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
                Image {
                    height: 1,
                    width: n as u32,
                    encoding: "mono8".into(),
                    step: n as u32,
                    data,
                    ..Default::default()
                }
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

    /// A disk that fills up mid-run (the `.part` file is /dev/full): the writer thread's
    /// failure reaches a later write and the finish, naming the file, and nothing panics.
    #[cfg(target_os = "linux")]
    #[test]
    fn a_write_failure_on_the_writer_thread_is_reported() {
        let dir = std::env::temp_dir().join(format!("agrisim-recorder-full-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("run.mcap");
        std::os::unix::fs::symlink("/dev/full", part_path(&path)).unwrap();
        let mut r = Recorder::with_chunks(&path, RecordPolicy::default(), Chunks::Small).unwrap();
        let msgs = images(1, 4_000_000);
        let mut failed = None;
        for k in 0..100 {
            if let Err(e) = r.publish("/camera/image", k * 100_000_000, &msgs[0]) {
                failed = Some(e.to_string());
                break;
            }
        }
        let finished = r.finish().unwrap_err().to_string();
        std::fs::remove_dir_all(&dir).unwrap();
        let failed = failed.expect("a write after the failure reports it");
        for e in [&failed, &finished] {
            assert!(e.contains("run.mcap") && e.contains("No space left on device"), "{e}");
        }
        assert!(!path.exists(), "an unfinished file keeps its temporary name");
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
