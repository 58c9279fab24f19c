//! Wheel odometry: dead reckoning from (noisy) wheel encoder readings, and its message.

use crate::se2::{integrate, Twist2};
use crate::wheels::WheelLayout;
use agrisim_math::{Pose2, Rng};
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::geometry_msgs::{Point, Pose, PoseWithCovariance, Quaternion, Twist, TwistWithCovariance, Vector3};
use agrisim_msgs::nav_msgs::Odometry;
use agrisim_msgs::std_msgs::Header;

/// Dead-reckoned pose in the odom frame. The odom frame starts at the initial base pose
/// (REP 105: odom is continuous and drifts; map -> odom corrections come from localization).
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct WheelOdometry {
    pub pose: Pose2,
    pub twist: Twist2,
}

impl WheelOdometry {
    /// Integrates one step from the wheels' travel over it (mean contact velocities, what
    /// tick-counting encoders measure), read with encoder and steering-sensor noise.
    pub fn update(
        &mut self,
        layout: &WheelLayout,
        travel: &[(f64, f64); 4],
        enc_noise: f64,
        steer_noise: f64,
        rng: &mut Rng,
        h: f64,
    ) {
        let read: [(f64, f64); 4] = std::array::from_fn(|i| {
            let (vx, vy) = travel[i];
            let speed = vx.hypot(vy) + layout.radius * rng.gauss(enc_noise);
            let angle = vy.atan2(vx) + rng.gauss(steer_noise);
            (speed * angle.cos(), speed * angle.sin())
        });
        self.twist = layout.forward_from_velocities(&read);
        integrate(&mut self.pose, self.twist, h);
    }

    pub fn message(&self, stamp_ns: i64) -> Odometry {
        let (s, c) = (self.pose.yaw / 2.0).sin_cos();
        Odometry {
            header: Header { stamp: Time::from_nanos(stamp_ns), frame_id: "odom".into() },
            child_frame_id: "base_link".into(),
            pose: PoseWithCovariance {
                pose: Pose {
                    position: Point { x: self.pose.x, y: self.pose.y, z: 0.0 },
                    orientation: Quaternion { x: 0.0, y: 0.0, z: s, w: c },
                },
                covariance: [0.0; 36],
            },
            twist: TwistWithCovariance {
                twist: Twist {
                    linear: Vector3 { x: self.twist.vx, y: self.twist.vy, z: 0.0 },
                    angular: Vector3 { x: 0.0, y: 0.0, z: self.twist.wz },
                },
                covariance: [0.0; 36],
            },
        }
    }
}
