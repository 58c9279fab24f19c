//! The robot's URDF links as kinematic rapier bodies: one body per link carrying that link's
//! collision primitives, placed each step from base pose + forward kinematics.
//!
//! The base box of [`crate::base_box`] stays the robot's chassis (navigation's height band and
//! the contacts reported on `base_link`), so base_link's own box and the wheel and steering
//! links are left out: they lie inside or below it, and wheels touch the floor by design.

use crate::robot_model::{chassis_link, RobotModel, Side};
use crate::robot_parts::{Group, LinkBody, RobotPart};
use crate::scene_world::SceneWorld;
use agrisim_robot::{Pose as RPose, Shape};
use rapier3d::prelude::*;

/// `user_data` of link colliders: this plus the part index (scene objects carry their index,
/// far below; the base box carries [`crate::scene_world::ROBOT_TAG`]).
pub const PART_TAG: u128 = 1 << 64;

pub fn group_of(name: &str) -> Group {
    if name.starts_with("left_") {
        Group::Arm(Side::Left)
    } else if name.starts_with("right_") {
        Group::Arm(Side::Right)
    } else {
        Group::Body
    }
}

/// Map-frame pose of base_link (on the floor, REP 105) as an f64 transform.
pub fn base_pose(x: f64, y: f64, yaw: f64) -> RPose {
    RPose::from_xyz_rpy([x, y, 0.0], [0.0, 0.0, yaw])
}

/// rapier (f32) pose of an f64 transform.
pub fn to_rapier(p: &RPose) -> Pose {
    let [x, y, z, w] = p.quaternion();
    let t = p.trans;
    Pose::from_parts(
        Vector::new(t[0] as f32, t[1] as f32, t[2] as f32),
        Rotation::from_xyzw(x as f32, y as f32, z as f32, w as f32),
    )
}

/// f64 transform of a rapier pose.
pub fn from_rapier(p: &Pose) -> RPose {
    let q = p.rotation;
    let (x, y, z, w) = (q.x as f64, q.y as f64, q.z as f64, q.w as f64);
    RPose {
        rot: [
            [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - z * w), 2.0 * (x * z + y * w)],
            [2.0 * (x * y + z * w), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - x * w)],
            [2.0 * (x * z - y * w), 2.0 * (y * z + x * w), 1.0 - 2.0 * (x * x + y * y)],
        ],
        trans: [p.translation.x as f64, p.translation.y as f64, p.translation.z as f64],
    }
}

/// The parry shape of a URDF primitive and its offset (URDF cylinders run along z, parry's along y).
fn shape_of(s: &Shape) -> Result<(SharedShape, Pose), String> {
    let positive = |v: f64| v.is_finite() && v > 0.0;
    let upright = Pose::from_rotation(Rotation::from_rotation_x(std::f32::consts::FRAC_PI_2));
    match *s {
        Shape::Box { size } if size.iter().all(|&v| positive(v)) => {
            Ok((SharedShape::cuboid(0.5 * size[0] as f32, 0.5 * size[1] as f32, 0.5 * size[2] as f32), Pose::IDENTITY))
        }
        Shape::Cylinder { radius, length } if positive(radius) && positive(length) => {
            Ok((SharedShape::cylinder(0.5 * length as f32, radius as f32), upright))
        }
        Shape::Capsule { radius, length } if positive(radius) && length >= 0.0 => {
            Ok((SharedShape::capsule_z(0.5 * length as f32, radius as f32), Pose::IDENTITY))
        }
        Shape::Sphere { radius } if positive(radius) => Ok((SharedShape::ball(radius as f32), Pose::IDENTITY)),
        _ => Err(format!("robot collision shape {s:?} has a non-positive size")),
    }
}

impl SceneWorld {
    /// Adds a kinematic body per collision-carrying link at `base * link_in_base`; registers
    /// the base box as part 0 and every link primitive as a further part.
    pub fn add_robot_links(&mut self, model: &RobotModel, base: &RPose, link_in_base: &[RPose]) -> Result<(), String> {
        self.parts.clear();
        self.parts.push(RobotPart {
            collider: self.robot.collider,
            link: "base_link".into(),
            group: Group::Body,
            floor_counts: false,
        });
        for (i, link) in model.robot.links().iter().enumerate() {
            if link.colliders.is_empty() || chassis_link(&link.name) {
                continue;
            }
            let pose = to_rapier(&base.mul(&link_in_base[i]));
            if !pose.is_finite() {
                return Err(format!("robot link {} pose is not finite", link.name));
            }
            let body = self.bodies.insert(RigidBodyBuilder::kinematic_position_based().pose(pose));
            for c in &link.colliders {
                let (shape, offset) = shape_of(&c.shape).map_err(|e| format!("link {}: {e}", link.name))?;
                let tag = PART_TAG + self.parts.len() as u128;
                let position = to_rapier(&c.origin) * offset;
                let builder = ColliderBuilder::new(shape).position(position).user_data(tag).friction(0.8);
                let collider = self.colliders.insert_with_parent(builder, body, &mut self.bodies);
                self.parts.push(RobotPart {
                    collider,
                    link: link.name.clone(),
                    group: group_of(&link.name),
                    floor_counts: true,
                });
            }
            self.links.push(LinkBody { link: i, body, pose });
        }
        Ok(())
    }

    /// The robot part a collider is (None for scene objects).
    pub fn part_of(&self, collider: &Collider) -> Option<usize> {
        if collider.user_data == crate::scene_world::ROBOT_TAG {
            return Some(0);
        }
        let i = collider.user_data.checked_sub(PART_TAG)?;
        (i < self.parts.len() as u128).then_some(i as usize)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rapier_pose_round_trip() {
        for rpy in [[0.1, -0.4, 2.9], [3.1, 0.2, -3.0], [-1.5, 1.5, 0.0], [0.0, 0.0, 3.1]] {
            let p = RPose::from_xyz_rpy([1.0, -2.0, 0.5], rpy);
            let back = from_rapier(&to_rapier(&p));
            assert!(p.max_abs_diff(&back) < 1e-6, "{rpy:?}");
        }
    }
}
