//! `sensor_msgs`: joint states, point clouds, IMU, images and camera calibration.

use crate::message::ros_message;
use crate::std_msgs::Header;

ros_message! {
    /// `sensor_msgs/msg/JointState`: parallel arrays indexed like `name`; any of
    /// position/velocity/effort may be empty.
    #[derive(Debug, Default, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
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

ros_message! {
    /// `sensor_msgs/msg/Image`: an uncompressed image, rows top to bottom, `step` bytes each;
    /// `encoding` names the pixel layout (`rgb8`, `32FC1`, `mono16`, `32SC1`, ...).
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct Image = "sensor_msgs/msg/Image" {
        pub header: Header,
        pub height: u32,
        pub width: u32,
        pub encoding: String,
        pub is_bigendian: u8,
        pub step: u32,
        pub data: Vec<u8>,
    }
}

ros_message! {
    /// `sensor_msgs/msg/RegionOfInterest`: a sub-window of an image (all 0 = the full image).
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct RegionOfInterest = "sensor_msgs/msg/RegionOfInterest" {
        pub x_offset: u32,
        pub y_offset: u32,
        pub height: u32,
        pub width: u32,
        pub do_rectify: bool,
    }
}

ros_message! {
    /// `sensor_msgs/msg/CameraInfo`: calibration of a camera; `k` (3x3), `r` (3x3) and `p`
    /// (3x4) are row-major.
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct CameraInfo = "sensor_msgs/msg/CameraInfo" {
        pub header: Header,
        pub height: u32,
        pub width: u32,
        pub distortion_model: String,
        pub d: Vec<f64>,
        pub k: [f64; 9],
        pub r: [f64; 9],
        pub p: [f64; 12],
        pub binning_x: u32,
        pub binning_y: u32,
        pub roi: RegionOfInterest,
    }
}

ros_message! {
    /// `sensor_msgs/msg/CompressedImage`: an encoded image (`format` "jpeg", "png", ...);
    /// here only as a part of `visualization_msgs/Marker` (its texture).
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct CompressedImage = "sensor_msgs/msg/CompressedImage" {
        pub header: Header,
        pub format: String,
        pub data: Vec<u8>,
    }
}

/// The pinhole model of a [`CameraInfo`]'s K, as the algorithm nodes read a camera: pixel
/// (u, v) has its centre at (u + 0.5, v + 0.5), as the camera FMU renders it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pinhole {
    pub fx: f64,
    pub fy: f64,
    pub cx: f64,
    pub cy: f64,
}

impl Pinhole {
    /// From a row-major K; `None` unless the focal lengths are positive and all are finite.
    pub fn from_k(k: &[f64; 9]) -> Option<Pinhole> {
        let p = Pinhole { fx: k[0], fy: k[4], cx: k[2], cy: k[5] };
        (p.fx > 0.0 && p.fy > 0.0 && [p.fx, p.fy, p.cx, p.cy].iter().all(|v| v.is_finite())).then_some(p)
    }

    pub fn from_camera_info(info: &CameraInfo) -> Option<Pinhole> {
        Pinhole::from_k(&info.k)
    }

    /// The point at pixel (u, v) (its centre) with depth z, in the optical frame.
    pub fn unproject(&self, u: usize, v: usize, z: f64) -> [f64; 3] {
        [(u as f64 + 0.5 - self.cx) / self.fx * z, (v as f64 + 0.5 - self.cy) / self.fy * z, z]
    }

    /// The image position of a point of the optical frame (z > 0).
    pub fn project(&self, p: [f64; 3]) -> [f64; 2] {
        [self.fx * p[0] / p[2] + self.cx, self.fy * p[1] / p[2] + self.cy]
    }
}
