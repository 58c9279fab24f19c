//! ROS 2 message types and their CDR encoding, with no dependency but serde and the
//! workspace's math crate.
//!
//! Why this crate exists: FMUs exchange ROS 2 messages as CDR bytes in FMI 3 Binary ports,
//! and the orchestrator records them to MCAP with `ros2msg` schemas (DESIGN.md §3-4). Both
//! must produce exactly what ROS 2 tools (rosbag2, Foxglove, mcap-ros2-support, rosbags)
//! read, without pulling a ROS installation or a serde stack into every FMU.
//!
//! * [`cdr`]: [`CdrWriter`] / [`CdrReader`] (XCDR1, CDR_LE header; reader never panics).
//! * [`message`]: the [`Message`] trait (`to_cdr` / `from_cdr`) and FMI mimeTypes.
//! * one module per ROS package with plain structs ([`geometry_msgs::Twist`], ...).
//! * [`dynamic`]: any known type by name at run time ([`dynamic::Value`] trees), for bindings and bridges.
//! * [`planar`]: `geometry_msgs/Pose` to and from the planar pose of `agrisim_math`.
//! * [`schema`]: the .msg texts from models/msgs and [`ros2msg_schema`] for MCAP.
//!
//! ```
//! use agrisim_msgs::geometry_msgs::{Twist, Vector3};
//! use agrisim_msgs::Message;
//!
//! let cmd = Twist { linear: Vector3 { x: 0.5, y: 0.0, z: 0.0 }, ..Default::default() };
//! let bytes = cmd.to_cdr(); // 4-byte CDR_LE header + 6 x f64
//! assert_eq!(bytes.len(), 52);
//! assert_eq!(Twist::from_cdr(&bytes).unwrap(), cmd);
//! assert_eq!(Twist::MIME_TYPE, "application/x-ros2-cdr-frames; version=1; type=geometry_msgs/msg/Twist");
//! let schema = agrisim_msgs::ros2msg_schema(Twist::TYPE_NAME).unwrap();
//! assert!(schema.contains("MSG: geometry_msgs/Vector3"));
//! ```

pub mod cdr;
mod check;
pub mod dynamic;
pub mod message;
pub mod planar;
pub mod schema;
pub mod type_hash;

pub mod agrisim;
pub mod builtin_interfaces;
pub mod control_msgs;
pub mod geometry_msgs;
pub mod nav_msgs;
pub mod rosgraph_msgs;
pub mod sensor_msgs;
pub mod shape_msgs;
pub mod std_msgs;
pub mod tf2_msgs;
pub mod trajectory_msgs;
pub mod vision_msgs;
pub mod visualization_msgs;

pub use cdr::{CdrError, CdrField, CdrReader, CdrWriter, CDR_LE_HEADER};
pub use check::check_cdr;
pub use message::{mime_type, mime_type_for, type_name_from_mime, Message, MIME_PREFIX};
pub use schema::{all_type_names, msg_text, ros2msg_schema};
pub use type_hash::{type_hash, type_hashes, TypeHashError};
