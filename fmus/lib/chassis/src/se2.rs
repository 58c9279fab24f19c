//! Body-frame twist and the exact integration of a planar pose under it. The pose is the
//! workspace's one [`Pose2`] (REP 103: x forward, y left, z up).

use agrisim_math::{wrap_angle_euclid, Pose2};

/// Body-frame twist: forward `vx`, left `vy`, counter-clockwise `wz`.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Twist2 {
    pub vx: f64,
    pub vy: f64,
    pub wz: f64,
}

/// Moves `pose` by a body twist held constant for `h` seconds, using the SE(2) exponential
/// map, so straight lines and circles are exact (no Euler drift).
///
/// The yaw is wrapped with [`wrap_angle_euclid`] (`rem_euclid`), not with
/// `agrisim_math::wrap_angle` (`%`) that [`Pose2::compose`] uses: the two can differ in the
/// last bit, and the chassis' ground-truth and odometry poses are logged, so this integration
/// keeps the wrap it has always had.
pub fn integrate(pose: &mut Pose2, t: Twist2, h: f64) {
    let dth = t.wz * h;
    // (sin θ)/θ and (1 - cos θ)/θ, with series near 0 to keep full precision.
    let (a, b) = if dth.abs() < 1e-6 {
        (1.0 - dth * dth / 6.0, dth / 2.0 - dth * dth * dth / 24.0)
    } else {
        (dth.sin() / dth, (1.0 - dth.cos()) / dth)
    };
    let (dx_b, dy_b) = ((a * t.vx - b * t.vy) * h, (b * t.vx + a * t.vy) * h);
    let (s, c) = pose.yaw.sin_cos();
    pose.x += c * dx_b - s * dy_b;
    pose.y += s * dx_b + c * dy_b;
    pose.yaw = wrap_angle_euclid(pose.yaw + dth);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn circle_closes_after_one_revolution() {
        let mut p = Pose2::default();
        let w = 0.5;
        let tw = Twist2 { vx: 1.0, vy: 0.0, wz: w };
        let n = 1000;
        let period = 2.0 * std::f64::consts::PI / w;
        for _ in 0..n {
            integrate(&mut p, tw, period / n as f64);
        }
        assert!(p.x.abs() < 1e-9 && p.y.abs() < 1e-9, "{p:?}");
    }

    #[test]
    fn single_step_matches_closed_form_arc() {
        let mut p = Pose2 { x: 1.0, y: 2.0, yaw: 0.3 };
        let tw = Twist2 { vx: 0.7, vy: -0.2, wz: 0.4 };
        integrate(&mut p, tw, 2.0);
        // closed form: p(t) = p0 + R(yaw0) * ∫ R(wz s) v ds
        let (w, t) = (0.4_f64, 2.0_f64);
        let ix = ((w * t).sin() * 0.7 - (1.0 - (w * t).cos()) * -0.2) / w;
        let iy = ((1.0 - (w * t).cos()) * 0.7 + (w * t).sin() * -0.2) / w;
        let (s, c) = 0.3_f64.sin_cos();
        assert!((p.x - (1.0 + c * ix - s * iy)).abs() < 1e-12);
        assert!((p.y - (2.0 + s * ix + c * iy)).abs() < 1e-12);
    }
}
