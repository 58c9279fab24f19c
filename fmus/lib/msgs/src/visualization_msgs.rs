//! `visualization_msgs` (ROS 2 Humble and later): markers, the shapes RViz and Foxglove draw.
//! agrisim publishes the greenhouse as one [`MarkerArray`] of instanced list markers
//! (`/scene/markers`, a viewer topic: see docs/formats.md).

use crate::builtin_interfaces::Duration;
use crate::geometry_msgs::{Point, Pose, Vector3};
use crate::message::ros_message;
use crate::sensor_msgs::CompressedImage;
use crate::std_msgs::{ColorRGBA, Header};

ros_message! {
    /// `visualization_msgs/msg/UVCoordinate`: a texture coordinate.
    #[derive(Debug, Default, Clone, Copy, PartialEq)]
    pub struct UVCoordinate = "visualization_msgs/msg/UVCoordinate" {
        pub u: f32,
        pub v: f32,
    }
}

ros_message! {
    /// `visualization_msgs/msg/MeshFile`: a mesh file's name and bytes.
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct MeshFile = "visualization_msgs/msg/MeshFile" {
        pub filename: String,
        pub data: Vec<u8>,
    }
}

ros_message! {
    /// `visualization_msgs/msg/Marker`: one shape, or one list of shapes of a kind
    /// (`*_LIST`, `POINTS`, `LINE_*`: `points` with optional per-point `colors`).
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct Marker = "visualization_msgs/msg/Marker" {
        pub header: Header,
        pub ns: String,
        pub id: i32,
        pub r#type: i32,
        pub action: i32,
        pub pose: Pose,
        pub scale: Vector3,
        pub color: ColorRGBA,
        pub lifetime: Duration,
        pub frame_locked: bool,
        pub points: Vec<Point>,
        pub colors: Vec<ColorRGBA>,
        pub texture_resource: String,
        pub texture: CompressedImage,
        pub uv_coordinates: Vec<UVCoordinate>,
        pub text: String,
        pub mesh_resource: String,
        pub mesh_file: MeshFile,
        pub mesh_use_embedded_materials: bool,
    }
}

impl Marker {
    pub const ARROW: i32 = 0;
    pub const CUBE: i32 = 1;
    pub const SPHERE: i32 = 2;
    pub const CYLINDER: i32 = 3;
    pub const LINE_STRIP: i32 = 4;
    pub const LINE_LIST: i32 = 5;
    pub const CUBE_LIST: i32 = 6;
    pub const SPHERE_LIST: i32 = 7;
    pub const POINTS: i32 = 8;
    pub const TEXT_VIEW_FACING: i32 = 9;
    pub const MESH_RESOURCE: i32 = 10;
    pub const TRIANGLE_LIST: i32 = 11;

    pub const ADD: i32 = 0;
    pub const MODIFY: i32 = 0;
    pub const DELETE: i32 = 2;
    pub const DELETEALL: i32 = 3;
}

ros_message! {
    /// `visualization_msgs/msg/MarkerArray`: several markers at once.
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct MarkerArray = "visualization_msgs/msg/MarkerArray" {
        pub markers: Vec<Marker>,
    }
}
