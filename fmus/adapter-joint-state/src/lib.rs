//! JointStateFromScalars: an adapter FMU that lets an arm model with plain Real joint
//! outputs stand where agrisim's Arm FMU publishes `joint_states`. Inputs `q1`..`q7` (and
//! `qd1`..`qd7`, reported when `with_velocity`); output the message port `joint_states`
//! (sensor_msgs/msg/JointState, the Arm's MIME type) at `rate` on simulation time, under the
//! names of parameter `joints`.
//!
//! The input names are not message fields (JointState carries arrays indexed by name), so
//! no table is generated from a .msg file here.
//!
//! - [`ports`]: the variable table; [`joints`]: the names; [`adapter`]: the model.

pub mod adapter;
pub mod joints;
pub mod ports;

pub use adapter::JointStateFromScalars;

agrisim_fmi::export_fmu!(crate::JointStateFromScalars);
