//! The robot's own fixed structure (chassis, enclosure, harvest crate, sensor post, lidar,
//! lift mast, carriage, camera) as obstacles of an arm. Read from the URDF so a change of
//! the robot changes the planner; parts on the lift move with it.

use crate::iso::to_iso;
use crate::prim::Prim;
use agrisim_robot::{Collider, Robot};
use nalgebra::{Isometry3, Translation3, Vector3};
use std::collections::BTreeMap;

/// Links of the fixed body (everything except the arms, fingers and wheels; the wheels sit
/// below the chassis box, where no arm can reach).
pub const BODY_LINKS: [&str; 8] = [
    "base_link",
    "rear_enclosure_link",
    "harvest_box_link",
    "sensor_post_link",
    "lidar_link",
    "lift_mast_link",
    "lift_link",
    "camera_link",
];

/// One collision primitive of the fixed body.
#[derive(Debug, Clone)]
pub struct BodyPart {
    /// `link[index]`, e.g. `harvest_box_link[2]`.
    pub name: String,
    pub link: String,
    pub collider: Collider,
    /// Primitive pose in the planning frame at lift 0.
    pose0: Isometry3<f64>,
    /// Displacement per metre of lift (zero for parts not on the lift).
    per_lift: Vector3<f64>,
}

impl BodyPart {
    /// The part as a primitive at lift height `lift`.
    pub fn prim(&self, lift: f64) -> Prim {
        Prim::new(self.collider.shape, self.pose(lift))
    }
    pub fn pose(&self, lift: f64) -> Isometry3<f64> {
        Translation3::from(self.per_lift * lift) * self.pose0
    }
}

/// All fixed-body primitives, in [`BODY_LINKS`] order.
pub fn body_parts(robot: &Robot) -> Result<Vec<BodyPart>, String> {
    let at = |lift: f64| robot.fk(&BTreeMap::from([("lift_joint".to_string(), lift)]));
    let (f0, f1) = (at(0.0)?, at(1.0)?);
    let mut out = Vec::new();
    for l in BODY_LINKS {
        let cols = robot.colliders(l).ok_or_else(|| format!("robot has no link {l}"))?;
        let (p0, p1) = (to_iso(&f0[l]), to_iso(&f1[l]));
        for (i, c) in cols.iter().enumerate() {
            out.push(BodyPart {
                name: format!("{l}[{i}]"),
                link: l.to_string(),
                collider: *c,
                pose0: p0 * to_iso(&c.origin),
                per_lift: p1.translation.vector - p0.translation.vector,
            });
        }
    }
    Ok(out)
}
