//! Parallel gripper (Franka Hand figures): the finger gap moves at constant speed toward the
//! commanded gap and stops on an object between the fingers.
//!
//! Figures: maximum gap 0.08 m (2 x 0.04 m finger travel, URDF), continuous grasping force
//! 70 N (Franka Hand datasheet; the URDF finger effort limit); gap speed default 0.1 m/s, the
//! default speed of franka_gripper's GripperCommand action server (franka_ros
//! franka_gripper config `default_speed: 0.1`), within the URDF finger velocity limit.
//!
//! Object: the world FMU reports `grasp_width` (width of the object between the fingers, 0 =
//! none). While closing, the gap cannot go below it: the fingers stall there and squeeze with
//! `min(max_effort, limit)` (max_effort <= 0 means the full limit); the limit is the
//! `max_grip_force` parameter, 70 N by default.

/// Continuous grasping force of the Franka Hand [N].
pub const MAX_FORCE: f64 = 70.0;
/// `reached_goal` tolerance on the gap [m].
pub const GOAL_TOLERANCE: f64 = 1e-3;

#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Gripper {
    pub width: f64,
    /// Gap rate [m/s] over the last update.
    pub velocity: f64,
    pub target: f64,
    pub max_effort: f64,
    pub stalled: bool,
    pub max_width: f64,
    pub speed: f64,
    /// Force limit [N] (default [`MAX_FORCE`]).
    pub limit: f64,
}

impl Gripper {
    pub fn new(width: f64, max_width: f64, speed: f64) -> Gripper {
        Gripper {
            width,
            velocity: 0.0,
            target: width,
            max_effort: 0.0,
            stalled: false,
            max_width,
            speed,
            limit: MAX_FORCE,
        }
    }

    /// Accepts a command or explains why not (the previous one stays active).
    pub fn command(&mut self, position: f64, max_effort: f64) -> Result<(), String> {
        if !(position.is_finite() && (0.0..=self.max_width).contains(&position)) {
            return Err(format!("gripper command position {position} m outside [0, {}] m", self.max_width));
        }
        if max_effort.is_nan() {
            return Err("gripper command max_effort is NaN".into());
        }
        self.target = position;
        self.max_effort = max_effort;
        Ok(())
    }

    /// Grip force when stalled on an object [N].
    pub fn force(&self) -> f64 {
        if !self.stalled {
            0.0
        } else if self.max_effort > 0.0 {
            self.max_effort.min(self.limit)
        } else {
            self.limit
        }
    }

    pub fn reached_goal(&self) -> bool {
        (self.width - self.target).abs() <= GOAL_TOLERANCE
    }

    /// Moves for `dt` with an object of width `grasp_width` (0 = none) between the fingers.
    pub fn update(&mut self, dt: f64, grasp_width: f64) {
        let before = self.width;
        let step = self.speed * dt;
        let mut w = if self.target < self.width {
            (self.width - step).max(self.target)
        } else {
            (self.width + step).min(self.target)
        };
        let object = grasp_width > 0.0 && grasp_width.is_finite();
        // The fingers stop on an object they close onto (never pushed open by one).
        let stop = if object { grasp_width.min(before) } else { 0.0 };
        self.stalled = object && self.target < stop - GOAL_TOLERANCE && w <= stop;
        if object && w < stop {
            w = stop;
        }
        self.width = w;
        self.velocity = if dt > 0.0 { (w - before) / dt } else { 0.0 };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closes_at_speed_and_stalls_on_object() {
        let mut g = Gripper::new(0.08, 0.08, 0.1);
        g.command(0.0, 40.0).unwrap();
        for _ in 0..100 {
            g.update(1e-3, 0.05);
        }
        assert!((g.width - 0.07).abs() < 1e-12, "{}", g.width);
        for _ in 0..1000 {
            g.update(1e-3, 0.05);
        }
        assert_eq!(g.width, 0.05);
        assert!(g.stalled && !g.reached_goal());
        assert_eq!(g.force(), 40.0);
        g.command(0.0, 200.0).unwrap();
        assert_eq!(g.force(), 70.0);
        // Object gone: the fingers close fully.
        for _ in 0..1000 {
            g.update(1e-3, 0.0);
        }
        assert_eq!(g.width, 0.0);
        assert!(!g.stalled && g.reached_goal() && g.force() == 0.0);
        // A lower limit caps every command.
        let mut g = Gripper { limit: 30.0, ..Gripper::new(0.05, 0.08, 0.1) };
        g.command(0.0, 50.0).unwrap();
        g.update(1e-3, 0.05);
        assert!(g.stalled && g.force() == 30.0);
        assert!(g.command(0.09, 10.0).is_err() && g.command(f64::NAN, 10.0).is_err());
    }
}
