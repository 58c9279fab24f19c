//! agrisim-bench: the evaluations. Many-trial benchmarks (navigation, dual-arm harvest, whole-row
//! harvest) with
//! honest statistics and every trial recorded, and the master's overhead.
//!
//! A judge reads only what was published on the bus (the messages every trial records) and
//! the world's ground-truth outputs through the engine; never a node's memory. So a node
//! written elsewhere (a ROS 2 node, a Python script) is judged by the same harness.

pub mod harvest;
pub mod harvest_targets;
pub mod initial_pose;
pub mod map;
pub mod nav;
pub mod overhead;
pub mod report;
pub mod row;
pub mod scenes;
pub mod stats;
pub mod targets;
pub mod task_publisher;
pub mod trials;

pub use overhead::{overhead, OverheadReport};
