//! The base's recent path, so each point is cast from where the robot was when it was
//! measured (a frame lasts 0.1 s; at 1 m/s and 0.5 rad/s that is 10 cm and 3 deg of motion).
//!
//! Poses arrive at communication points. Between two of them the pose is interpolated
//! linearly (yaw along the shorter way); after the latest one it is held, since the chassis'
//! pose at the end of the current step is not known yet: points of the last step lag by up to
//! one step (2 cm at 1 m/s with the 0.02 s step).

use agrisim_math::Pose2;
use std::collections::VecDeque;

#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Trajectory {
    /// (time, pose) in time order; yaw unwrapped so neighbours differ by less than pi.
    samples: VecDeque<(f64, Pose2)>,
}

impl Trajectory {
    /// Records the pose at `time`, dropping samples older than `keep` seconds before it (one
    /// older sample is kept so the window stays interpolable).
    pub fn push(&mut self, time: f64, mut pose: Pose2, keep: f64) {
        while self.samples.back().is_some_and(|(t, _)| *t >= time) {
            self.samples.pop_back();
        }
        if let Some((_, last)) = self.samples.back() {
            let d =
                (pose.yaw - last.yaw + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
            pose.yaw = last.yaw + d;
        }
        self.samples.push_back((time, pose));
        while self.samples.len() > 2 && self.samples[1].0 < time - keep {
            self.samples.pop_front();
        }
    }

    /// The pose at `time`: interpolated inside the recorded window, held outside it.
    pub fn at(&self, time: f64) -> Pose2 {
        let (Some(&(t0, first)), Some(&(t1, last))) = (self.samples.front(), self.samples.back()) else {
            return Pose2::default();
        };
        if time <= t0 {
            return first;
        }
        if time >= t1 {
            return last;
        }
        let k = self.samples.partition_point(|(t, _)| *t <= time);
        let ((ta, a), (tb, b)) = (self.samples[k - 1], self.samples[k]);
        let f = (time - ta) / (tb - ta);
        Pose2 { x: a.x + f * (b.x - a.x), y: a.y + f * (b.y - a.y), yaw: a.yaw + f * (b.yaw - a.yaw) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolates_holds_and_unwraps_yaw() {
        let mut tr = Trajectory::default();
        tr.push(0.0, Pose2 { x: 0.0, y: 0.0, yaw: 3.1 }, 1.0);
        tr.push(0.1, Pose2 { x: 1.0, y: -1.0, yaw: -3.1 }, 1.0);
        let p = tr.at(0.05);
        assert!((p.x - 0.5).abs() < 1e-12 && (p.y + 0.5).abs() < 1e-12);
        // 3.1 -> -3.1 is a small turn through pi, not a full turn back.
        assert!((p.yaw - std::f64::consts::PI).abs() < 1e-9, "{}", p.yaw);
        assert_eq!(tr.at(0.2).x, 1.0);
        assert_eq!(tr.at(-1.0).x, 0.0);
        for k in 2..100 {
            tr.push(k as f64 * 0.1, Pose2::default(), 0.25);
        }
        assert!(tr.samples.len() <= 5);
    }
}
