//! What an ideal IMU on the planar base reads: rigid-body kinematics of the mount point.
//!
//! The base moves in the plane (z up, roll = pitch = 0) with body velocity v = (vx, vy, 0)
//! and yaw rate w = (0, 0, wz). A point r (the mount, in base_link) then has the body-frame
//! acceleration a = dv/dt + w x v + dw/dt x r + w x (w x r). An accelerometer measures the
//! specific force f = a - g, with g = (0, 0, -9.80665) in the level base frame, so +9.80665 on
//! z at rest. Gyro and accelerometer readings are these vectors expressed in the IMU frame.
//!
//! The chassis delivers velocities at communication points only, so dv/dt and dw/dt are the
//! backward differences of the last two inputs (the mean acceleration over the last step:
//! exact for constant accelerations, half a step late otherwise). Between communication
//! points velocities and accelerations are held; yaw advances with the held yaw rate.

use crate::frame::{Quat, Vec3};
use agrisim_math::vec3::{add, cross};

/// Chassis ground truth at one instant (inputs of the FMU).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BaseState {
    pub yaw: f64,
    /// Body-frame velocity [m/s] and yaw rate [rad/s].
    pub vx: f64,
    pub vy: f64,
    pub wz: f64,
}

/// IMU pose on base_link.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Mount {
    pub translation: Vec3,
    pub rotation: Quat,
}

/// Error-free readings in the IMU frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Truth {
    pub angular_velocity: Vec3,
    pub specific_force: Vec3,
    /// Orientation of the IMU frame in the world (map) frame.
    pub orientation: Quat,
}

/// Specific force at the mount point in base_link.
pub fn specific_force_base(state: &BaseState, accel: [f64; 2], yaw_accel: f64, r: Vec3, gravity: f64) -> Vec3 {
    let w = [0.0, 0.0, state.wz];
    let alpha = [0.0, 0.0, yaw_accel];
    let v = [state.vx, state.vy, 0.0];
    let a = add(add([accel[0], accel[1], 0.0], cross(w, v)), add(cross(alpha, r), cross(w, cross(w, r))));
    [a[0], a[1], a[2] + gravity]
}

/// The latest chassis inputs and the accelerations estimated from the two latest ones.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct HeldMotion {
    time: f64,
    state: BaseState,
    accel: [f64; 2],
    yaw_accel: f64,
}

impl HeldMotion {
    /// Starts at rest acceleration-wise: nothing to difference yet.
    pub fn start(time: f64, state: BaseState) -> HeldMotion {
        HeldMotion { time, state, accel: [0.0; 2], yaw_accel: 0.0 }
    }

    /// Takes the inputs present at communication point `time`.
    pub fn update(&mut self, time: f64, state: BaseState) {
        let dt = time - self.time;
        if dt > 0.0 {
            self.accel = [(state.vx - self.state.vx) / dt, (state.vy - self.state.vy) / dt];
            self.yaw_accel = (state.wz - self.state.wz) / dt;
        }
        self.time = time;
        self.state = state;
    }

    /// Ideal readings at time `t` (>= the latest input's time).
    pub fn truth_at(&self, t: f64, mount: &Mount, gravity: f64) -> Truth {
        let s = &self.state;
        let yaw = s.yaw + s.wz * (t - self.time);
        let f = specific_force_base(s, self.accel, self.yaw_accel, mount.translation, gravity);
        Truth {
            angular_velocity: mount.rotation.inverse_rotate([0.0, 0.0, s.wz]),
            specific_force: mount.rotation.inverse_rotate(f),
            orientation: Quat::yaw(yaw).compose(mount.rotation),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn circle_needs_centripetal_force_toward_the_centre() {
        // vx = 1 m/s, wz = 0.5 rad/s: radius 2 m, centre on +y; a = v^2/r = 0.5 m/s^2 along +y.
        let s = BaseState { yaw: 0.0, vx: 1.0, vy: 0.0, wz: 0.5 };
        let f = specific_force_base(&s, [0.0; 2], 0.0, [0.0; 3], 9.8);
        assert_eq!(f, [0.0, 0.5, 9.8]);
        // A point 1 m ahead of base_link sees an extra -w^2 r = -0.25 along x.
        let f = specific_force_base(&s, [0.0; 2], 0.0, [1.0, 0.0, 0.0], 9.8);
        assert!((f[0] + 0.25).abs() < 1e-15 && (f[1] - 0.5).abs() < 1e-15);
    }
}
