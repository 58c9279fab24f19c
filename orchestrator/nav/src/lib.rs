//! The navigation stack, Nav2-shaped and speaking only ROS 2 messages, so real Nav2 nodes
//! can replace it piece by piece.
//!
//! Two nodes, which by default run as one (the navigator steps an embedded localizer first):
//! * [`Localizer`] ([`localization`]): `/odom` + `/imu` + `/points` + `/map` ->
//!   `/tf` (map -> odom) and `/localization/pose`.
//! * [`Navigator`] ([`navigator`]): `/goal_pose` + `/localization/pose` + `/points` + `/map`
//!   -> `/cmd_vel`, `/plan`, `/navigate/status`.
//!
//! With `embedded_localizer = false` they are separate nodes (run the localizer first, so the
//! navigator sees this instant's pose); the messages on the bus are the same either way.
//!
//! Two seams, as in Nav2: a [`GlobalPlanner`] ([`astar`] by default, [`straight_line`] for
//! open ground) and a [`Controller`] ([`dwa`]), chosen by name in [`plugins`].
//!
//! Inside, one concept per file: [`map`] (the OccupancyGrid), [`distance`] (exact distance
//! transform), [`costmap`] (global costmap, inflation), [`local_costmap`] (rolling window from
//! the LiDAR), [`footprint`], [`global_planner`] and [`controller`] (the seams),
//! [`tracking`] (progress along the plan), [`turn_spot`] (where to turn beside an obstacle),
//! [`scan_match`] + [`lidar_odometry`] + [`localization`], [`executor`] (the goal's state
//! machine), [`config`] (all parameters), [`topics`] and [`cloud`] (PointCloud2 codec).
//! Deterministic: no clocks, no hash maps, no threads.

pub mod astar;
pub mod cloud;
pub mod config;
pub mod controller;
pub mod costmap;
pub mod distance;
pub mod dwa;
pub mod executor;
pub mod footprint;
pub mod global_planner;
pub mod lidar_odometry;
pub mod local_costmap;
pub mod localization;
pub mod map;
pub mod navigator;
pub mod plugins;
pub mod scan_match;
pub mod straight_line;
pub mod topics;
pub mod tracking;
pub mod turn_spot;

pub use config::NavConfig;
/// The name the benchmark harness uses for [`NavConfig`].
pub type NavigatorConfig = NavConfig;
pub use agrisim_math::pose2::{self, Pose2};
pub use controller::Controller;
pub use executor::{ExecutorStats, Goal, State};
pub use global_planner::{GlobalPlanner, PlanError};
pub use localization::Localizer;
pub use navigator::Navigator;
pub use plugins::{ControllerKind, PlannerKind, Plugins};
