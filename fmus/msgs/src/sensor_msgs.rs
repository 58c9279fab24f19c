//! `sensor_msgs`: joint states, point clouds, IMU.

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

ros_message! {
    /// `sensor_msgs/msg/PointField`: one field of a PointCloud2 point.
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct PointField = "sensor_msgs/msg/PointField" {
        pub name: String,
        pub offset: u32,
        pub datatype: u8,
        pub count: u32,
    }
}

impl PointField {
    pub const INT8: u8 = 1;
    pub const UINT8: u8 = 2;
    pub const INT16: u8 = 3;
    pub const UINT16: u8 = 4;
    pub const INT32: u8 = 5;
    pub const UINT32: u8 = 6;
    pub const FLOAT32: u8 = 7;
    pub const FLOAT64: u8 = 8;
}

ros_message! {
    /// `sensor_msgs/msg/PointCloud2`: points as a binary blob described by `fields`.
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct PointCloud2 = "sensor_msgs/msg/PointCloud2" {
        pub header: Header,
        pub height: u32,
        pub width: u32,
        pub fields: Vec<PointField>,
        pub is_bigendian: bool,
        pub point_step: u32,
        pub row_step: u32,
        pub data: Vec<u8>,
        pub is_dense: bool,
    }
}

ros_message! {
    /// `sensor_msgs/msg/Imu`: orientation, angular velocity and specific force; a covariance
    /// whose element 0 is -1 marks an estimate as absent.
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct Imu = "sensor_msgs/msg/Imu" {
        pub header: Header,
        pub orientation: crate::geometry_msgs::Quaternion,
        pub orientation_covariance: [f64; 9],
        pub angular_velocity: crate::geometry_msgs::Vector3,
        pub angular_velocity_covariance: [f64; 9],
        pub linear_acceleration: crate::geometry_msgs::Vector3,
        pub linear_acceleration_covariance: [f64; 9],
    }
}
