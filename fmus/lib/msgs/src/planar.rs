//! `geometry_msgs/Pose` to and from [`Pose2`], the planar pose of `agrisim_math`. The
//! conversions live on the message side so that the math crate, and through it the FMI export
//! layer and every model, link no message types.

use crate::geometry_msgs::{Pose, Quaternion};
use agrisim_math::Pose2;

impl From<&Pose> for Pose2 {
    /// Reads x, y and the yaw of the quaternion (roll and pitch are ignored: the floor is flat).
    fn from(p: &Pose) -> Pose2 {
        Pose2 { x: p.position.x, y: p.position.y, yaw: p.orientation.yaw() }
    }
}

impl From<Pose2> for Pose {
    /// z = 0 and a rotation about +z only.
    fn from(p: Pose2) -> Pose {
        let mut m = Pose::default();
        m.position.x = p.x;
        m.position.y = p.y;
        m.orientation = Quaternion::from_yaw(p.yaw);
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pose_round_trips_through_the_message() {
        for k in -20..=20 {
            let a = Pose2::new(0.3 * k as f64, -1.7 + 0.1 * k as f64, 0.31 * k as f64);
            let m = Pose::from(a);
            assert_eq!((m.position.x, m.position.y, m.position.z), (a.x, a.y, 0.0));
            let b = Pose2::from(&m);
            assert_eq!((b.x, b.y), (a.x, a.y));
            assert!((b.yaw - agrisim_math::wrap_angle(a.yaw)).abs() < 1e-12, "{a:?} -> {b:?}");
        }
    }

    #[test]
    fn roll_and_pitch_are_ignored() {
        // 90 degrees about +z, then a small roll: the yaw read back stays 90 degrees.
        let (h, r) = (std::f64::consts::FRAC_PI_4, 0.05_f64);
        let z = Quaternion { x: 0.0, y: 0.0, z: h.sin(), w: h.cos() };
        let x = Quaternion { x: r.sin(), y: 0.0, z: 0.0, w: r.cos() };
        let q = Quaternion {
            w: z.w * x.w - z.x * x.x - z.y * x.y - z.z * x.z,
            x: z.w * x.x + z.x * x.w + z.y * x.z - z.z * x.y,
            y: z.w * x.y - z.x * x.z + z.y * x.w + z.z * x.x,
            z: z.w * x.z + z.x * x.y - z.y * x.x + z.z * x.w,
        };
        let m = Pose { orientation: q, ..Default::default() };
        assert!((Pose2::from(&m).yaw - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    }
}
