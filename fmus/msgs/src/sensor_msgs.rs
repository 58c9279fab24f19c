//! `sensor_msgs`: joint states.

use crate::message::ros_message;
use crate::std_msgs::Header;

ros_message! {
    /// `sensor_msgs/msg/JointState`: parallel arrays indexed like `name`; any of
    /// position/velocity/effort may be empty.
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct JointState = "sensor_msgs/msg/JointState" {
        pub header: Header,
        pub name: Vec<String>,
        pub position: Vec<f64>,
        pub velocity: Vec<f64>,
        pub effort: Vec<f64>,
    }
}
