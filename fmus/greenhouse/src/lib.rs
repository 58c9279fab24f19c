//! The Greenhouse world FMU: the tomato greenhouse held in a rapier world, the robot moving
//! through it (base box plus the URDF links as kinematic bodies following base pose, lift,
//! arm joints and fingers: [`robot_model`], [`robot_links`]), harvest physics (grasp, carry,
//! handover, release, fall, place: [`harvest`]), and what the rest of agrisim needs to know
//! of it: robot contacts by category ([`contacts`], reported by [`collision_report`]), the
//! clearance the navigation benchmark scores ([`clearance`]), ground-truth fruit poses
//! ([`ground_truth`]) and the planning scene for the manipulation planner ([`planning_scene`]).
//!
//! The scene itself comes from `agrisim_scene` (same TOML + seed as every other consumer),
//! so collisions happen against exactly the geometry the LiDAR sees and the map is drawn from;
//! the robot from models/robot/agrisim_robot.urdf, compiled in.

pub mod base_box;
pub mod clearance;
pub mod collision_report;
pub mod contacts;
pub mod foliage;
pub mod geometry;
pub mod ground_truth;
pub mod harvest;
pub mod moved_objects;
pub mod pedicel;
pub mod planning_scene;
pub mod ports;
pub mod robot_links;
pub mod robot_model;
pub mod robot_parts;
pub mod scene_world;
pub mod stems;
pub mod world;

pub use world::GreenhouseWorld;

agrisim_fmi::export_fmu!(GreenhouseWorld);
