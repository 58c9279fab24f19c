//! The Greenhouse world FMU: the tomato greenhouse held in a rapier world, the robot base
//! moving through it as a kinematic body, and what the rest of agrisim needs to know of it:
//! robot-scene contacts ([`contacts`], reported by [`collision_report`]), the clearance the
//! navigation benchmark scores ([`clearance`]), and ground-truth fruit poses ([`ground_truth`]).
//!
//! The scene itself comes from `agrisim_greenhouse` (same TOML + seed as every other consumer),
//! so collisions happen against exactly the geometry the LiDAR sees and the map is drawn from.

pub mod base_box;
pub mod clearance;
pub mod collision_report;
pub mod contacts;
pub mod geometry;
pub mod ground_truth;
pub mod ports;
pub mod scene_world;
pub mod world;

pub use world::GreenhouseWorld;

agrisim_fmi::export_fmu!(GreenhouseWorld);
