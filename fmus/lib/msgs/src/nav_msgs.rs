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

ros_message! {
    /// `nav_msgs/msg/MapMetaData`: resolution, size and origin (pose of cell (0,0)'s corner).
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct MapMetaData = "nav_msgs/msg/MapMetaData" {
        pub map_load_time: crate::builtin_interfaces::Time,
        pub resolution: f32,
        pub width: u32,
        pub height: u32,
        pub origin: crate::geometry_msgs::Pose,
    }
}

ros_message! {
    /// `nav_msgs/msg/OccupancyGrid`: row-major cells, 0 free .. 100 occupied, -1 unknown.
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct OccupancyGrid = "nav_msgs/msg/OccupancyGrid" {
        pub header: Header,
        pub info: MapMetaData,
        pub data: Vec<i8>,
    }
}
