//! Planar rigid transforms (x, y, yaw): the workspace's one 2-D pose type, used by the
//! navigation stack, the chassis FMU (ground truth and odometry) and the LiDAR FMU (the base's
//! recent path). Composition follows the TF convention: `a.compose(b)` is "b expressed in a's
//! parent frame".
//!
//! Two angle wraps exist on purpose: [`wrap_angle`] (`%`, used by [`Pose2::compose`],
//! [`Pose2::inverse`] and the navigation stack) and [`wrap_angle_euclid`] (`rem_euclid`, used
//! by the chassis FMU's pose integration). Both map to (-pi, pi] but can differ in the last bit
//! (and at the boundary) for some inputs; the chassis pose is logged, so it keeps its own.
//!
//! The conversions to and from `geometry_msgs/Pose` live in `agrisim-msgs` (its `planar`
//! module): this crate links no message types, so the FMI export layer does not either.

/// A pose in the plane, or the transform from a child frame to its parent.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
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
        Pose2 {
            x: self.x + c * other.x - s * other.y,
            y: self.y + s * other.x + c * other.y,
            yaw: wrap_angle(self.yaw + other.yaw),
        }
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

/// Angle in (-pi, pi] via `rem_euclid`: the chassis FMU's wrap (its pose integration and
/// wheel steering). Not interchangeable with [`wrap_angle`]: the two can differ in the last
/// bit, and the chassis' logged pose must stay bit-identical, so it keeps this one.
pub fn wrap_angle_euclid(a: f64) -> f64 {
    let mut r = a.rem_euclid(2.0 * std::f64::consts::PI);
    if r > std::f64::consts::PI {
        r -= 2.0 * std::f64::consts::PI;
    }
    r
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
        assert!((wrap_angle(3.0 * std::f64::consts::PI) - std::f64::consts::PI).abs() < 1e-12);
    }

    #[test]
    fn both_wraps_land_in_half_open_interval_and_agree_closely() {
        use std::f64::consts::PI;
        for k in -40..=40 {
            let a = k as f64 * 0.37;
            let (w, e) = (wrap_angle(a), wrap_angle_euclid(a));
            assert!(w > -PI && w <= PI && e > -PI && e <= PI, "{a}: {w} {e}");
            assert!((w - e).abs() < 1e-12, "{a}: {w} {e}");
        }
    }
}
