//! The model: takes every new trajectory in order, validates it whole (a trajectory that
//! fails a rule is rejected with a warning naming the rule, `status` 2, and the set-point in
//! force goes on), and writes the set-points sampled at the end of each step.
//!
//! Timing follows the Arm FMU: a trajectory starts at its `header.stamp` when that lies
//! ahead, else when it is taken (the start of the step), from the set-point in force then.

use crate::joints;
use crate::ports::*;
use crate::reference::{Reference, Waypoint};
use agrisim_fmi::{InPort, Log, Model, Store, Var};
use agrisim_msgs::trajectory_msgs::JointTrajectory;
use agrisim_msgs::Message;
use agrisim_schedule::to_ns;

#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct JointTrajectoryToScalars {
    /// Derived from the parameters.
    joints: Vec<String>,
    input: Option<InPort>,
    reference: Reference,
    rejected_last: bool,
    count: i32,
}

/// The waypoints of `m` in output order, or the first rule it breaks. Joints beyond the
/// configured ones keep `hold`.
fn waypoints(m: &JointTrajectory, joints: &[String], hold: &[f64; N]) -> Result<Vec<Waypoint>, String> {
    let cols = joints::columns(joints, &m.joint_names)?;
    if m.points.is_empty() {
        return Err("trajectory has no points".into());
    }
    let n = cols.len();
    let place = |v: &[f64]| {
        let mut out = *hold;
        for (k, &i) in cols.iter().enumerate() {
            out[i] = v[k];
        }
        out
    };
    let mut out: Vec<Waypoint> = Vec::with_capacity(m.points.len());
    for (p, pt) in m.points.iter().enumerate() {
        if pt.positions.len() != n {
            return Err(format!("point {p}: {} positions, expected {n}", pt.positions.len()));
        }
        if !pt.velocities.is_empty() && pt.velocities.len() != n {
            return Err(format!("point {p}: {} velocities, expected 0 or {n}", pt.velocities.len()));
        }
        if pt.positions.iter().chain(&pt.velocities).any(|x| !x.is_finite()) {
            return Err(format!("point {p}: a position or velocity is not finite"));
        }
        let d = pt.time_from_start;
        if d.nanosec >= 1_000_000_000 {
            return Err(format!("point {p}: time_from_start.nanosec {} not below 1e9", d.nanosec));
        }
        let t_ns = d.to_nanos();
        if t_ns < 0 || out.last().is_some_and(|w| t_ns <= w.t_ns) {
            return Err(format!(
                "point {p}: time_from_start {} s negative or not after the point before",
                t_ns as f64 * 1e-9
            ));
        }
        // Joints the trajectory does not drive stand still.
        let qd = (!pt.velocities.is_empty()).then(|| {
            let mut v = [0.0; N];
            for (k, &i) in cols.iter().enumerate() {
                v[i] = pt.velocities[k];
            }
            v
        });
        out.push(Waypoint { t_ns, q: place(&pt.positions), qd });
    }
    Ok(out)
}

impl JointTrajectoryToScalars {
    fn take(&mut self, io: &Store, now_ns: i64, log: &mut dyn Log) -> Result<(), String> {
        let msgs = self.input.get_or_insert_with(|| InPort::new(TRAJECTORY, TRAJECTORY_SEQ)).take(io, "trajectory")?;
        for bytes in msgs {
            let msg = JointTrajectory::from_cdr(&bytes).map_err(|e| {
                format!("not a valid trajectory_msgs/msg/JointTrajectory CDR message ({} bytes): {e}", bytes.len())
            });
            let start_ns = msg.as_ref().map_or(now_ns, |m| m.header.stamp.to_nanos().max(now_ns));
            let hold = self.reference.sample(start_ns).q;
            match msg.and_then(|m| waypoints(&m, &self.joints, &hold)) {
                Ok(points) => {
                    self.reference = std::mem::take(&mut self.reference).replaced_by(start_ns, points, now_ns);
                    self.count = self.count.saturating_add(1);
                    self.rejected_last = false;
                }
                Err(e) => {
                    self.rejected_last = true;
                    log.warning(format_args!(
                        "trajectory rejected at t={} s: {e}; the set-points in force go on",
                        now_ns as f64 * 1e-9
                    ));
                }
            }
        }
        Ok(())
    }

    fn write_outputs(&mut self, io: &mut Store, t_ns: i64) {
        let sp = self.reference.sample(t_ns);
        for (i, q) in Q.into_iter().zip(sp.q) {
            io.set_f64(i, q);
        }
        let st = if self.rejected_last {
            status::REJECTED
        } else if self.reference.executing(t_ns) {
            status::EXECUTING
        } else {
            status::HOLDING
        };
        io.set_i32(STATUS, st);
        io.set_i32(COUNT, self.count);
        self.reference.prune(t_ns);
    }
}

impl Model for JointTrajectoryToScalars {
    const NAME: &'static str = "JointTrajectoryToScalars";
    const DESCRIPTION: &'static str =
        "Adapter: trajectory_msgs/JointTrajectory in, joint set-points q1..q7 out (linear or cubic Hermite on simulation time)";
    const VARIABLES: &'static [Var] = VARIABLES;

    agrisim_fmi::whole_state!();

    fn new() -> Self {
        Self::default()
    }

    fn initialize(&mut self, io: &mut Store, start_time: f64, log: &mut dyn Log) -> Result<(), String> {
        let q0 = Q_INIT.map(|i| io.f64(i));
        if q0.iter().any(|q| !q.is_finite()) {
            return Err(format!("initial set-points must be finite, got {q0:?}"));
        }
        *self = JointTrajectoryToScalars {
            joints: joints::parse(io.string(JOINTS))?,
            input: None,
            reference: Reference::hold(q0),
            rejected_last: false,
            count: 0,
        };
        let now = to_ns(start_time);
        self.take(io, now, log)?;
        self.write_outputs(io, now);
        Ok(())
    }

    fn do_step(&mut self, io: &mut Store, t: f64, h: f64, log: &mut dyn Log) -> Result<(), String> {
        self.take(io, to_ns(t), log)?;
        self.write_outputs(io, to_ns(t + h));
        Ok(())
    }
}
