//! The algorithm layer's unit: like a ROS 2 node, it speaks only messages (and the system's
//! scalar inputs), so a real ROS 2 node or a Python script can take its place.

use crate::bus::Bus;
use crate::error::Result;

/// A node runs at every message exchange instant.
pub trait Node {
    fn name(&self) -> &str;
    /// Reads what it needs from the bus and publishes its outputs at time `t_ns`.
    fn step(&mut self, t_ns: i64, bus: &mut Bus) -> Result<()>;
}
