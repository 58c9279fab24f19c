//! agrisim-ros2: the live ROS 2 link. A DDS bridge carries what the message bus carries to
//! ROS 2 peers (rmw_cyclonedds, rmw_fastrtps: Humble, Jazzy) and their commands back, so an
//! external navigation, perception or manipulation node replaces a built-in one and the
//! benchmark harness still judges the run.
//!
//! Messages cross as raw CDR: the bytes on the bus are the bytes on the wire (no decode and
//! re-encode), so what a peer receives equals what the MCAP records. Inbound messages are
//! checked against their topic's type before they reach the bus; a bad one is rejected,
//! counted and reported, and the run goes on.
//!
//! * [`names`]: ROS 2 topic and type names on DDS (`rt/...`, `pkg::msg::dds_::Type_`), remapping;
//! * [`qos`]: the QoS ROS 2 users expect per topic;
//! * [`raw`]: the raw-CDR sample type and its RustDDS adapters;
//! * [`bridge`]: the bridge node (lockstep or real time) and its statistics;
//! * [`graph`]: the bridge as a node of the ROS 2 graph (`ros_discovery_info`);
//! * [`confine`]: the bridge's sockets kept to traffic from this machine;
//! * [`announce`]: its announcements repeated to this machine's LAN addresses.

pub mod announce;
pub mod bridge;
pub mod confine;
pub mod graph;
pub mod names;
pub mod qos;
pub mod raw;

pub use agrisim_link::Topics;
pub use bridge::{BridgeConfig, Mode, Ros2Bridge, Stats};
pub use graph::Distro;

/// Tests that open sockets hold this: the confinement test counts the sockets that appear
/// in the process while it runs.
#[cfg(test)]
pub(crate) static SOCKET_TESTS: std::sync::Mutex<()> = std::sync::Mutex::new(());
