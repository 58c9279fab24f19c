//! The message side of the system: ROS 2 topics as seen by the algorithm layer.
//!
//! FMU message outputs wired to the system's output connectors arrive here; nodes read them,
//! publish their own messages (routed by the master to the FMU inputs wired to the system's
//! input connectors) and set scalar system inputs. Everything published is also recorded.
//! Topics live in a BTreeMap: iteration order is by name, never by hash.

use crate::error::Result;
use agrisim_msgs::Message;
use std::collections::{BTreeMap, VecDeque};
use std::sync::Arc;

/// The latest message on a topic.
#[derive(Clone, Debug, PartialEq)]
pub struct Sample {
    pub type_name: String,
    /// Counts messages on this topic (1 for the first).
    pub seq: u64,
    /// Simulation time of publication \[ns\].
    pub time_ns: i64,
    /// Shared by the topic's latest sample, its readers' queue and the outbox: a camera
    /// image is copied once onto the bus, not once per holder.
    pub cdr: Arc<[u8]>,
}

/// A message published in the current exchange, not yet routed and recorded.
#[derive(Clone, Debug, PartialEq)]
pub struct Published {
    pub topic: String,
    pub type_name: String,
    pub time_ns: i64,
    pub cdr: Arc<[u8]>,
}

#[derive(Default, Debug, Clone)]
pub struct Bus {
    latest: BTreeMap<String, Sample>,
    scalars: BTreeMap<String, f64>,
    outbox: Vec<Published>,
    /// Topics with [`Reader`]s: the messages some reader has not taken yet.
    queues: BTreeMap<String, Queue>,
    /// Messages a reader could not decode (skipped, not fatal), for the run's status log.
    rejected: Vec<String>,
    /// Ground truth is sealed: nodes may not read it ([`crate::ground_truth`]).
    sealed: bool,
    /// The node whose step is running (None: the judge, a bridge, the engine).
    reader: Option<String>,
    /// Ground-truth reads by a node under the seal, since the last check.
    breaches: std::cell::RefCell<Vec<String>>,
}

/// Messages of one topic kept for its readers, and where each reader is.
#[derive(Default, Debug, Clone)]
struct Queue {
    samples: VecDeque<Sample>,
    /// Per reader (index = reader id): the last sequence number it took.
    cursors: Vec<u64>,
}

/// A reader that sees every message on a topic, in order (a localizer integrating every IMU
/// sample, a judge counting every contact), unlike [`Bus::take_new`] which sees the newest.
/// It joins the topic at its first [`Reader::take`]: from then on, the newest message
/// then present and everything after.
#[derive(Clone, Debug)]
pub struct Reader {
    topic: String,
    id: Option<usize>,
}

impl Reader {
    pub fn new(topic: &str) -> Reader {
        Reader { topic: topic.to_string(), id: None }
    }

    /// A reader that joins `topic` now: it will take every message published from now on
    /// (a judge that must see all of them).
    pub fn subscribe(bus: &mut Bus, topic: &str) -> Reader {
        let mut r = Reader::new(topic);
        r.join(bus, false);
        r
    }

    pub fn topic(&self) -> &str {
        &self.topic
    }

    fn join(&mut self, bus: &mut Bus, with_latest: bool) -> usize {
        if let Some(id) = self.id {
            return id;
        }
        let latest = bus.latest.get(&self.topic);
        let q = bus.queues.entry(self.topic.clone()).or_default();
        let seq = latest.map_or(0, |s| s.seq);
        q.cursors.push(if with_latest { seq.saturating_sub(1) } else { seq });
        if let Some(s) = latest.filter(|_| with_latest) {
            if q.samples.back().is_none_or(|b| b.seq < s.seq) {
                q.samples.push_back(s.clone());
            }
        }
        self.id = Some(q.cursors.len() - 1);
        q.cursors.len() - 1
    }

    /// Every message since the last call, oldest first, as published.
    pub fn take_samples(&mut self, bus: &mut Bus) -> Vec<Sample> {
        if bus.refused(&self.topic) {
            return vec![];
        }
        let id = self.join(bus, true);
        let q = bus.queues.get_mut(&self.topic).expect("joined");
        let from = q.cursors[id];
        let out: Vec<Sample> = q.samples.iter().filter(|s| s.seq > from).cloned().collect();
        if let Some(s) = out.last() {
            q.cursors[id] = s.seq;
        }
        let done = q.cursors.iter().copied().min().unwrap_or(u64::MAX);
        while q.samples.front().is_some_and(|s| s.seq <= done) {
            q.samples.pop_front();
        }
        out
    }

    /// Every message since the last call, oldest first, decoded; one that does not decode
    /// is skipped and reported ([`Bus::take_rejected`]), never fatal.
    pub fn take<M: Message>(&mut self, bus: &mut Bus) -> Result<Vec<M>> {
        let samples = self.take_samples(bus);
        let mut out = Vec::with_capacity(samples.len());
        for s in samples {
            if let Some(m) = bus.decode::<M>(&self.topic, &s) {
                out.push(m);
            }
        }
        Ok(out)
    }
}

/// Readers of every topic on the bus (joined as topics appear): what a bridge forwards.
#[derive(Clone, Debug, Default)]
pub struct Tap {
    readers: BTreeMap<String, Reader>,
}

impl Tap {
    /// Every message since the last call on every topic `keep` accepts, topic by topic in
    /// name order, oldest first: (topic, type, sample).
    pub fn take(&mut self, bus: &mut Bus, keep: impl Fn(&str) -> bool) -> Vec<(String, String, Sample)> {
        let topics: Vec<(String, String)> =
            bus.topics().filter(|(t, _)| keep(t)).map(|(t, ty)| (t.to_string(), ty.to_string())).collect();
        let mut out = vec![];
        for (topic, ty) in topics {
            let samples = self.readers.entry(topic.clone()).or_insert_with(|| Reader::new(&topic)).take_samples(bus);
            out.extend(samples.into_iter().map(|s| (topic.clone(), ty.clone(), s)));
        }
        out
    }
}

impl Bus {
    /// Publishes CDR bytes on `topic`.
    pub fn publish_raw(&mut self, topic: &str, type_name: &str, time_ns: i64, cdr: impl Into<Arc<[u8]>>) {
        let cdr = cdr.into();
        let seq = self.latest.get(topic).map_or(1, |s| s.seq + 1);
        let sample = Sample { type_name: type_name.to_string(), seq, time_ns, cdr: cdr.clone() };
        if let Some(q) = self.queues.get_mut(topic) {
            q.samples.push_back(sample.clone());
        }
        self.latest.insert(topic.to_string(), sample);
        self.outbox.push(Published { topic: topic.to_string(), type_name: type_name.to_string(), time_ns, cdr });
    }

    pub fn publish<M: Message>(&mut self, topic: &str, time_ns: i64, msg: &M) {
        self.publish_raw(topic, M::TYPE_NAME, time_ns, msg.to_cdr());
    }

    pub fn latest(&self, topic: &str) -> Option<&Sample> {
        if self.refused(topic) {
            return None;
        }
        self.latest.get(topic)
    }

    /// From now on, nodes cannot read ground truth ([`crate::ground_truth`]): a read during a
    /// node's step gets nothing and is a breach ([`Bus::take_breaches`]). Judges and bridges,
    /// reading outside node steps, still can.
    pub fn seal_ground_truth(&mut self) {
        self.sealed = true;
    }

    pub fn is_sealed(&self) -> bool {
        self.sealed
    }

    /// The node whose step runs now (`None` when it returns).
    pub fn set_reader(&mut self, node: Option<&str>) {
        self.reader = node.map(str::to_string);
    }

    /// Ground-truth reads the seal refused since the last call: "node N read T".
    pub fn take_breaches(&mut self) -> Vec<String> {
        std::mem::take(&mut *self.breaches.borrow_mut())
    }

    /// Whether a read of `topic` now is refused by the seal (and noted as a breach).
    fn refused(&self, topic: &str) -> bool {
        let Some(node) = self.reader.as_deref().filter(|_| self.sealed && crate::ground_truth::is_ground_truth(topic))
        else {
            return false;
        };
        self.breaches.borrow_mut().push(format!("node {node} read the ground-truth topic {topic}"));
        true
    }

    /// The latest message on `topic` if it is newer than `seen` (updated), decoded; one
    /// that does not decode is skipped and reported ([`Bus::take_rejected`]).
    pub fn take_new<M: Message>(&mut self, topic: &str, seen: &mut u64) -> Result<Option<M>> {
        if self.refused(topic) {
            return Ok(None);
        }
        match self.latest.get(topic) {
            Some(s) if s.seq > *seen => {
                *seen = s.seq;
                let s = s.clone();
                Ok(self.decode(topic, &s))
            }
            _ => Ok(None),
        }
    }

    fn decode<M: Message>(&mut self, topic: &str, s: &Sample) -> Option<M> {
        match M::from_cdr(&s.cdr) {
            Ok(m) => Some(m),
            Err(e) => {
                self.rejected.push(format!(
                    "topic {topic}: message {} ({} bytes, published at t={} s) is not a valid {}: {e}; skipped",
                    s.seq,
                    s.cdr.len(),
                    s.time_ns as f64 / 1e9,
                    M::TYPE_NAME
                ));
                None
            }
        }
    }

    /// Every topic with a message so far and its type, by name.
    pub fn topics(&self) -> impl Iterator<Item = (&str, &str)> {
        self.latest.iter().map(|(t, s)| (t.as_str(), s.type_name.as_str()))
    }

    /// Reports a message refused before it reached the bus (a bridge's inbound check); it
    /// goes to the run's status log with the readers' skips.
    pub fn reject(&mut self, reason: String) {
        self.rejected.push(reason);
    }

    /// Reports of messages readers skipped since the last call.
    pub fn take_rejected(&mut self) -> Vec<String> {
        std::mem::take(&mut self.rejected)
    }

    pub fn set_scalar(&mut self, name: &str, value: f64) {
        match self.scalars.get_mut(name) {
            Some(v) => *v = value,
            None => {
                self.scalars.insert(name.to_string(), value);
            }
        }
    }

    pub fn scalar(&self, name: &str) -> Option<f64> {
        self.scalars.get(name).copied()
    }

    /// All scalar system inputs, by name.
    pub fn scalars(&self) -> &BTreeMap<String, f64> {
        &self.scalars
    }

    /// Messages published since the last drain, in publication order.
    pub fn drain(&mut self) -> Vec<Published> {
        std::mem::take(&mut self.outbox)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sealed_bus_refuses_ground_truth_to_nodes_only() {
        use agrisim_msgs::geometry_msgs::PoseArray;
        let mut bus = Bus::default();
        bus.publish("/fruits", 1, &PoseArray::default());
        bus.publish("/points_like", 1, &PoseArray::default());
        bus.seal_ground_truth();
        // A node's step: the ground truth is not there, and the read is a breach.
        bus.set_reader(Some("harvest"));
        let mut seen = 0;
        assert_eq!(bus.take_new::<PoseArray>("/fruits", &mut seen).unwrap(), None);
        assert!(bus.latest("/camera/labels").is_none());
        let mut r = Reader::new("/fmu/world/signals");
        assert!(r.take_samples(&mut bus).is_empty());
        let mut other = 0;
        assert!(bus.take_new::<PoseArray>("/points_like", &mut other).unwrap().is_some());
        bus.set_reader(None);
        assert_eq!(
            bus.take_breaches(),
            [
                "node harvest read the ground-truth topic /fruits",
                "node harvest read the ground-truth topic /camera/labels",
                "node harvest read the ground-truth topic /fmu/world/signals"
            ]
        );
        // The judge, outside node steps, reads it.
        assert!(bus.take_new::<PoseArray>("/fruits", &mut seen).unwrap().is_some());
        assert!(bus.take_breaches().is_empty());
    }

    #[test]
    fn tap_takes_every_new_message_of_every_kept_topic_once() {
        let mut bus = Bus::default();
        let mut tap = Tap::default();
        bus.publish_raw("/b", "x/msg/B", 1, vec![1]);
        bus.publish_raw("/a", "x/msg/A", 1, vec![2]);
        bus.publish_raw("/a", "x/msg/A", 2, vec![3]);
        let got: Vec<(String, Vec<u8>)> =
            tap.take(&mut bus, |t| t != "/c").into_iter().map(|(t, _, s)| (t, s.cdr.to_vec())).collect();
        // A topic is joined at its newest message, then followed in full.
        assert_eq!(got, [("/a".to_string(), vec![3]), ("/b".to_string(), vec![1])]);
        bus.publish_raw("/a", "x/msg/A", 3, vec![4]);
        bus.publish_raw("/a", "x/msg/A", 4, vec![5]);
        bus.publish_raw("/c", "x/msg/C", 4, vec![6]);
        let got: Vec<Vec<u8>> = tap.take(&mut bus, |t| t != "/c").into_iter().map(|(_, _, s)| s.cdr.to_vec()).collect();
        assert_eq!(got, [vec![4], vec![5]]);
        assert!(tap.take(&mut bus, |t| t != "/c").is_empty());
    }
}
