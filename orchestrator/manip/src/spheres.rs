//! Sphere approximation of every arm body, generated from the URDF collision primitives.
//!
//! Each primitive is cut along its longest axis into n equal slabs, and each slab is covered
//! by the sphere about its centre that contains the slab entirely (radius^2 = cross-section
//! half-diagonal^2 + (slab/2)^2). The spheres therefore contain the primitive: any contact of
//! the exact shape is also a sphere contact (conservative), which the tests check against
//! parry. Slabs no longer than the cross-section radius keep the overshoot below ~12 %.

use crate::layout::NBODIES;
use agrisim_robot::{Collider, Shape};
use nalgebra::{Point3, Vector3};

/// A sphere in its body's frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sphere {
    pub center: Point3<f64>,
    pub radius: f64,
}

/// Spheres of every arm body (flat, body after body) plus one bounding sphere per body for
/// culling.
#[derive(Debug, Clone)]
pub struct SphereModel {
    /// All spheres, each in its body's frame; body `b` owns `flat[offsets[b]..offsets[b + 1]]`.
    pub flat: Vec<Sphere>,
    pub offsets: [usize; NBODIES + 1],
    pub bounds: [Sphere; NBODIES],
}

impl SphereModel {
    pub fn new(colliders: &[Vec<Collider>]) -> SphereModel {
        let per: Vec<Vec<Sphere>> = colliders.iter().map(|c| c.iter().flat_map(cover).collect()).collect();
        let bounds = std::array::from_fn(|b| enclose(&per[b]));
        let mut offsets = [0; NBODIES + 1];
        for b in 0..NBODIES {
            offsets[b + 1] = offsets[b] + per[b].len();
        }
        SphereModel { flat: per.concat(), offsets, bounds }
    }

    /// Spheres of body `b`.
    pub fn of(&self, b: usize) -> &[Sphere] {
        &self.flat[self.offsets[b]..self.offsets[b + 1]]
    }

    /// Total number of spheres (for reports).
    pub fn count(&self) -> usize {
        self.flat.len()
    }
}

/// Spheres containing one collider, in its link's frame.
pub fn cover(c: &Collider) -> Vec<Sphere> {
    // (half extents along the primitive's x, y, z; cross-section radius about each axis).
    let (half, round) = match c.shape {
        Shape::Sphere { radius } => {
            return vec![Sphere { center: Point3::from(c.origin.trans), radius }];
        }
        Shape::Box { size } => (Vector3::from(size) * 0.5, false),
        Shape::Cylinder { radius, length } => (Vector3::new(radius, radius, length * 0.5), true),
        Shape::Capsule { radius, length } => {
            // Capsule: spheres along the segment (radius exactly), spaced radius apart.
            let n = ((length / radius).ceil() as usize).max(1);
            return (0..=n)
                .map(|i| {
                    let z = -length * 0.5 + length * i as f64 / n as f64;
                    Sphere { center: Point3::from(c.origin.transform_point([0.0, 0.0, z])), radius }
                })
                .collect();
        }
    };
    let axis = if round { 2 } else { half.imax() };
    let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
    let rc = if round { half[u] } else { (half[u] * half[u] + half[v] * half[v]).sqrt() };
    let len = 2.0 * half[axis];
    let n = ((len / rc).ceil() as usize).max(1);
    let h = len / n as f64;
    let radius = (rc * rc + 0.25 * h * h).sqrt();
    (0..n)
        .map(|i| {
            let mut p = [0.0; 3];
            p[axis] = -half[axis] + h * (i as f64 + 0.5);
            Sphere { center: Point3::from(c.origin.transform_point(p)), radius }
        })
        .collect()
}

/// A sphere containing all of `s` (centroid-centred; not minimal, but cheap and safe).
fn enclose(s: &[Sphere]) -> Sphere {
    if s.is_empty() {
        return Sphere { center: Point3::origin(), radius: 0.0 };
    }
    let c = s.iter().fold(Vector3::zeros(), |a, x| a + x.center.coords) / s.len() as f64;
    let center = Point3::from(c);
    let radius = s.iter().map(|x| (x.center - center).norm() + x.radius).fold(0.0, f64::max);
    Sphere { center, radius }
}

/// Whether two spheres in the world (centre, radius) touch, with `pad` between them.
#[inline]
pub(crate) fn spheres_touch(a: &(Point3<f64>, f64), b: &(Point3<f64>, f64), pad: f64) -> bool {
    let r = a.1 + b.1 + pad;
    (a.0 - b.0).norm_squared() <= r * r
}

/// Whether two bodies' sphere sets touch.
pub(crate) fn bodies_touch(
    s: &[(Point3<f64>, f64)],
    a: std::ops::Range<usize>,
    t: &[(Point3<f64>, f64)],
    b: std::ops::Range<usize>,
    pad: f64,
) -> bool {
    s[a].iter().any(|x| t[b.clone()].iter().any(|y| spheres_touch(x, y, pad)))
}
