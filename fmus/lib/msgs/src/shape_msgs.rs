//! `shape_msgs`: primitive collision shapes.

use crate::geometry_msgs::Polygon;
use crate::message::ros_message;

ros_message! {
    /// `shape_msgs/msg/SolidPrimitive` as in ROS 2 Humble and Jazzy (common_interfaces
    /// 4.x+): `dimensions` is the bounded sequence `float64[<=3]` (same wire format as an
    /// unbounded one; ROS peers reject more than 3 values, so keep it at most 3) and a
    /// `polygon` follows, used only by `PRISM`. Shapes are centred at the origin; cylinder
    /// and cone axes are +Z.
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct SolidPrimitive = "shape_msgs/msg/SolidPrimitive" {
        pub r#type: u8,
        pub dimensions: Vec<f64>,
        pub polygon: Polygon,
    }
}

impl SolidPrimitive {
    pub const BOX: u8 = 1;
    pub const SPHERE: u8 = 2;
    pub const CYLINDER: u8 = 3;
    pub const CONE: u8 = 4;
    pub const PRISM: u8 = 5;
    pub const BOX_X: usize = 0;
    pub const BOX_Y: usize = 1;
    pub const BOX_Z: usize = 2;
    pub const SPHERE_RADIUS: usize = 0;
    pub const CYLINDER_HEIGHT: usize = 0;
    pub const CYLINDER_RADIUS: usize = 1;
    pub const CONE_HEIGHT: usize = 0;
    pub const CONE_RADIUS: usize = 1;
    pub const PRISM_HEIGHT: usize = 0;
    /// Upper bound of `dimensions` (`float64[<=3]`).
    pub const MAX_DIMENSIONS: usize = 3;

    /// A box with full side lengths `x`, `y`, `z`.
    pub fn new_box(x: f64, y: f64, z: f64) -> Self {
        Self { r#type: Self::BOX, dimensions: vec![x, y, z], ..Default::default() }
    }

    pub fn sphere(radius: f64) -> Self {
        Self { r#type: Self::SPHERE, dimensions: vec![radius], ..Default::default() }
    }

    /// A cylinder along +Z, `height` in total.
    pub fn cylinder(height: f64, radius: f64) -> Self {
        Self { r#type: Self::CYLINDER, dimensions: vec![height, radius], ..Default::default() }
    }
}
