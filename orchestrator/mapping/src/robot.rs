//! The robot's collision geometry for the self-filter, from the URDF text on
//! `/robot_description` (as MoveIt's robot self filter builds its shapes from the robot
//! model): per link its collision primitives in the link frame. Placed in the map frame with
//! each link's pose from TF, they are the [`Primitive`]s the map filters out of a depth frame.
//!
//! Meshes are left out (the project's URDF has primitives only); each one left out is counted.

use crate::shape::{Primitive, Shape};
use nalgebra::{Isometry3, Translation3, UnitQuaternion};

/// One link's collision shapes, each at its origin in the link frame.
#[derive(Debug, Clone, PartialEq)]
pub struct LinkShapes {
    pub link: String,
    pub shapes: Vec<(Shape, Isometry3<f64>)>,
}

/// The links with collision primitives, in URDF order.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RobotShapes {
    pub links: Vec<LinkShapes>,
    /// Collision elements left out: meshes and unusable sizes, as "link: reason".
    pub ignored: Vec<String>,
}

/// A URDF origin (xyz, then fixed-axis roll, pitch, yaw: R = Rz(yaw) Ry(pitch) Rx(roll), as
/// URDF specifies and nalgebra's `from_euler_angles` computes).
fn origin(p: &urdf_rs::Pose) -> Option<Isometry3<f64>> {
    let (t, r) = (p.xyz.0, p.rpy.0);
    t.iter().chain(r.iter()).all(|v| v.is_finite()).then(|| {
        Isometry3::from_parts(Translation3::new(t[0], t[1], t[2]), UnitQuaternion::from_euler_angles(r[0], r[1], r[2]))
    })
}

impl RobotShapes {
    /// Parses URDF text; errors say what urdf-rs could not read.
    pub fn from_urdf(text: &str) -> Result<RobotShapes, String> {
        let urdf = urdf_rs::read_from_string(text).map_err(|e| format!("URDF parse error: {e}"))?;
        let mut out = RobotShapes::default();
        for l in &urdf.links {
            let mut shapes = Vec::new();
            for (i, c) in l.collision.iter().enumerate() {
                let shape = match &c.geometry {
                    urdf_rs::Geometry::Box { size } => Shape::Box { size: size.0 },
                    urdf_rs::Geometry::Cylinder { radius, length } => {
                        Shape::Cylinder { radius: *radius, length: *length }
                    }
                    urdf_rs::Geometry::Capsule { radius, length } => {
                        Shape::Capsule { radius: *radius, length: *length }
                    }
                    urdf_rs::Geometry::Sphere { radius } => Shape::Sphere { radius: *radius },
                    urdf_rs::Geometry::Mesh { filename, .. } => {
                        out.ignored.push(format!("{} collision {i}: mesh {filename} not used", l.name));
                        continue;
                    }
                };
                let sizes: Vec<f64> = match shape {
                    Shape::Box { size } => size.to_vec(),
                    Shape::Sphere { radius } => vec![radius],
                    Shape::Cylinder { radius, length } | Shape::Capsule { radius, length } => vec![radius, length],
                };
                let Some(at) = origin(&c.origin).filter(|_| sizes.iter().all(|v| v.is_finite() && *v >= 0.0)) else {
                    out.ignored.push(format!("{} collision {i}: non-finite or negative size or origin", l.name));
                    continue;
                };
                shapes.push((shape, at));
            }
            if !shapes.is_empty() {
                out.links.push(LinkShapes { link: l.name.clone(), shapes });
            }
        }
        Ok(out)
    }

    /// The shapes placed in the map frame with each link's pose from `pose_of` (the link
    /// frame in the map frame); the links it has no pose for, in URDF order.
    pub fn place(&self, mut pose_of: impl FnMut(&str) -> Option<Isometry3<f64>>) -> (Vec<Primitive>, Vec<&str>) {
        let (mut placed, mut missing) = (Vec::new(), Vec::new());
        for l in &self.links {
            match pose_of(&l.link) {
                Some(pose) => placed.extend(l.shapes.iter().map(|(s, at)| Primitive::new(*s, pose * at))),
                None => missing.push(l.link.as_str()),
            }
        }
        (placed, missing)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Point3;

    const URDF: &str = r#"<robot name="r">
      <link name="base"><collision><origin xyz="0 0 0.1" rpy="0 0 0"/><geometry><box size="0.2 0.4 0.2"/></geometry></collision></link>
      <link name="arm">
        <collision><origin xyz="0.5 0 0" rpy="0 1.5707963267948966 0"/><geometry><cylinder radius="0.05" length="1.0"/></geometry></collision>
        <collision><geometry><sphere radius="0.1"/></geometry></collision>
        <collision><geometry><mesh filename="package://r/arm.stl"/></geometry></collision>
      </link>
      <link name="tcp"/>
      <joint name="j" type="fixed"><parent link="base"/><child link="arm"/></joint>
      <joint name="k" type="fixed"><parent link="arm"/><child link="tcp"/></joint>
    </robot>"#;

    #[test]
    fn collision_shapes_are_read_and_placed() {
        let r = RobotShapes::from_urdf(URDF).unwrap();
        assert_eq!(r.links.iter().map(|l| l.link.as_str()).collect::<Vec<_>>(), ["base", "arm"]);
        assert_eq!(r.links[1].shapes.len(), 2);
        assert_eq!(r.ignored.len(), 1, "{:?}", r.ignored);
        assert!(r.ignored[0].contains("arm collision 2: mesh"));
        // The arm 1 m up: its cylinder (pitched onto the x axis) reaches x = 1.0 at z = 1.
        let (placed, missing) = r.place(|l| (l == "arm").then(|| Isometry3::translation(0.0, 0.0, 1.0)));
        assert_eq!(missing, ["base"]);
        assert_eq!(placed.len(), 2);
        assert!(placed[0].contains(&Point3::new(0.99, 0.0, 1.0), 0.0));
        assert!(!placed[0].contains(&Point3::new(0.5, 0.0, 1.06), 0.0));
        assert!(placed[0].contains(&Point3::new(0.5, 0.0, 1.06), 0.02));
        assert!(placed[1].contains(&Point3::new(0.0, 0.09, 1.0), 0.0));
        assert!(RobotShapes::from_urdf("<robot").is_err());
    }
}
