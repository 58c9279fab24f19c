//! Planar rigid transforms (x, y, yaw): the only geometry a ground robot's navigation needs.
//! Composition follows the TF convention: `a.compose(b)` is "b expressed in a's parent frame".

use agrisim_msgs::geometry_msgs::{Pose, Quaternion};

/// A pose in the plane, or the transform from a child frame to its parent.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Pose2 {
    pub x: f64,
    pub y: f64,
    pub yaw: f64,
}

impl Pose2 {
    pub const fn new(x: f64, y: f64, yaw: f64) -> Pose2 {
        Pose2 { x, y, yaw }
    }

    /// `self ∘ other`: `other` (given in self's frame) expressed in self's parent frame.
    pub fn compose(&self, other: &Pose2) -> Pose2 {
        let (s, c) = self.yaw.sin_cos();
        Pose2 { x: self.x + c * other.x - s * other.y, y: self.y + s * other.x + c * other.y, yaw: wrap_angle(self.yaw + other.yaw) }
    }

    pub fn inverse(&self) -> Pose2 {
        let (s, c) = self.yaw.sin_cos();
        Pose2 { x: -(c * self.x + s * self.y), y: -(-s * self.x + c * self.y), yaw: wrap_angle(-self.yaw) }
    }

    /// A point given in this frame, expressed in the parent frame.
    pub fn apply(&self, px: f64, py: f64) -> (f64, f64) {
        let (s, c) = self.yaw.sin_cos();
        (self.x + c * px - s * py, self.y + s * px + c * py)
    }

    pub fn dist(&self, other: &Pose2) -> f64 {
        (self.x - other.x).hypot(self.y - other.y)
    }

    /// Reads x, y and the yaw of the quaternion (roll and pitch are ignored: the floor is flat).
    pub fn from_msg(p: &Pose) -> Pose2 {
        Pose2 { x: p.position.x, y: p.position.y, yaw: yaw_of(&p.orientation) }
    }

    pub fn to_msg(&self) -> Pose {
        let mut p = Pose::default();
        p.position.x = self.x;
        p.position.y = self.y;
        p.orientation = Quaternion::from_yaw(self.yaw);
        p
    }
}

/// Yaw (rotation about +z) of a quaternion, ZYX convention.
pub fn yaw_of(q: &Quaternion) -> f64 {
    (2.0 * (q.w * q.z + q.x * q.y)).atan2(1.0 - 2.0 * (q.y * q.y + q.z * q.z))
}

/// Angle in (-pi, pi].
pub fn wrap_angle(a: f64) -> f64 {
    let mut a = a % std::f64::consts::TAU;
    if a <= -std::f64::consts::PI {
        a += std::f64::consts::TAU;
    } else if a > std::f64::consts::PI {
        a -= std::f64::consts::TAU;
    }
    a
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn compose_inverse_is_identity() {
        let a = Pose2::new(1.0, -2.0, 2.5);
        let b = Pose2::new(0.3, 0.7, -1.0);
        let c = a.compose(&b);
        let back = a.inverse().compose(&c);
        assert!((back.x - b.x).abs() < 1e-12 && (back.y - b.y).abs() < 1e-12 && (back.yaw - b.yaw).abs() < 1e-12);
        let q = Pose2::from_msg(&c.to_msg());
        assert!((q.yaw - c.yaw).abs() < 1e-12);
        assert!((wrap_angle(3.0 * std::f64::consts::PI) - std::f64::consts::PI).abs() < 1e-12);
    }
}
