//! The one boundary between agrisim's f64 scene description (greenhouse objects, FMI ports,
//! ROS 2 messages) and rapier's f32 world. f32 is ample here: 1 ulp at 500 m is 0.06 mm.

use agrisim_msgs::geometry_msgs as gm;
use agrisim_scene::scene::{Placement, Shape};
use rapier3d::prelude::{Pose, Rotation, SharedShape, Vector};

/// rapier pose of a greenhouse placement (the quaternion is renormalized).
pub fn pose_of(p: &Placement) -> Result<Pose, String> {
    let [x, y, z] = p.translation;
    let [qx, qy, qz, qw] = p.rotation;
    let all = [x, y, z, qx, qy, qz, qw];
    let norm = (qx * qx + qy * qy + qz * qz + qw * qw).sqrt();
    if all.iter().any(|v| !v.is_finite()) || norm < 1e-9 {
        return Err(format!("placement {p:?} is not finite or its rotation is not a quaternion"));
    }
    let rotation = Rotation::from_xyzw((qx / norm) as f32, (qy / norm) as f32, (qz / norm) as f32, (qw / norm) as f32);
    Ok(Pose::from_parts(Vector::new(x as f32, y as f32, z as f32), rotation))
}

/// A greenhouse shape as a parry shape plus the pose of the parry shape in the object's frame.
///
/// parry's cylinder runs along its local y axis, the scene's along z: a quarter turn about x
/// takes one to the other. Boxes and spheres need no offset.
pub fn shape_of(s: &Shape) -> Result<(SharedShape, Pose), String> {
    let positive = |v: f64| v.is_finite() && v > 0.0;
    match *s {
        Shape::Box { half } if half.iter().all(|&h| positive(h)) => {
            Ok((SharedShape::cuboid(half[0] as f32, half[1] as f32, half[2] as f32), Pose::IDENTITY))
        }
        Shape::Cylinder { radius, half_height } if positive(radius) && positive(half_height) => Ok((
            SharedShape::cylinder(half_height as f32, radius as f32),
            Pose::from_rotation(Rotation::from_rotation_x(std::f32::consts::FRAC_PI_2)),
        )),
        Shape::Sphere { radius } if positive(radius) => Ok((SharedShape::ball(radius as f32), Pose::IDENTITY)),
        _ => Err(format!("shape {s:?} has a non-positive or non-finite size")),
    }
}

/// The placement (the scene object's own frame) of a collider made by [`shape_of`]: its
/// position with a cylinder's quarter turn undone.
pub fn object_pose(collider: &rapier3d::prelude::Collider) -> Pose {
    let position = *collider.position();
    if collider.shape().as_cylinder().is_some() {
        position * Pose::from_rotation(Rotation::from_rotation_x(std::f32::consts::FRAC_PI_2)).inverse()
    } else {
        position
    }
}

/// Pose of base_link in the map frame, from the planar ground truth and a height.
pub fn planar_pose(x: f64, y: f64, yaw: f64, z: f64) -> Pose {
    Pose::from_parts(Vector::new(x as f32, y as f32, z as f32), Rotation::from_rotation_z(yaw as f32))
}

pub fn point_msg(v: Vector) -> gm::Point {
    gm::Point { x: v.x as f64, y: v.y as f64, z: v.z as f64 }
}

pub fn vector_msg(v: Vector) -> gm::Vector3 {
    gm::Vector3 { x: v.x as f64, y: v.y as f64, z: v.z as f64 }
}

pub fn pose_msg(p: &Pose) -> gm::Pose {
    let q = p.rotation;
    gm::Pose {
        position: point_msg(p.translation),
        orientation: gm::Quaternion { x: q.x as f64, y: q.y as f64, z: q.z as f64, w: q.w as f64 },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cylinder_axis_is_the_objects_z() {
        let (shape, offset) = shape_of(&Shape::Cylinder { radius: 0.1, half_height: 1.0 }).unwrap();
        let aabb = shape.compute_aabb(&offset);
        assert!(
            (aabb.maxs.z - 1.0).abs() < 1e-6 && (aabb.maxs.x - 0.1).abs() < 1e-6 && (aabb.maxs.y - 0.1).abs() < 1e-6,
            "{aabb:?}"
        );
    }

    #[test]
    fn bad_shapes_and_placements_are_errors() {
        assert!(shape_of(&Shape::Sphere { radius: 0.0 }).is_err());
        assert!(shape_of(&Shape::Box { half: [1.0, f64::NAN, 1.0] }).is_err());
        assert!(pose_of(&Placement { translation: [0.0; 3], rotation: [0.0; 4] }).is_err());
        assert!(pose_of(&Placement::at(1.0, 2.0, 3.0)).is_ok());
    }
}
