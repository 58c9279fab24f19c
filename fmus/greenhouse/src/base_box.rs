//! The robot base as one box: what the world knows of the robot until the arm links arrive.
//! base_link sits on the floor under the box centre (REP 105), so the box spans the height
//! band [clearance, clearance + height] that navigation must keep free.

use crate::geometry::planar_pose;
use crate::ports::*;
use agrisim_fmi::Store;
use rapier3d::prelude::{Pose, SharedShape};

#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BaseBox {
    pub length: f64,
    pub width: f64,
    pub height: f64,
    /// Gap between the floor and the box bottom.
    pub clearance: f64,
}

impl BaseBox {
    pub fn from_params(io: &Store) -> Result<BaseBox, String> {
        let get = |i: usize, min: f64| {
            let v = io.f64(i);
            if v.is_finite() && v >= min && v <= 1e3 {
                Ok(v)
            } else {
                Err(format!("parameter {} must be finite and in [{min}, 1000], got {v}", VARIABLES[i].name))
            }
        };
        Ok(BaseBox {
            length: get(BASE_LENGTH, 1e-3)?,
            width: get(BASE_WIDTH, 1e-3)?,
            height: get(BASE_HEIGHT, 1e-3)?,
            clearance: get(BASE_CLEARANCE, 0.0)?,
        })
    }

    pub fn shape(&self) -> SharedShape {
        SharedShape::cuboid((self.length / 2.0) as f32, (self.width / 2.0) as f32, (self.height / 2.0) as f32)
    }

    /// Pose of the box centre for base_link at (x, y, yaw) in the map frame.
    pub fn pose(&self, x: f64, y: f64, yaw: f64) -> Pose {
        planar_pose(x, y, yaw, self.clearance + self.height / 2.0)
    }

    /// Vertical extent of the box [m]: the navigation height band.
    pub fn band(&self) -> [f64; 2] {
        [self.clearance, self.clearance + self.height]
    }
}

impl Default for BaseBox {
    fn default() -> Self {
        BaseBox { length: 1.2, width: 0.9, height: 0.6, clearance: 0.05 }
    }
}
