//! Time parameterization of joint-space paths for agrisim's 7-DoF harvest arms.
//!
//! Pipeline used by the harvest state machine ([`time_waypoints`] does it in one call):
//! planner waypoints → path ([`BlendedPolylinePath`] or [`CubicSplinePath`]) → TOPP-RA
//! ([`toppra::parameterize_within_limits`]) → [`sample`] at the send period → [`limits::check`]
//! → `trajectory_msgs/JointTrajectory`. State-to-state moves with jerk limits (approach,
//! retreat) use [`jerk_limited::plan`] ([`time_state_to_state`]). Every result implements
//! [`Trajectory`], so sampling and checking are the same for both.

pub mod blended;
pub mod grid;
pub mod jerk_limited;
pub mod limits;
mod lp2d;
pub mod panda;
pub mod path;
pub mod pipeline;
pub mod sampled;
pub mod spline;
pub mod toppra;

pub use blended::BlendedPolylinePath;
pub use grid::GridSpec;
pub use jerk_limited::{JerkLimitedMotion, JointState, KinematicLimits};
pub use limits::{check, CheckError, JointLimits, LimitViolation, Quantity};
pub use path::{JointPath, PathError};
pub use pipeline::{time_path, time_state_to_state, time_waypoints, PathShape, PlanError, TimingConfig};
pub use sampled::{sample, Sampled, Trajectory};
pub use spline::{CubicSplinePath, PathParam, SplineEnd};
pub use toppra::{
    parameterize, parameterize_within_limits, Discretization, ToppraError, ToppraProblem, ToppraTrajectory,
};
