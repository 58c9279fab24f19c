//! The two ways the harvest task turns motion requests into checked, sampled trajectories:
//! planner waypoints → path → TOPP-RA, and state → state with jerk limits (ruckig). Both end
//! sampled at the send period and checked against the hardware limits, so nothing that fails
//! the check is ever returned.

use std::fmt;

use crate::blended::BlendedPolylinePath;
use crate::jerk_limited::{self, JerkLimitedError, JointState, KinematicLimits};
use crate::limits::{check, CheckError, JointLimits};
use crate::panda;
use crate::path::{JointPath, PathError};
use crate::sampled::{sample, Sampled};
use crate::spline::{CubicSplinePath, PathParam};
use crate::toppra::{parameterize_within_limits, ToppraError, ToppraProblem};

/// Geometric path through the planner's waypoints.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PathShape {
    /// Not-a-knot cubic spline (smooth, but may swing away from the collision-checked segments).
    Spline(PathParam),
    /// The collision-checked polyline with corner blends of this joint-space radius.
    Blended { radius: f64 },
}

/// Limits and send period.
#[derive(Debug, Clone, PartialEq)]
pub struct TimingConfig {
    /// Limits the motion is planned with (velocity and acceleration for TOPP-RA; jerk too for
    /// ruckig). Position bounds are not used for planning.
    pub planning: JointLimits,
    /// Limits every sample is checked against (position, velocity, acceleration, and jerk by
    /// finite differences at `dt`); empty vectors skip a quantity.
    pub hardware: JointLimits,
    /// Send period, s: sample spacing of the result.
    pub dt: f64,
    pub shape: PathShape,
}

impl TimingConfig {
    /// Panda arm: conservative planning limits, published limits for the check, blended path.
    pub fn panda(dt: f64) -> Self {
        TimingConfig {
            planning: panda::planning_limits(),
            hardware: panda::limits(),
            dt,
            shape: PathShape::Blended { radius: 0.1 },
        }
    }
}

/// Why no trajectory was produced.
#[derive(Debug, Clone, PartialEq)]
pub enum PlanError {
    Path(PathError),
    Toppra(ToppraError),
    JerkLimited(JerkLimitedError),
    /// The sampled result broke a hardware limit (e.g. a spline overshooting a joint range).
    Check(CheckError),
}

impl fmt::Display for PlanError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PlanError::Path(e) => e.fmt(f),
            PlanError::Toppra(e) => e.fmt(f),
            PlanError::JerkLimited(e) => e.fmt(f),
            PlanError::Check(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for PlanError {}

/// Relative tolerance of the final check (numerical noise only).
const CHECK_TOL: f64 = 1e-6;
/// Re-solves allowed to pull between-gridpoint overshoot under the planning limits.
const ROUNDS: usize = 8;

/// Waypoints (joint vectors, start first) → time-optimal rest-to-rest trajectory sampled at
/// `cfg.dt`, within the planning limits at every sample and checked against `cfg.hardware`.
pub fn time_waypoints(waypoints: &[Vec<f64>], cfg: &TimingConfig) -> Result<Sampled, PlanError> {
    match cfg.shape {
        PathShape::Spline(param) => {
            time_path(CubicSplinePath::through_waypoints(waypoints, param).map_err(PlanError::Path)?, cfg)
        }
        PathShape::Blended { radius } => {
            time_path(BlendedPolylinePath::new(waypoints, radius).map_err(PlanError::Path)?, cfg)
        }
    }
}

/// Any path → TOPP-RA → samples at `cfg.dt` → hardware check.
pub fn time_path<P: JointPath + Clone>(path: P, cfg: &TimingConfig) -> Result<Sampled, PlanError> {
    let problem = ToppraProblem::new(cfg.planning.velocity.clone(), cfg.planning.acceleration.clone());
    let traj = parameterize_within_limits(path, &problem, cfg.dt, CHECK_TOL, ROUNDS).map_err(PlanError::Toppra)?;
    let samples = sample(&traj, cfg.dt);
    check(&samples, &cfg.hardware, CHECK_TOL).map_err(PlanError::Check)?;
    Ok(samples)
}

/// Jerk-limited, time-synchronized motion from `start` to `goal` (ruckig) with the planning
/// velocity, acceleration and jerk limits, sampled at `cfg.dt` and checked against `cfg.hardware`.
pub fn time_state_to_state(start: &JointState, goal: &JointState, cfg: &TimingConfig) -> Result<Sampled, PlanError> {
    let lim = KinematicLimits {
        velocity: cfg.planning.velocity.clone(),
        acceleration: cfg.planning.acceleration.clone(),
        jerk: cfg.planning.jerk.clone(),
    };
    let motion = jerk_limited::plan(start, goal, &lim).map_err(PlanError::JerkLimited)?;
    let samples = sample(&motion, cfg.dt);
    check(&samples, &cfg.hardware, CHECK_TOL).map_err(PlanError::Check)?;
    Ok(samples)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::limits::Quantity;

    #[test]
    fn panda_waypoints_and_state_to_state_give_checked_samples() {
        let wps = vec![
            vec![0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785],
            vec![0.5, -0.3, 0.2, -2.0, 0.1, 1.9, 0.5],
            vec![1.0, 0.2, -0.3, -1.5, 0.4, 2.2, 0.0],
        ];
        for shape in [PathShape::Blended { radius: 0.1 }, PathShape::Spline(PathParam::ChordLength)] {
            let cfg = TimingConfig { shape, ..TimingConfig::panda(0.05) };
            let s = time_waypoints(&wps, &cfg).unwrap();
            assert!(s.t.windows(2).all(|w| w[1] > w[0] && w[1] - w[0] <= 0.05 + 1e-12));
            assert_eq!(s.q[0], wps[0]);
            assert!(s.q.last().unwrap().iter().zip(&wps[2]).all(|(a, b)| (a - b).abs() < 1e-9));
            check(&s, &cfg.planning.scaled(1.0, 1.0, 1e6), 1e-6).unwrap();
        }
        let cfg = TimingConfig::panda(0.01);
        let s = time_state_to_state(&JointState::at_rest(wps[0].clone()), &JointState::at_rest(wps[2].clone()), &cfg)
            .unwrap();
        check(&s, &cfg.planning, 1e-6).unwrap();
        // A target outside joint 4's range is caught by the hardware check.
        let mut bad = wps[2].clone();
        bad[3] = 0.3;
        let e = time_state_to_state(&JointState::at_rest(wps[0].clone()), &JointState::at_rest(bad), &cfg).unwrap_err();
        assert!(
            matches!(e, PlanError::Check(CheckError::Violation(ref v)) if v.joint == 3 && v.quantity == Quantity::Position),
            "{e}"
        );
    }

    #[test]
    fn random_panda_waypoint_paths_all_time_and_check() {
        let mut state = 99u64;
        let mut uniform = move || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut total_time = 0.0;
        for case in 0..100 {
            let n = 2 + (uniform() * 6.0) as usize;
            // Inside the Panda ranges with a 5 % margin (blends and splines may round corners).
            let wps: Vec<Vec<f64>> = (0..n)
                .map(|_| {
                    (0..7)
                        .map(|j| {
                            let (lo, hi) = (panda::POSITION_MIN[j], panda::POSITION_MAX[j]);
                            let m = 0.05 * (hi - lo);
                            lo + m + (hi - lo - 2.0 * m) * uniform()
                        })
                        .collect()
                })
                .collect();
            let cfg = TimingConfig {
                shape: PathShape::Blended { radius: 0.05 + 0.2 * uniform() },
                ..TimingConfig::panda(0.05)
            };
            let s = time_waypoints(&wps, &cfg).unwrap_or_else(|e| panic!("case {case}: {e}"));
            check(&s, &cfg.planning.scaled(1.0, 1.0, 1e6), 1e-6).unwrap();
            assert!(s.q.last().unwrap().iter().zip(&wps[n - 1]).all(|(a, b)| (a - b).abs() < 1e-9));
            total_time += s.t.last().unwrap();
        }
        assert!(total_time > 100.0 * 0.5);
    }
}
