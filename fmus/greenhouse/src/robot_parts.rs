//! What the world keeps of each robot collider ([`RobotPart`], with its [`Group`]) and of each
//! URDF link's kinematic body ([`LinkBody`]): held by the scene world, built by
//! [`robot_links`](crate::robot_links), read by contact reports.

use crate::robot_model::Side;
use rapier3d::prelude::*;

/// Which rigid group a robot collider belongs to: arm-arm contacts are left vs right links.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Group {
    /// Chassis, enclosure, harvest box, mast, lift, sensors.
    Body,
    Arm(Side),
}

/// One robot collider as contact reports see it.
#[derive(Clone, Debug, PartialEq)]
pub struct RobotPart {
    pub collider: ColliderHandle,
    /// URDF link name (`base_link` for the base box).
    pub link: String,
    pub group: Group,
    /// Whether touching the floor counts (not for the base box: its bottom is the ride height).
    pub floor_counts: bool,
}

/// A link's kinematic body and the map-frame pose it was last put at.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LinkBody {
    /// Index into [`RobotModel::link_names`](crate::robot_model::RobotModel::link_names).
    pub link: usize,
    pub body: RigidBodyHandle,
    pub pose: Pose,
}
