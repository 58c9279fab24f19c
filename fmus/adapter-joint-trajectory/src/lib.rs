//! JointTrajectoryToScalars: an adapter FMU that lets an arm model with plain Real
//! position set-point inputs stand where agrisim's Arm FMU takes `trajectory` messages.
//! Input: the message port `trajectory` (trajectory_msgs/msg/JointTrajectory, the Arm's MIME
//! type) with `trajectory_seq`; outputs: the set-points `q1`..`q7` sampled at the end of each
//! step, `status` and `count`. Parameter `joints` maps the message's joint names to outputs
//! (the k-th name drives qk); `q1_init`..`q7_init` hold before any trajectory.
//!
//! The output names are not message fields (a JointTrajectory carries arrays indexed by
//! joint name), so no table is generated from a .msg file here.
//!
//! - [`ports`]: the variable table; [`joints`]: the name mapping; [`reference`]: the
//!   interpolation; [`adapter`]: the model.

pub mod adapter;
pub mod joints;
pub mod ports;
pub mod reference;

pub use adapter::JointTrajectoryToScalars;

agrisim_fmi::export_fmu!(crate::JointTrajectoryToScalars);
