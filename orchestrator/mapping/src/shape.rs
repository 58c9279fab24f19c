//! Solid primitives in the map frame: the robot's links for the self-filter (supplied by the
//! caller from the URDF's collision shapes and the joint states) and the allowed objects.

use agrisim_msgs::geometry_msgs::Pose;
use agrisim_msgs::shape_msgs::SolidPrimitive;
use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion, Vector3};

/// A primitive's geometry in its own frame (centred; cylinders and capsules along local z).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    Sphere { radius: f64 },
    Box { size: [f64; 3] },
    Cylinder { radius: f64, length: f64 },
    Capsule { radius: f64, length: f64 },
}

/// A shape placed in the map frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Primitive {
    pub shape: Shape,
    pub pose: Isometry3<f64>,
}

/// A sphere in the map frame (an allowed object: the fruit to grasp).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sphere {
    pub center: Point3<f64>,
    pub radius: f64,
}

impl Primitive {
    pub fn new(shape: Shape, pose: Isometry3<f64>) -> Primitive {
        Primitive { shape, pose }
    }

    /// Radius of the smallest sphere about the primitive's origin that holds it.
    pub fn bounding_radius(&self) -> f64 {
        match self.shape {
            Shape::Sphere { radius } => radius,
            Shape::Box { size } => 0.5 * Vector3::from(size).norm(),
            Shape::Cylinder { radius, length } => (radius * radius + 0.25 * length * length).sqrt(),
            Shape::Capsule { radius, length } => radius + 0.5 * length,
        }
    }

    /// Distance from a point (map frame) to the solid, 0 inside.
    pub fn distance(&self, p: &Point3<f64>) -> f64 {
        let l = self.pose.inverse_transform_point(p);
        match self.shape {
            Shape::Sphere { radius } => (l.coords.norm() - radius).max(0.0),
            Shape::Box { size } => Vector3::from_fn(|i, _| (l[i].abs() - 0.5 * size[i]).max(0.0)).norm(),
            Shape::Cylinder { radius, length } => {
                let dr = ((l.x * l.x + l.y * l.y).sqrt() - radius).max(0.0);
                let dz = (l.z.abs() - 0.5 * length).max(0.0);
                (dr * dr + dz * dz).sqrt()
            }
            Shape::Capsule { radius, length } => {
                let z = l.z.clamp(-0.5 * length, 0.5 * length);
                (Vector3::new(l.x, l.y, l.z - z).norm() - radius).max(0.0)
            }
        }
    }

    /// Whether a point lies in the solid grown by `padding` (touching counts).
    pub fn contains(&self, p: &Point3<f64>, padding: f64) -> bool {
        let r = self.bounding_radius() + padding;
        (p - Point3::from(self.pose.translation.vector)).norm_squared() <= r * r && self.distance(p) <= padding
    }

    /// A `shape_msgs/SolidPrimitive` (box, sphere, cylinder) at a pose, as a planning scene or
    /// a URDF collision element gives it; `None` for cones, prisms, short dimension lists,
    /// non-finite or negative sizes and unusable orientations.
    pub fn from_msg(p: &SolidPrimitive, pose: &Pose) -> Option<Primitive> {
        let d = &p.dimensions;
        let shape = match p.r#type {
            SolidPrimitive::BOX if d.len() >= 3 => Shape::Box { size: [d[0], d[1], d[2]] },
            SolidPrimitive::SPHERE if !d.is_empty() => Shape::Sphere { radius: d[0] },
            SolidPrimitive::CYLINDER if d.len() >= 2 => Shape::Cylinder {
                radius: d[SolidPrimitive::CYLINDER_RADIUS],
                length: d[SolidPrimitive::CYLINDER_HEIGHT],
            },
            _ => return None,
        };
        if !d.iter().all(|v| v.is_finite() && *v >= 0.0) {
            return None;
        }
        let q = &pose.orientation;
        let q = UnitQuaternion::try_new(Quaternion::new(q.w, q.x, q.y, q.z), 1e-9)?;
        let t = &pose.position;
        [t.x, t.y, t.z]
            .iter()
            .all(|v| v.is_finite())
            .then(|| Primitive::new(shape, Isometry3::from_parts(Translation3::new(t.x, t.y, t.z), q)))
    }
}

/// Squared distance from a point to an axis-aligned box.
pub(crate) fn point_box_distance_sq(p: &[f64; 3], lo: &[f64; 3], hi: &[f64; 3]) -> f64 {
    (0..3)
        .map(|i| {
            let d = (lo[i] - p[i]).max(p[i] - hi[i]).max(0.0);
            d * d
        })
        .sum()
}

/// Distance from a segment to an axis-aligned box. The distance along the segment is convex,
/// so a golden-section search finds its minimum (to 1e-9 of the segment's length).
pub(crate) fn segment_box_distance(a: &[f64; 3], b: &[f64; 3], lo: &[f64; 3], hi: &[f64; 3]) -> f64 {
    let at = |t: f64| -> f64 {
        let p = [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2])];
        point_box_distance_sq(&p, lo, hi)
    };
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut l, mut h) = (0.0f64, 1.0f64);
    let (mut x1, mut x2) = (h - g * (h - l), l + g * (h - l));
    let (mut f1, mut f2) = (at(x1), at(x2));
    for _ in 0..44 {
        if f1 <= f2 {
            h = x2;
            x2 = x1;
            f2 = f1;
            x1 = h - g * (h - l);
            f1 = at(x1);
        } else {
            l = x1;
            x1 = x2;
            f1 = f2;
            x2 = l + g * (h - l);
            f2 = at(x2);
        }
    }
    [at(0.0), at(1.0), f1, f2].into_iter().fold(f64::INFINITY, f64::min).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distances_of_each_shape() {
        let at = |x, y, z| Isometry3::translation(x, y, z);
        let s = Primitive::new(Shape::Sphere { radius: 0.1 }, at(1.0, 0.0, 0.0));
        assert!((s.distance(&Point3::new(1.3, 0.0, 0.0)) - 0.2).abs() < 1e-12);
        assert!(s.contains(&Point3::new(1.05, 0.0, 0.0), 0.0));
        assert!(!s.contains(&Point3::new(1.15, 0.0, 0.0), 0.0));
        assert!(s.contains(&Point3::new(1.15, 0.0, 0.0), 0.06));
        let b = Primitive::new(Shape::Box { size: [0.2, 0.4, 0.6] }, at(0.0, 0.0, 0.0));
        assert!((b.distance(&Point3::new(0.4, 0.0, 0.0)) - 0.3).abs() < 1e-12);
        assert_eq!(b.distance(&Point3::new(0.09, 0.19, 0.29)), 0.0);
        let c = Primitive::new(Shape::Cylinder { radius: 0.05, length: 0.4 }, at(0.0, 0.0, 0.0));
        assert!((c.distance(&Point3::new(0.0, 0.0, 0.3)) - 0.1).abs() < 1e-12);
        assert!((c.distance(&Point3::new(0.15, 0.0, 0.1)) - 0.1).abs() < 1e-12);
        let k = Primitive::new(Shape::Capsule { radius: 0.05, length: 0.4 }, at(0.0, 0.0, 0.0));
        assert!((k.distance(&Point3::new(0.0, 0.0, 0.35)) - 0.1).abs() < 1e-12);
    }

    #[test]
    fn segment_to_box() {
        let (lo, hi) = ([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]);
        // Parallel to a face at 0.5 above it.
        assert!((segment_box_distance(&[-1.0, 0.5, 1.5], &[2.0, 0.5, 1.5], &lo, &hi) - 0.5).abs() < 1e-9);
        // Through the box.
        assert_eq!(segment_box_distance(&[-1.0, 0.5, 0.5], &[2.0, 0.5, 0.5], &lo, &hi), 0.0);
        // Past a corner: closest approach of the diagonal line x + y = 3 to (1, 1) is sqrt(2)/2.
        let d = segment_box_distance(&[3.0, 0.0, 0.5], &[0.0, 3.0, 0.5], &lo, &hi);
        assert!((d - 0.5f64.sqrt()).abs() < 1e-9, "{d}");
    }
}
