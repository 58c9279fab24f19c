//! `control_msgs`: gripper command (the message inside the ROS 2 `GripperCommand` action
//! goal, here sent on its own as a port value).

use crate::message::ros_message;

ros_message! {
    /// `control_msgs/msg/GripperCommand`: target `position` (for agrisim's parallel
    /// grippers: the finger gap in m) and the force limit `max_effort` in N.
    #[derive(Debug, Default, Clone, Copy, PartialEq)]
    pub struct GripperCommand = "control_msgs/msg/GripperCommand" {
        pub position: f64,
        pub max_effort: f64,
    }
}
