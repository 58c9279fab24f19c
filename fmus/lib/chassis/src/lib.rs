//! Chassis models of agrisim's mobile base: a 4-wheel-steering omnidirectional platform.
//!
//! Two interchangeable models with one variable table ([`ports`]): [`ChassisKinematic`]
//! (wheels follow their set-points, seeded slip) and [`ChassisDynamic`] (mass, inertia,
//! motor torque limits, tyre slip). Frames follow REP 103: x forward, y left, z up.

pub mod chassis;
pub mod command;
pub mod dynamic;
pub mod kinematic;
pub mod odometry;
pub mod ports;
pub mod se2;
pub mod wheels;

pub use agrisim_schedule::schedule;

pub use dynamic::ChassisDynamic;
pub use kinematic::ChassisKinematic;
