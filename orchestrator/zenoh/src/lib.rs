//! agrisim-zenoh: the live ROS 2 link over Zenoh, in the wire format of rmw_zenoh (ROS 2
//! Jazzy, Kilted; `RMW_IMPLEMENTATION=rmw_zenoh_cpp`), beside the DDS bridge (agrisim-ros2).
//! It carries the same topics the same way (raw CDR: the bytes on the bus are the bytes on
//! the wire and in the MCAP), with the same lockstep and real-time modes and the same checks
//! of what peers send (agrisim-link).
//!
//! * [`wire`]: key expressions with type hashes, attachments, liveliness tokens;
//! * [`bridge`]: the Zenoh session and the bridge node.

pub mod bridge;
pub mod wire;

pub use agrisim_link::{Mode, Remap, Stats};
pub use bridge::{ZenohBridge, ZenohConfig, DEFAULT_LISTEN};
