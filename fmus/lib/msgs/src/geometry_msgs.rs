//! `geometry_msgs`: points, poses, velocities and transforms.

use crate::message::ros_message;
use crate::std_msgs::Header;

ros_message! {
    /// `geometry_msgs/msg/Vector3`: a free vector (only rotated by transforms).
    #[derive(Debug, Default, Clone, Copy, PartialEq)]
    pub struct Vector3 = "geometry_msgs/msg/Vector3" {
        pub x: f64,
        pub y: f64,
        pub z: f64,
    }
}

ros_message! {
    /// `geometry_msgs/msg/Point`: a position.
    #[derive(Debug, Default, Clone, Copy, PartialEq)]
    pub struct Point = "geometry_msgs/msg/Point" {
        pub x: f64,
        pub y: f64,
        pub z: f64,
    }
}

ros_message! {
    /// `geometry_msgs/msg/Quaternion`. `Default` is the identity (w = 1), as in the
    /// .msg default values, so a default pose is a valid pose.
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub struct Quaternion = "geometry_msgs/msg/Quaternion" {
        pub x: f64,
        pub y: f64,
        pub z: f64,
        pub w: f64,
    }
}

impl Default for Quaternion {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Quaternion {
    pub const IDENTITY: Self = Self { x: 0.0, y: 0.0, z: 0.0, w: 1.0 };

    /// Rotation of `yaw` radians about +z (the common planar-robot case).
    pub fn from_yaw(yaw: f64) -> Self {
        let (s, c) = (0.5 * yaw).sin_cos();
        Self { x: 0.0, y: 0.0, z: s, w: c }
    }

    /// Yaw (rotation about +z) of this rotation, ZYX convention.
    pub fn yaw(&self) -> f64 {
        (2.0 * (self.w * self.z + self.x * self.y)).atan2(1.0 - 2.0 * (self.y * self.y + self.z * self.z))
    }
}

ros_message! {
    /// `geometry_msgs/msg/Pose`.
    #[derive(Debug, Default, Clone, Copy, PartialEq)]
    pub struct Pose = "geometry_msgs/msg/Pose" {
        pub position: Point,
        pub orientation: Quaternion,
    }
}

ros_message! {
    /// `geometry_msgs/msg/PoseStamped`.
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct PoseStamped = "geometry_msgs/msg/PoseStamped" {
        pub header: Header,
        pub pose: Pose,
    }
}

ros_message! {
    /// `geometry_msgs/msg/PoseWithCovariance`: row-major 6x6 covariance over
    /// (x, y, z, rot X, rot Y, rot Z).
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub struct PoseWithCovariance = "geometry_msgs/msg/PoseWithCovariance" {
        pub pose: Pose,
        pub covariance: [f64; 36],
    }
}

impl Default for PoseWithCovariance {
    fn default() -> Self {
        Self { pose: Pose::default(), covariance: [0.0; 36] }
    }
}

ros_message! {
    /// `geometry_msgs/msg/Twist`: linear (m/s) and angular (rad/s) velocity.
    #[derive(Debug, Default, Clone, Copy, PartialEq)]
    pub struct Twist = "geometry_msgs/msg/Twist" {
        pub linear: Vector3,
        pub angular: Vector3,
    }
}

ros_message! {
    /// `geometry_msgs/msg/TwistStamped`.
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct TwistStamped = "geometry_msgs/msg/TwistStamped" {
        pub header: Header,
        pub twist: Twist,
    }
}

ros_message! {
    /// `geometry_msgs/msg/TwistWithCovariance`: row-major 6x6 covariance.
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub struct TwistWithCovariance = "geometry_msgs/msg/TwistWithCovariance" {
        pub twist: Twist,
        pub covariance: [f64; 36],
    }
}

impl Default for TwistWithCovariance {
    fn default() -> Self {
        Self { twist: Twist::default(), covariance: [0.0; 36] }
    }
}

ros_message! {
    /// `geometry_msgs/msg/Transform`.
    #[derive(Debug, Default, Clone, Copy, PartialEq)]
    pub struct Transform = "geometry_msgs/msg/Transform" {
        pub translation: Vector3,
        pub rotation: Quaternion,
    }
}

ros_message! {
    /// `geometry_msgs/msg/TransformStamped`: pose of `child_frame_id` in `header.frame_id`.
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct TransformStamped = "geometry_msgs/msg/TransformStamped" {
        pub header: Header,
        pub child_frame_id: String,
        pub transform: Transform,
    }
}

ros_message! {
    /// `geometry_msgs/msg/PoseArray`: poses in one frame (e.g. ground-truth fruit poses).
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct PoseArray = "geometry_msgs/msg/PoseArray" {
        pub header: Header,
        pub poses: Vec<Pose>,
    }
}

ros_message! {
    /// `geometry_msgs/msg/Point32`: a position in single precision (polygon vertices).
    #[derive(Debug, Default, Clone, Copy, PartialEq)]
    pub struct Point32 = "geometry_msgs/msg/Point32" {
        pub x: f32,
        pub y: f32,
        pub z: f32,
    }
}

ros_message! {
    /// `geometry_msgs/msg/Polygon`: vertices, the last connected to the first. Needed as
    /// the `polygon` field of `shape_msgs/SolidPrimitive`.
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct Polygon = "geometry_msgs/msg/Polygon" {
        pub points: Vec<Point32>,
    }
}
