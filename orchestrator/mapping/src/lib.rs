//! agrisim-mapping: a collision scene from sensed depth, as MoveIt's occupancy map monitor
//! builds one. An algorithm crate: it reads depth images, CameraInfo and TF (messages only)
//! and links no engine, scene generation or world crate.
//!
//! - [`map::OccupancyMap`]: log-odds voxels (1 cm by default) in sorted 16^3 chunks, updated
//!   per depth frame with OctoMap's sensor model: ray clearing by 3-D DDA ([`ray`]), max range,
//!   clamping; the robot's own links filtered out (points on them clear but never occupy).
//! - Queries for the arm planner: does a point, sphere or capsule touch occupied space grown by
//!   the padding, allowed objects (the fruit to grasp) left out.
//! - Export: the occupied voxels merged into boxes, as an `agrisim_msgs/PlanningScene` the
//!   harvest planner reads like the ground-truth `/planning_scene`.
//! - [`node::DepthMapper`]: the node that does this on the bus, for one or more cameras, its
//!   self-filter from `/robot_description` and TF ([`robot`]), its allowed objects from
//!   `/harvest/allowed`.
//!
//! The voxel walk and the update follow OctoMap's arithmetic, so a scan gives the same voxel
//! states (bit-identical log-odds) as OctoMap's `insertPointCloud` at the same resolution and
//! max range: `python/bench_mapping.py` times both on camera frames and compares them
//! (`agrisim-mapping-bench` is its agrisim side).
//!
//! Unknown space counts as free (MoveIt's default); the allowed objects and the robot links
//! come from messages (the URDF, TF from the joint states, the fruit the harvest node
//! grasps), never world outputs.

pub mod cost;
pub mod depth;
pub mod map;
pub mod node;
pub mod ray;
pub mod robot;
pub mod shape;

pub use agrisim_bus::Charged;
pub use cost::{CostModel, MapWork};
pub use depth::{DepthFrame, Intrinsics};
pub use map::{MapConfig, Occupancy, OccupancyMap, ScanStats, VoxelBox, OCCUPIED_KIND};
pub use node::{CameraTopics, DepthMapper, MapperConfig};
pub use ray::{Grid, Key};
pub use robot::RobotShapes;
pub use shape::{Primitive, Shape, Sphere};
