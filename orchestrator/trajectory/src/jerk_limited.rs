//! Jerk-limited, time-synchronized state-to-state motions (ruckig).
//!
//! Uses `rsruckig`, the pure-Rust port of ruckig (Berscheid & Kröger, RSS 2021), rather than
//! the official `ruckig` crate: the official crate 0.19 is a cxx binding that compiles the C++
//! library at build time (C++ toolchain in every build, C++ exceptions at the boundary), while
//! rsruckig is plain Rust, returns errors as `Result`, and agrees with the official ruckig
//! (its Python package) on durations — python/test_ruckig_crosscheck.py checks that.
//! All joints finish together (time synchronization); limits are symmetric per joint.

use std::fmt;
use std::panic::{catch_unwind, AssertUnwindSafe};

use rsruckig::prelude::{DataArrayOrVec, InputParameter, Ruckig, RuckigResult, ThrowErrorHandler};

use crate::sampled::Trajectory;

/// Position, velocity and acceleration of every joint.
#[derive(Debug, Clone, PartialEq)]
pub struct JointState {
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
}

impl JointState {
    /// At rest at `q`.
    pub fn at_rest(q: Vec<f64>) -> Self {
        let n = q.len();
        JointState { q, qd: vec![0.0; n], qdd: vec![0.0; n] }
    }
}

/// Symmetric kinematic limits per joint.
#[derive(Debug, Clone, PartialEq)]
pub struct KinematicLimits {
    pub velocity: Vec<f64>,
    pub acceleration: Vec<f64>,
    pub jerk: Vec<f64>,
}

/// Why no motion was produced.
#[derive(Debug, Clone, PartialEq)]
pub enum JerkLimitedError {
    /// Inconsistent joint counts, non-finite values or non-positive limits.
    BadInput(String),
    /// ruckig rejected or failed the problem (its message).
    Ruckig(String),
}

impl fmt::Display for JerkLimitedError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            JerkLimitedError::BadInput(m) => write!(f, "jerk-limited motion: bad input: {m}"),
            JerkLimitedError::Ruckig(m) => write!(f, "jerk-limited motion: ruckig: {m}"),
        }
    }
}

impl std::error::Error for JerkLimitedError {}

/// A planned jerk-limited motion, evaluable at any time.
pub struct JerkLimitedMotion {
    dof: usize,
    traj: rsruckig::prelude::Trajectory<0>,
}

impl fmt::Debug for JerkLimitedMotion {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("JerkLimitedMotion")
            .field("dof", &self.dof)
            .field("duration", &self.traj.get_duration())
            .finish()
    }
}

/// Time-optimal (for the slowest joint) synchronized motion from `start` to `goal`.
pub fn plan(
    start: &JointState,
    goal: &JointState,
    limits: &KinematicLimits,
) -> Result<JerkLimitedMotion, JerkLimitedError> {
    let dof = start.q.len();
    let vectors: [(&str, &Vec<f64>); 9] = [
        ("start q", &start.q),
        ("start qd", &start.qd),
        ("start qdd", &start.qdd),
        ("goal q", &goal.q),
        ("goal qd", &goal.qd),
        ("goal qdd", &goal.qdd),
        ("velocity limit", &limits.velocity),
        ("acceleration limit", &limits.acceleration),
        ("jerk limit", &limits.jerk),
    ];
    if dof == 0 {
        return Err(JerkLimitedError::BadInput("zero joints".into()));
    }
    for (name, v) in vectors {
        if v.len() != dof {
            return Err(JerkLimitedError::BadInput(format!("{name} has {} entries, expected {dof}", v.len())));
        }
        if v.iter().any(|x| !x.is_finite()) {
            return Err(JerkLimitedError::BadInput(format!("{name} is not finite")));
        }
    }
    for (name, v) in &vectors[6..] {
        if v.iter().any(|x| *x <= 0.0) {
            return Err(JerkLimitedError::BadInput(format!("{name} must be positive")));
        }
    }
    let mut input = InputParameter::<0>::new(Some(dof));
    for j in 0..dof {
        input.current_position[j] = start.q[j];
        input.current_velocity[j] = start.qd[j];
        input.current_acceleration[j] = start.qdd[j];
        input.target_position[j] = goal.q[j];
        input.target_velocity[j] = goal.qd[j];
        input.target_acceleration[j] = goal.qdd[j];
        input.max_velocity[j] = limits.velocity[j];
        input.max_acceleration[j] = limits.acceleration[j];
        input.max_jerk[j] = limits.jerk[j];
    }
    // The control cycle only matters for online stepping, not for `calculate`.
    let result = catch_unwind(AssertUnwindSafe(|| {
        let mut otg = Ruckig::<0, ThrowErrorHandler>::new(Some(dof), 0.001);
        let mut traj = rsruckig::prelude::Trajectory::<0>::new(Some(dof));
        otg.calculate(&input, &mut traj).map(|r| (r, traj))
    }));
    match result {
        Err(_) => Err(JerkLimitedError::Ruckig("panicked".into())),
        Ok(Err(e)) => Err(JerkLimitedError::Ruckig(e.to_string())),
        Ok(Ok((RuckigResult::Working | RuckigResult::Finished, traj))) => Ok(JerkLimitedMotion { dof, traj }),
        Ok(Ok((r, _))) => Err(JerkLimitedError::Ruckig(format!("{r:?}"))),
    }
}

impl Trajectory for JerkLimitedMotion {
    fn dof(&self) -> usize {
        self.dof
    }

    fn duration(&self) -> f64 {
        self.traj.get_duration()
    }

    fn state_at(&self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]) {
        let t = t.clamp(0.0, self.duration());
        let mut p = DataArrayOrVec::<f64, 0>::new(Some(self.dof), 0.0);
        let mut v = DataArrayOrVec::<f64, 0>::new(Some(self.dof), 0.0);
        let mut a = DataArrayOrVec::<f64, 0>::new(Some(self.dof), 0.0);
        let mut section = None;
        self.traj.at_time(t, &mut Some(&mut p), &mut Some(&mut v), &mut Some(&mut a), &mut None, &mut section);
        for j in 0..self.dof {
            q[j] = p[j];
            qd[j] = v[j];
            qdd[j] = a[j];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::limits::{check, JointLimits};
    use crate::sampled::sample;

    #[test]
    fn single_joint_rest_to_rest_matches_closed_form() {
        // Long move reaching all three limits: T = d/v + v/a + a/j (jerk-limited trapezoid).
        let (d, v, a, j) = (2.0, 1.0, 4.0, 40.0);
        let m = plan(
            &JointState::at_rest(vec![0.0]),
            &JointState::at_rest(vec![d]),
            &KinematicLimits { velocity: vec![v], acceleration: vec![a], jerk: vec![j] },
        )
        .unwrap();
        let want = d / v + v / a + a / j;
        assert!((m.duration() - want).abs() < 1e-9, "{} vs {want}", m.duration());
    }

    #[test]
    fn synchronized_motion_reaches_goal_within_limits() {
        let lim = KinematicLimits {
            velocity: vec![1.0, 2.0, 0.5],
            acceleration: vec![3.0, 5.0, 2.0],
            jerk: vec![30.0, 50.0, 20.0],
        };
        let start = JointState { q: vec![0.0, 0.3, -0.2], qd: vec![0.2, 0.0, -0.1], qdd: vec![0.0, 0.5, 0.0] };
        let goal = JointState::at_rest(vec![1.0, -0.7, 0.4]);
        let m = plan(&start, &goal, &lim).unwrap();
        let s = sample(&m, 0.001);
        let end = s.q.last().unwrap();
        assert!(end.iter().zip(&goal.q).all(|(a, b)| (a - b).abs() < 1e-9));
        assert!(s.q[0].iter().zip(&start.q).all(|(a, b)| (a - b).abs() < 1e-12));
        let jl = JointLimits {
            position: vec![],
            velocity: lim.velocity.clone(),
            acceleration: lim.acceleration.clone(),
            jerk: lim.jerk.clone(),
        };
        check(&s, &jl, 1e-6).unwrap();
        assert!(plan(&start, &goal, &KinematicLimits { jerk: vec![1.0, 0.0, 1.0], ..lim.clone() }).is_err());
    }
}
