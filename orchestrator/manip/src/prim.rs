//! Collision primitives placed in the planning frame, and the one narrow-phase query the
//! fast checker needs: does a sphere overlap a primitive? Closed forms only (no GJK), which
//! is what makes a configuration check cost microseconds.

use agrisim_robot::Shape;
use nalgebra::{Isometry3, Point3, Vector3};

/// A primitive with its pose (planning frame) and a bounding sphere for culling.
#[derive(Debug, Clone, Copy)]
pub struct Prim {
    pub shape: Shape,
    pub pose: Isometry3<f64>,
    inv: Isometry3<f64>,
    pub center: Point3<f64>,
    pub radius: f64,
}

impl Prim {
    pub fn new(shape: Shape, pose: Isometry3<f64>) -> Prim {
        let radius = bounding_radius(&shape);
        Prim { shape, pose, inv: pose.inverse(), center: Point3::from(pose.translation.vector), radius }
    }

    /// Axis-aligned bounds in the planning frame (exact for the rotated primitive's extent).
    pub fn aabb(&self) -> (Point3<f64>, Point3<f64>) {
        let r = self.pose.rotation.to_rotation_matrix().into_inner();
        let c = self.center;
        let ext = match self.shape {
            Shape::Sphere { radius } => Vector3::repeat(radius),
            Shape::Box { size } => {
                let h = Vector3::from(size) * 0.5;
                r.abs() * h
            }
            Shape::Cylinder { radius, length } | Shape::Capsule { radius, length } => {
                let cap = matches!(self.shape, Shape::Capsule { .. });
                let a = r.column(2).into_owned() * (length * 0.5);
                // A disc of radius r normal to axis n spans r*sqrt(1 - n_i^2) along axis i.
                let n = r.column(2);
                Vector3::from_fn(|i, _| {
                    a[i].abs() + if cap { radius } else { radius * (1.0 - n[i] * n[i]).max(0.0).sqrt() }
                })
            }
        };
        (c - ext, c + ext)
    }

    /// Distance from a point (planning frame) to the primitive's solid (0 inside).
    pub fn point_distance(&self, p: &Point3<f64>) -> f64 {
        let l = self.inv * p;
        match self.shape {
            Shape::Sphere { radius } => (l.coords.norm() - radius).max(0.0),
            Shape::Box { size } => {
                let d = Vector3::from_fn(|i, _| (l[i].abs() - size[i] * 0.5).max(0.0));
                d.norm()
            }
            Shape::Cylinder { radius, length } => {
                let dr = ((l.x * l.x + l.y * l.y).sqrt() - radius).max(0.0);
                let dz = (l.z.abs() - length * 0.5).max(0.0);
                (dr * dr + dz * dz).sqrt()
            }
            Shape::Capsule { radius, length } => {
                let z = l.z.clamp(-length * 0.5, length * 0.5);
                let d = Vector3::new(l.x, l.y, l.z - z).norm();
                (d - radius).max(0.0)
            }
        }
    }

    /// Whether a sphere overlaps the primitive (touching counts).
    #[inline]
    pub fn overlaps_sphere(&self, c: &Point3<f64>, r: f64) -> bool {
        let rr = self.radius + r;
        if (c - self.center).norm_squared() > rr * rr {
            return false;
        }
        self.point_distance(c) <= r
    }
}

/// Radius of the smallest sphere about the primitive's origin that contains it.
pub fn bounding_radius(s: &Shape) -> f64 {
    match *s {
        Shape::Sphere { radius } => radius,
        Shape::Box { size } => 0.5 * (size[0] * size[0] + size[1] * size[1] + size[2] * size[2]).sqrt(),
        Shape::Cylinder { radius, length } => (radius * radius + 0.25 * length * length).sqrt(),
        Shape::Capsule { radius, length } => radius + 0.5 * length,
    }
}
