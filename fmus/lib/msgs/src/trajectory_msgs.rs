//! `trajectory_msgs`: joint-space trajectories (the arm FMU's command input).

use crate::builtin_interfaces::Duration;
use crate::message::ros_message;
use crate::std_msgs::Header;

ros_message! {
    /// `trajectory_msgs/msg/JointTrajectoryPoint`: values ordered like the trajectory's
    /// `joint_names`; `velocities`, `accelerations` and `effort` may be empty.
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct JointTrajectoryPoint = "trajectory_msgs/msg/JointTrajectoryPoint" {
        pub positions: Vec<f64>,
        pub velocities: Vec<f64>,
        pub accelerations: Vec<f64>,
        pub effort: Vec<f64>,
        pub time_from_start: Duration,
    }
}

ros_message! {
    /// `trajectory_msgs/msg/JointTrajectory`: waypoints for named joints, timed from
    /// `header.stamp` (a zero stamp means "start on receipt", as in ros2_control).
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct JointTrajectory = "trajectory_msgs/msg/JointTrajectory" {
        pub header: Header,
        pub joint_names: Vec<String>,
        pub points: Vec<JointTrajectoryPoint>,
    }
}
