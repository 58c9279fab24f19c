//! Arm FMU (`Arm`): one Panda-like 7-DoF arm with its parallel gripper; instantiated twice
//! (parameter `side` = left / right selects the URDF joints).
//!
//! - [`description`]: joint names, limits and inertials of one side from the compiled-in URDF;
//! - [`validate`]: acceptance rules for trajectory_msgs/JointTrajectory (rejected whole, with
//!   a reason, never partially applied);
//! - [`reference`]: joint_trajectory_controller-style interpolation (linear / cubic / quintic);
//! - [`inertia`]: configuration-dependent effective joint inertias (mass-matrix diagonal)
//!   plus reflected rotor inertia;
//! - [`dynamics`]: PD + feedforward control at 1 kHz on a decoupled, gravity-compensated rigid
//!   joint model with torque saturation and friction, and a mismatched controller model, so
//!   tracking error is realistic rather than zero;
//! - [`gripper`]: Franka-Hand-like gap control that stalls on an object;
//! - [`arm`]: the FMI model; [`ports`]: its variable table.
//!
//! Simplifications: joints are decoupled (no inertial coupling, Coriolis or centrifugal
//! torques), gravity is compensated exactly, the lift and base motion do not disturb the arm,
//! a held fruit's mass is not added, and torque-rate limits are not modelled.

// Joint-indexed loops over several parallel arrays read better with an index.
#![allow(clippy::needless_range_loop)]

pub mod arm;
pub mod description;
pub mod dynamics;
pub mod gripper;
pub mod inertia;
pub mod load;
pub mod ports;
pub mod reference;
pub mod validate;

pub use arm::Arm;

agrisim_fmi::export_fmu!(crate::Arm);
