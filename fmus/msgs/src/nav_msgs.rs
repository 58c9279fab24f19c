//! `nav_msgs`: odometry and paths.

use crate::geometry_msgs::{PoseStamped, PoseWithCovariance, TwistWithCovariance};
use crate::message::ros_message;
use crate::std_msgs::Header;

ros_message! {
    /// `nav_msgs/msg/Odometry`: pose in `header.frame_id`, twist in `child_frame_id`.
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct Odometry = "nav_msgs/msg/Odometry" {
        pub header: Header,
        pub child_frame_id: String,
        pub pose: PoseWithCovariance,
        pub twist: TwistWithCovariance,
    }
}

ros_message! {
    /// `nav_msgs/msg/Path`.
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct Path = "nav_msgs/msg/Path" {
        pub header: Header,
        pub poses: Vec<PoseStamped>,
    }
}
