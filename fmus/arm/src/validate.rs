//! Validation of an incoming trajectory_msgs/JointTrajectory, following ROS 2
//! joint_trajectory_controller's acceptance rules where they apply to one 7-DoF arm, plus
//! limit checks the controller leaves to the planner. A trajectory failing any rule is
//! rejected whole with one human-readable reason (the first rule it breaks).
//!
//! Rules, in checking order:
//! 1. the bytes decode as CDR JointTrajectory;
//! 2. `joint_names` are exactly the arm's 7 joints, any order: no unknown name, no
//!    duplicate, none missing;
//! 3. at least one point;
//! 4. per point: 7 positions; velocities empty or 7; accelerations empty or 7 and only with
//!    velocities (`positions[, velocities[, accelerations]]`, JointTrajectoryPoint.msg);
//!    effort empty (the arm is position-controlled); all values finite;
//! 5. `time_from_start`: nanosec < 1e9, not negative, strictly increasing;
//! 6. positions within the URDF limits, velocities within the URDF velocity limits;
//! 7. the mean velocity each segment implies (from the current commanded position to point 0,
//!    then between points) within the velocity limits. A point at time 0 therefore has to
//!    equal the current commanded position (within [`START_TOLERANCE`]).

use crate::description::{ArmDescription, N};
use agrisim_msgs::trajectory_msgs::JointTrajectory;
use agrisim_msgs::Message;

/// How far a time-0 first point may be from the current commanded position [rad].
pub const START_TOLERANCE: f64 = 1e-3;

/// One validated waypoint, reordered to the arm's joint order.
#[derive(Clone, Debug, PartialEq)]
pub struct Waypoint {
    /// Time from the trajectory start [ns].
    pub t_ns: i64,
    pub q: [f64; N],
    pub qd: Option<[f64; N]>,
    pub qdd: Option<[f64; N]>,
}

fn fmt_t(ns: i64) -> String {
    format!("{} s", ns as f64 * 1e-9)
}

/// Decodes and validates `bytes`; `q_cmd` is the commanded position at arrival.
pub fn validate(bytes: &[u8], arm: &ArmDescription, q_cmd: &[f64; N]) -> Result<Vec<Waypoint>, String> {
    check(&decode(bytes)?, arm, q_cmd)
}

/// The trajectory message in `bytes`.
pub fn decode(bytes: &[u8]) -> Result<JointTrajectory, String> {
    JointTrajectory::from_cdr(bytes).map_err(|e| {
        format!("not a valid trajectory_msgs/msg/JointTrajectory CDR message ({} bytes): {e}", bytes.len())
    })
}

/// Validates a decoded trajectory.
pub fn check(msg: &JointTrajectory, arm: &ArmDescription, q_cmd: &[f64; N]) -> Result<Vec<Waypoint>, String> {
    // 2. names -> permutation: col[k] = arm joint index of message column k.
    let mut col = Vec::with_capacity(msg.joint_names.len());
    let mut seen = [false; N];
    for name in &msg.joint_names {
        let Some(i) = arm.index_of(name) else {
            return Err(format!("unknown joint name {name:?} (expected the {N} joints {}_joint1..7)", arm.side));
        };
        if seen[i] {
            return Err(format!("duplicate joint name {name:?}"));
        }
        seen[i] = true;
        col.push(i);
    }
    if let Some(i) = seen.iter().position(|s| !s) {
        return Err(format!(
            "joint {} missing from joint_names ({} of {N} given)",
            arm.joint_names[i],
            msg.joint_names.len()
        ));
    }
    // 3.
    if msg.points.is_empty() {
        return Err("trajectory has no points".into());
    }
    let reorder = |v: &[f64]| -> [f64; N] {
        let mut out = [0.0; N];
        for (k, &i) in col.iter().enumerate() {
            out[i] = v[k];
        }
        out
    };
    let mut out: Vec<Waypoint> = Vec::with_capacity(msg.points.len());
    for (p, pt) in msg.points.iter().enumerate() {
        // 4. dimensions and finiteness.
        if pt.positions.len() != N {
            return Err(format!("point {p}: {} positions, expected {N}", pt.positions.len()));
        }
        for (field, v) in [("velocities", &pt.velocities), ("accelerations", &pt.accelerations)] {
            if !v.is_empty() && v.len() != N {
                return Err(format!("point {p}: {} {field}, expected 0 or {N}", v.len()));
            }
        }
        if !pt.accelerations.is_empty() && pt.velocities.is_empty() {
            return Err(format!("point {p}: accelerations given without velocities"));
        }
        if !pt.effort.is_empty() {
            return Err(format!(
                "point {p}: {} effort values; effort commands are not supported (position-controlled arm)",
                pt.effort.len()
            ));
        }
        for (field, v) in
            [("positions", &pt.positions), ("velocities", &pt.velocities), ("accelerations", &pt.accelerations)]
        {
            if let Some(k) = v.iter().position(|x| !x.is_finite()) {
                return Err(format!("point {p}: {field}[{k}] ({}) is {}", msg.joint_names[k], v[k]));
            }
        }
        // 5. time.
        let d = pt.time_from_start;
        if d.nanosec >= 1_000_000_000 {
            return Err(format!("point {p}: time_from_start.nanosec {} not below 1e9", d.nanosec));
        }
        let t_ns = d.to_nanos();
        if t_ns < 0 {
            return Err(format!("point {p}: negative time_from_start {}", fmt_t(t_ns)));
        }
        if let Some(prev) = out.last() {
            if t_ns <= prev.t_ns {
                return Err(format!(
                    "point {p}: time_from_start {} not after point {} ({})",
                    fmt_t(t_ns),
                    p - 1,
                    fmt_t(prev.t_ns)
                ));
            }
        }
        // 6. limits.
        let q = reorder(&pt.positions);
        for i in 0..N {
            let l = arm.limits[i];
            if !l.contains(q[i]) {
                return Err(format!(
                    "point {p}: {} position {} rad outside limits [{}, {}]",
                    arm.joint_names[i], q[i], l.lower, l.upper
                ));
            }
        }
        let qd = (!pt.velocities.is_empty()).then(|| reorder(&pt.velocities));
        if let Some(v) = qd {
            for i in 0..N {
                if v[i].abs() > arm.limits[i].velocity {
                    return Err(format!(
                        "point {p}: {} velocity {} rad/s beyond limit {}",
                        arm.joint_names[i], v[i], arm.limits[i].velocity
                    ));
                }
            }
        }
        // 7. implied mean velocity of the segment ending here.
        let (q_prev, t_prev) = match out.last() {
            Some(w) => (w.q, w.t_ns),
            None => (*q_cmd, 0),
        };
        let dt = (t_ns - t_prev) as f64 * 1e-9;
        for i in 0..N {
            let dq = (q[i] - q_prev[i]).abs();
            if dt == 0.0 {
                if dq > START_TOLERANCE {
                    return Err(format!(
                        "point 0 at time 0: {} is {} rad from the current commanded position {} (a jump)",
                        arm.joint_names[i], q[i], q_prev[i]
                    ));
                }
            } else if dq / dt > arm.limits[i].velocity {
                let from = if p == 0 { "current position".to_string() } else { format!("point {}", p - 1) };
                return Err(format!(
                    "point {p}: {} moves {dq} rad in {dt} s from {from} ({} rad/s beyond limit {})",
                    arm.joint_names[i],
                    dq / dt,
                    arm.limits[i].velocity
                ));
            }
        }
        let qdd = (!pt.accelerations.is_empty()).then(|| reorder(&pt.accelerations));
        out.push(Waypoint { t_ns, q, qd, qdd });
    }
    Ok(out)
}
