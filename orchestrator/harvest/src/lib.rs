//! The dual-arm tomato harvest in the algorithm layer: a state machine node
//! ([`node::HarvestNode`]) over the manipulation stack (agrisim-manip: IK, collision
//! checking, RRT-Connect, shortcutting; agrisim-trajectory: TOPP-RA, ruckig, limit checks),
//! speaking only ROS 2 messages to the arm, gripper, lift and world FMUs.
//!
//! * [`geometry`]: where base, lift and grippers go (stand-off, grasp, handover, box);
//! * [`motion`]: goal -> IK goal set -> path -> time-parameterized, limit-checked
//!   trajectory_msgs/JointTrajectory;
//! * [`base`]: fine positioning of the holonomic base;
//! * [`stage`]: stages and failure categories; [`node`]: the state machine;
//! * [`row`]: the whole-row harvest, the node taken through a list of fruit;
//! * [`sight`]: harvest by sight: a region for a task, the perception node's fruit map, the
//!   mapping node's sensed scene.

pub mod base;
pub mod geometry;
pub mod motion;
pub mod node;
pub mod row;
pub mod sight;
pub mod stage;

pub use node::{topics, HarvestNode, Task};
pub use row::RowNode;
pub use stage::{Failure, Stage};
