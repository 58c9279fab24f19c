//! Fine positioning of the omnidirectional base next to a plant: a proportional controller
//! on the localized pose that crabs sideways and creeps forward in one motion (the 4WS base
//! is holonomic), speed-limited and slowed near the goal so it stops without overshoot.

use agrisim_math::pose2::wrap_angle;
use agrisim_math::Pose2;

#[derive(Debug, Clone, Copy)]
pub struct BaseController {
    pub gain: f64,
    pub yaw_gain: f64,
    pub max_speed: f64,
    pub max_yaw_rate: f64,
    /// Position / yaw tolerances of "in place" [m, rad].
    pub tolerance: (f64, f64),
}

impl Default for BaseController {
    fn default() -> Self {
        BaseController { gain: 0.8, yaw_gain: 1.0, max_speed: 0.3, max_yaw_rate: 0.4, tolerance: (0.01, 0.01) }
    }
}

impl BaseController {
    /// Velocity command (vx, vy, wz) in base_link driving `pose` to `goal` (both map frame).
    pub fn command(&self, pose: Pose2, goal: [f64; 3]) -> [f64; 3] {
        let (dx, dy) = (goal[0] - pose.x, goal[1] - pose.y);
        let (s, c) = pose.yaw.sin_cos();
        // Error in base_link.
        let (ex, ey) = (c * dx + s * dy, -s * dx + c * dy);
        let mut v = [self.gain * ex, self.gain * ey];
        let n = v[0].hypot(v[1]);
        if n > self.max_speed {
            v = [v[0] * self.max_speed / n, v[1] * self.max_speed / n];
        }
        let wz = (self.yaw_gain * wrap_angle(goal[2] - pose.yaw)).clamp(-self.max_yaw_rate, self.max_yaw_rate);
        [v[0], v[1], wz]
    }

    pub fn in_place(&self, pose: Pose2, goal: [f64; 3]) -> bool {
        (goal[0] - pose.x).hypot(goal[1] - pose.y) <= self.tolerance.0 && wrap_angle(goal[2] - pose.yaw).abs() <= self.tolerance.1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn converges_on_an_ideal_holonomic_base() {
        let ctl = BaseController::default();
        let goal = [3.0, -0.4, 0.05];
        let mut p = Pose2::new(1.5, 0.2, -0.1);
        let dt = 0.1;
        let mut steps = 0;
        while !ctl.in_place(p, goal) {
            let [vx, vy, wz] = ctl.command(p, goal);
            let (s, c) = p.yaw.sin_cos();
            p = Pose2::new(p.x + dt * (c * vx - s * vy), p.y + dt * (s * vx + c * vy), p.yaw + dt * wz);
            steps += 1;
            assert!(steps < 400, "no convergence: {p:?}");
        }
        assert!(steps > 10);
    }
}
