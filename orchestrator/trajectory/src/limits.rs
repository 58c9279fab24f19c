//! Checking a sampled trajectory against per-joint limits before it is sent.
//!
//! Velocity and acceleration are taken from the samples; jerk is the finite difference of
//! acceleration between consecutive samples, so it depends on the sample rate: TOPP-RA
//! (piecewise-constant s̈) has acceleration steps whose finite-difference jerk grows as the
//! step shrinks. Check at the rate the trajectory is sent at.

use std::fmt;

use crate::sampled::Sampled;

/// Per-joint limits. Any of the vectors may be empty to skip that check.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct JointLimits {
    /// Lower and upper position bound per joint.
    pub position: Vec<(f64, f64)>,
    /// |qd| bound per joint.
    pub velocity: Vec<f64>,
    /// |qdd| bound per joint.
    pub acceleration: Vec<f64>,
    /// |d qdd / dt| bound per joint.
    pub jerk: Vec<f64>,
}

impl JointLimits {
    /// The same limits with velocity, acceleration and jerk scaled by the given factors
    /// (position bounds unchanged), e.g. for conservative planning limits.
    pub fn scaled(&self, velocity: f64, acceleration: f64, jerk: f64) -> JointLimits {
        JointLimits {
            position: self.position.clone(),
            velocity: self.velocity.iter().map(|v| v * velocity).collect(),
            acceleration: self.acceleration.iter().map(|v| v * acceleration).collect(),
            jerk: self.jerk.iter().map(|v| v * jerk).collect(),
        }
    }
}

/// Which quantity broke its limit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    Position,
    Velocity,
    Acceleration,
    Jerk,
}

impl fmt::Display for Quantity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Quantity::Position => "position",
            Quantity::Velocity => "velocity",
            Quantity::Acceleration => "acceleration",
            Quantity::Jerk => "jerk",
        })
    }
}

/// The first limit violation in time order (joints in index order at equal time).
#[derive(Debug, Clone, PartialEq)]
pub struct LimitViolation {
    pub joint: usize,
    pub time: f64,
    pub quantity: Quantity,
    /// The offending value (signed); NaN/inf count as violations.
    pub value: f64,
    /// The bound it broke (for position the nearer of lower/upper bound).
    pub limit: f64,
}

/// Why a sampled trajectory is not acceptable.
#[derive(Debug, Clone, PartialEq)]
pub enum CheckError {
    /// Sample arrays of different lengths, wrong joint count, empty, or times not strictly
    /// increasing / not finite.
    Malformed(String),
    /// A joint exceeded a limit.
    Violation(LimitViolation),
}

impl fmt::Display for CheckError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CheckError::Malformed(m) => write!(f, "malformed trajectory: {m}"),
            CheckError::Violation(v) => write!(
                f,
                "joint {} {} limit violated at t = {:.4} s: value {:.6} beyond limit {:.6}",
                v.joint, v.quantity, v.time, v.value, v.limit
            ),
        }
    }
}

impl std::error::Error for CheckError {}

/// Checks every sample of `traj`; a value passes if within its limit enlarged by `rel_tol`
/// (velocity etc.: |v| <= limit·(1 + rel_tol); position: within the range widened by
/// rel_tol·(upper − lower) on each side). Returns the first violation in time.
pub fn check(traj: &Sampled, limits: &JointLimits, rel_tol: f64) -> Result<(), CheckError> {
    let n = traj.t.len();
    if n == 0 {
        return Err(CheckError::Malformed("no samples".into()));
    }
    if traj.q.len() != n || traj.qd.len() != n || traj.qdd.len() != n {
        return Err(CheckError::Malformed(format!(
            "{} times but {} / {} / {} position / velocity / acceleration samples",
            n,
            traj.q.len(),
            traj.qd.len(),
            traj.qdd.len()
        )));
    }
    let dof = traj.q[0].len();
    for (name, len) in [
        ("position", limits.position.len()),
        ("velocity", limits.velocity.len()),
        ("acceleration", limits.acceleration.len()),
        ("jerk", limits.jerk.len()),
    ] {
        if len != 0 && len != dof {
            return Err(CheckError::Malformed(format!("{len} {name} limits for {dof} joints")));
        }
    }
    for k in 0..n {
        if !traj.t[k].is_finite() || (k > 0 && traj.t[k] <= traj.t[k - 1]) {
            return Err(CheckError::Malformed(format!("time {k} ({}) not finite or not increasing", traj.t[k])));
        }
        if traj.q[k].len() != dof || traj.qd[k].len() != dof || traj.qdd[k].len() != dof {
            return Err(CheckError::Malformed(format!("sample {k} does not have {dof} joints")));
        }
    }
    let fail = |joint, k: usize, quantity, value, limit| {
        Err(CheckError::Violation(LimitViolation { joint, time: traj.t[k], quantity, value, limit }))
    };
    let over = |value: f64, limit: f64| value.is_nan() || value.abs() > limit * (1.0 + rel_tol);
    for k in 0..n {
        for j in 0..dof {
            if let Some(&(lo, hi)) = limits.position.get(j) {
                let q = traj.q[k][j];
                let slack = rel_tol * (hi - lo);
                if !(q >= lo - slack && q <= hi + slack) {
                    let limit = if (q - lo).abs() < (q - hi).abs() { lo } else { hi };
                    return fail(j, k, Quantity::Position, q, limit);
                }
            }
            if let Some(&lim) = limits.velocity.get(j) {
                if over(traj.qd[k][j], lim) {
                    return fail(j, k, Quantity::Velocity, traj.qd[k][j], lim);
                }
            }
            if let Some(&lim) = limits.acceleration.get(j) {
                if over(traj.qdd[k][j], lim) {
                    return fail(j, k, Quantity::Acceleration, traj.qdd[k][j], lim);
                }
            }
            if k > 0 {
                if let Some(&lim) = limits.jerk.get(j) {
                    let jerk = (traj.qdd[k][j] - traj.qdd[k - 1][j]) / (traj.t[k] - traj.t[k - 1]);
                    if over(jerk, lim) {
                        return fail(j, k, Quantity::Jerk, jerk, lim);
                    }
                }
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp() -> Sampled {
        // One joint, constant acceleration 1 from rest, 10 samples at 0.1 s.
        let t: Vec<f64> = (0..10).map(|k| k as f64 * 0.1).collect();
        Sampled {
            q: t.iter().map(|t| vec![0.5 * t * t]).collect(),
            qd: t.iter().map(|t| vec![*t]).collect(),
            qdd: t.iter().map(|_| vec![1.0]).collect(),
            t,
        }
    }

    #[test]
    fn reports_first_violation_with_details() {
        let lim = JointLimits {
            position: vec![(-1.0, 1.0)],
            velocity: vec![0.5],
            acceleration: vec![2.0],
            jerk: vec![100.0],
        };
        assert_eq!(
            check(&ramp(), &lim, 1e-6),
            Err(CheckError::Violation(LimitViolation {
                joint: 0,
                time: 0.6000000000000001,
                quantity: Quantity::Velocity,
                value: 0.6000000000000001,
                limit: 0.5
            }))
        );
        let ok = JointLimits { velocity: vec![0.9], ..lim.clone() };
        assert_eq!(check(&ramp(), &ok, 0.0), Ok(()));
        // Jerk: an acceleration step of 1 over 0.1 s is 10 rad/s³.
        let mut s = ramp();
        s.qdd[5][0] = 2.0;
        let tight = JointLimits { jerk: vec![5.0], ..ok.clone() };
        let e = check(&s, &tight, 0.0).unwrap_err();
        assert!(matches!(e, CheckError::Violation(LimitViolation { quantity: Quantity::Jerk, .. })));
        assert!(e.to_string().contains("joint 0 jerk limit violated at t = 0.5000 s"), "{e}");
        // NaN is a violation, non-monotonic time is malformed.
        let mut s = ramp();
        s.q[3][0] = f64::NAN;
        assert!(matches!(
            check(&s, &ok, 0.0),
            Err(CheckError::Violation(LimitViolation { quantity: Quantity::Position, .. }))
        ));
        let mut s = ramp();
        s.t[4] = s.t[3];
        assert!(matches!(check(&s, &ok, 0.0), Err(CheckError::Malformed(_))));
    }
}
