//! The algorithm layer's unit: like a ROS 2 node, it speaks only messages (and the system's
//! scalar inputs), so a real ROS 2 node or a Python script can take its place.

use crate::bus::Bus;
use crate::error::Result;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

/// A node runs at every message exchange instant.
pub trait Node {
    fn name(&self) -> &str;
    /// Reads what it needs from the bus and publishes its outputs at time `t_ns`.
    fn step(&mut self, t_ns: i64, bus: &mut Bus) -> Result<()>;
}

/// Simulated compute time a node charged so far \[s\] (its thinking, priced by a cost model of
/// its counted work, never a clock), readable by its owner after the node is boxed (a
/// benchmark's per-trial totals). Clones share the total.
#[derive(Clone, Debug, Default)]
pub struct Charged(Arc<AtomicU64>);

impl Charged {
    pub fn seconds(&self) -> f64 {
        f64::from_bits(self.0.load(Ordering::Relaxed))
    }
    /// Adds `s` seconds (the node's owner only reads).
    pub fn add(&self, s: f64) {
        self.0.store((self.seconds() + s).to_bits(), Ordering::Relaxed);
    }
}
