//! `std_msgs`: the common stamped-data header, Float64 for scalars on the bridge, String
//! (the robot description) and ColorRGBA (markers).

use crate::builtin_interfaces::Time;
use crate::message::ros_message;

ros_message! {
    /// `std_msgs/msg/Header`: timestamp and coordinate frame of stamped data.
    #[derive(Debug, Default, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
    pub struct Header = "std_msgs/msg/Header" {
        pub stamp: Time,
        pub frame_id: std::string::String,
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
    pub fn new(stamp: Time, frame_id: impl Into<std::string::String>) -> Self {
        Self { stamp, frame_id: frame_id.into() }
    }
}

ros_message! {
    /// `std_msgs/msg/String`: one string (`/robot_description` carries the URDF in it).
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct String = "std_msgs/msg/String" {
        pub data: std::string::String,
    }
}

ros_message! {
    /// `std_msgs/msg/ColorRGBA`: a colour, channels in \[0, 1\] (`a` = 1 opaque).
    #[derive(Debug, Default, Clone, Copy, PartialEq)]
    pub struct ColorRGBA = "std_msgs/msg/ColorRGBA" {
        pub r: f32,
        pub g: f32,
        pub b: f32,
        pub a: f32,
    }
}

impl ColorRGBA {
    pub const fn new(r: f32, g: f32, b: f32, a: f32) -> Self {
        Self { r, g, b, a }
    }
}
