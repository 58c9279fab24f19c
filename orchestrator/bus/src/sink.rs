//! The MCAP writer on a thread of its own. The stepping thread hands over what to record and
//! goes on while the writer compresses and writes it: zstd on the stepping thread took about
//! a tenth of a camera run's wall time, with the other core idle. Records are written in the
//! order they are handed over, so the file is byte for byte what writing in place gives.
//! An error of the writer is returned by the next call, and by every call after it; the
//! writer still finishes the file, so everything written before the error stays readable.

use crate::error::{Context, Result};
use agrisim_error::Error;
use mcap::records::{MessageHeader, Metadata};
use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::sync::mpsc::{sync_channel, Receiver, SyncSender};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;

pub(crate) type Writer = mcap::Writer<BufWriter<File>>;

/// Records waiting for the writer at most; beyond, the stepping thread waits (a camera frame
/// is four messages of a few MB, so this bounds the queue to a few frames).
const QUEUE: usize = 16;

enum Cmd {
    Schema { name: String, encoding: &'static str, data: Vec<u8>, reply: SyncSender<Result<u16>> },
    Channel { schema: u16, topic: String, encoding: &'static str, metadata: BTreeMap<String, String>, reply: SyncSender<Result<u16>> },
    Message { header: MessageHeader, data: Vec<u8> },
    Metadata(Metadata),
}

pub(crate) struct Sink {
    tx: Option<SyncSender<Cmd>>,
    thread: Option<JoinHandle<Result<()>>>,
    /// The writer's first error.
    failed: Arc<Mutex<Option<Error>>>,
    /// The file, for messages.
    what: String,
}

impl Sink {
    /// Starts the writer thread for `writer` (the file `what`).
    pub(crate) fn start(writer: Writer, what: String) -> Result<Sink> {
        let (tx, rx) = sync_channel(QUEUE);
        let failed = Arc::new(Mutex::new(None));
        let (f, w) = (failed.clone(), what.clone());
        let thread = std::thread::Builder::new()
            .name("mcap-writer".into())
            .spawn(move || serve(writer, rx, f, w))
            .context(|| format!("{what}: cannot start the writer thread"))?;
        Ok(Sink { tx: Some(tx), thread: Some(thread), failed, what })
    }

    pub(crate) fn schema(&mut self, name: &str, encoding: &'static str, data: &[u8]) -> Result<u16> {
        let (reply, answer) = sync_channel(1);
        self.send(Cmd::Schema { name: name.to_string(), encoding, data: data.to_vec(), reply })?;
        self.wait(answer)
    }

    pub(crate) fn channel(&mut self, schema: u16, topic: &str, encoding: &'static str, metadata: BTreeMap<String, String>) -> Result<u16> {
        let (reply, answer) = sync_channel(1);
        self.send(Cmd::Channel { schema, topic: topic.to_string(), encoding, metadata, reply })?;
        self.wait(answer)
    }

    /// Queues a message (its bytes copied: the caller's buffer is free again at once).
    pub(crate) fn message(&mut self, header: MessageHeader, data: &[u8]) -> Result<()> {
        self.send(Cmd::Message { header, data: data.to_vec() })
    }

    pub(crate) fn metadata(&mut self, m: Metadata) -> Result<()> {
        self.send(Cmd::Metadata(m))
    }

    /// Writes what is queued, then the summary and footer; the writer's error if it had one.
    pub(crate) fn finish(mut self) -> Result<()> {
        self.stop()
    }

    fn stop(&mut self) -> Result<()> {
        drop(self.tx.take());
        match self.thread.take().map(JoinHandle::join) {
            None => Ok(()),
            Some(Ok(result)) => result,
            Some(Err(_)) => Err(agrisim_error::err!("{}: the writer thread panicked", self.what)),
        }
    }

    fn send(&mut self, cmd: Cmd) -> Result<()> {
        if let Some(e) = self.failed.lock().expect("writer error lock").clone() {
            return Err(e);
        }
        let tx = self.tx.as_ref().ok_or_else(|| agrisim_error::err!("{}: recording already finished", self.what))?;
        match tx.send(cmd) {
            Ok(()) => Ok(()),
            // The thread ended early: its result says why.
            Err(_) => Err(self.stop().err().unwrap_or_else(|| agrisim_error::err!("{}: the writer thread stopped", self.what))),
        }
    }

    fn wait(&mut self, answer: Receiver<Result<u16>>) -> Result<u16> {
        match answer.recv() {
            Ok(r) => r,
            Err(_) => Err(self.stop().err().unwrap_or_else(|| agrisim_error::err!("{}: the writer thread stopped", self.what))),
        }
    }
}

impl Drop for Sink {
    fn drop(&mut self) {
        let _ = self.stop();
    }
}

/// The writer thread: carries out the commands in order; after an error it answers every
/// later one with it. When the queue closes it finishes the file (also after an error, so
/// what was written stays readable).
fn serve(mut w: Writer, rx: Receiver<Cmd>, failed: Arc<Mutex<Option<Error>>>, what: String) -> Result<()> {
    let fail = |e: Error| {
        failed.lock().expect("writer error lock").get_or_insert(e).clone()
    };
    for cmd in rx {
        let broken = failed.lock().expect("writer error lock").clone();
        match cmd {
            Cmd::Schema { name, encoding, data, reply } => {
                let r = match broken {
                    Some(e) => Err(e),
                    None => w.add_schema(&name, encoding, &data).context(|| format!("{what}: MCAP schema {name}")).map_err(fail),
                };
                let _ = reply.send(r);
            }
            Cmd::Channel { schema, topic, encoding, metadata, reply } => {
                let r = match broken {
                    Some(e) => Err(e),
                    None => w.add_channel(schema, &topic, encoding, &metadata).context(|| format!("{what}: MCAP channel {topic}")).map_err(fail),
                };
                let _ = reply.send(r);
            }
            Cmd::Message { header, data } if broken.is_none() => {
                if let Err(e) = w.write_to_known_channel(&header, &data).context(|| format!("writing {what}")) {
                    fail(e);
                }
            }
            Cmd::Metadata(m) if broken.is_none() => {
                if let Err(e) = w.write_metadata(&m).context(|| format!("{what}: MCAP metadata {}", m.name)) {
                    fail(e);
                }
            }
            Cmd::Message { .. } | Cmd::Metadata(_) => {}
        }
    }
    let finished = w.finish().context(|| format!("finishing {what}"));
    match failed.lock().expect("writer error lock").clone() {
        Some(e) => Err(e),
        None => finished.map(drop),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::recorder::write_options;

    fn temp(name: &str) -> std::path::PathBuf {
        std::env::temp_dir().join(format!("agrisim-sink-{}-{name}", std::process::id()))
    }

    fn header(channel_id: u16, sequence: u32) -> MessageHeader {
        MessageHeader { channel_id, sequence, log_time: 1000 * sequence as u64, publish_time: 1000 * sequence as u64 }
    }

    /// Messages from a few bytes to past a chunk (1 MB), some compressible, some not.
    fn payload(i: u32) -> Vec<u8> {
        let n = [3usize, 700, 40_000, 1_300_000][i as usize % 4];
        let mut x = 0x9E37_79B9u32.wrapping_mul(i + 1);
        (0..n).map(|k| if k % 3 == 0 { (k / 97) as u8 } else { x ^= x << 13; x ^= x >> 17; x ^= x << 5; x as u8 }).collect()
    }

    #[test]
    fn the_thread_writes_what_writing_in_place_writes() {
        let (a, b) = (temp("thread.mcap"), temp("in-place.mcap"));
        let meta = BTreeMap::from([("k".to_string(), "v".to_string())]);
        let m = Metadata { name: "run".into(), metadata: meta.clone() };
        let mut sink = Sink::start(write_options().create(BufWriter::new(File::create(&a).unwrap())).unwrap(), "a".into()).unwrap();
        let s = sink.schema("std_msgs/msg/String", "ros2msg", b"string data").unwrap();
        let c = sink.channel(s, "/x", "cdr", meta.clone()).unwrap();
        sink.metadata(m.clone()).unwrap();
        for i in 1..=40 {
            sink.message(header(c, i), &payload(i)).unwrap();
        }
        sink.finish().unwrap();
        let mut w = write_options().create(BufWriter::new(File::create(&b).unwrap())).unwrap();
        let s = w.add_schema("std_msgs/msg/String", "ros2msg", b"string data").unwrap();
        let c = w.add_channel(s, "/x", "cdr", &meta).unwrap();
        w.write_metadata(&m).unwrap();
        for i in 1..=40 {
            w.write_to_known_channel(&header(c, i), &payload(i)).unwrap();
        }
        w.finish().unwrap();
        drop(w);
        let (x, y) = (std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
        let _ = (std::fs::remove_file(&a), std::fs::remove_file(&b));
        assert!(x.len() > 1_000_000 && x == y, "{} and {} bytes", x.len(), y.len());
    }

    /// A device that takes no bytes: the writer's error comes back to the caller, which is
    /// never left waiting.
    #[test]
    fn a_write_error_comes_back_to_the_caller_naming_the_file() {
        let Ok(full) = File::options().write(true).open("/dev/full") else { return };
        let mut sink = Sink::start(write_options().create(BufWriter::new(full)).unwrap(), "/dev/full".into()).unwrap();
        let s = sink.schema("std_msgs/msg/String", "ros2msg", b"string data");
        let first = s.and_then(|s| sink.channel(s, "/x", "cdr", BTreeMap::new())).and_then(|c| {
            (1..=20).try_for_each(|i| sink.message(header(c, i), &payload(3)))
        });
        let e = match first {
            Err(e) => e,
            Ok(()) => sink.finish().expect_err("wrote to /dev/full"),
        };
        assert!(e.0.starts_with("/dev/full: "), "{e}");
    }
}
