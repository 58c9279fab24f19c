//! `std_msgs`: the common stamped-data header, and Float64 for scalars on the bridge.

use crate::builtin_interfaces::Time;
use crate::message::ros_message;

ros_message! {
    /// `std_msgs/msg/Header`: timestamp and coordinate frame of stamped data.
    #[derive(Debug, Default, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
    pub struct Header = "std_msgs/msg/Header" {
        pub stamp: Time,
        pub frame_id: String,
    }
}

ros_message! {
    /// `std_msgs/msg/Float64`: one number (scalar connectors on the ROS 2 bridge).
    #[derive(Debug, Default, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
    pub struct Float64 = "std_msgs/msg/Float64" {
        pub data: f64,
    }
}

impl Header {
    pub fn new(stamp: Time, frame_id: impl Into<String>) -> Self {
        Self { stamp, frame_id: frame_id.into() }
    }
}
