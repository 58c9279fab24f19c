//! Franka Emika Panda joint limits (the harvest robot's arms use Panda kinematics and limits).
//!
//! Source: Franka Control Interface documentation, "Robot and interface specifications",
//! joint-space limits table (also the constants kMaxJointVelocity / kMaxJointAcceleration /
//! kMaxJointJerk of libfranka's rate_limiting.h). Position limits as in the same table.

use crate::limits::JointLimits;

/// Number of arm joints.
pub const DOF: usize = 7;
/// Lower joint position limits, rad.
pub const POSITION_MIN: [f64; DOF] = [-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973];
/// Upper joint position limits, rad.
pub const POSITION_MAX: [f64; DOF] = [2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973];
/// Maximum joint velocity, rad/s.
pub const VELOCITY: [f64; DOF] = [2.175, 2.175, 2.175, 2.175, 2.61, 2.61, 2.61];
/// Maximum joint acceleration, rad/s².
pub const ACCELERATION: [f64; DOF] = [15.0, 7.5, 10.0, 12.5, 15.0, 20.0, 20.0];
/// Maximum joint jerk, rad/s³.
pub const JERK: [f64; DOF] = [7500.0, 3750.0, 5000.0, 6250.0, 7500.0, 10000.0, 10000.0];

/// The published limits.
pub fn limits() -> JointLimits {
    JointLimits {
        position: POSITION_MIN.iter().copied().zip(POSITION_MAX).collect(),
        velocity: VELOCITY.to_vec(),
        acceleration: ACCELERATION.to_vec(),
        jerk: JERK.to_vec(),
    }
}

/// Conservative limits to plan with, so that tracking error and the limit checker's tolerance
/// never bring the real motion to the hardware limits: 50 % velocity, 30 % acceleration,
/// 10 % jerk (MoveIt's Panda configuration likewise plans with a quarter of the acceleration).
pub fn planning_limits() -> JointLimits {
    limits().scaled(0.5, 0.3, 0.1)
}
