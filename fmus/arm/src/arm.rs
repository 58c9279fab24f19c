//! The `Arm` model: trajectory and gripper command intake, the 1 kHz control loop over each
//! communication step, status and message outputs.

use crate::description::{ArmDescription, N};
use crate::dynamics::{self, JointParams, ModelMismatch, CONTROL_PERIOD_NS, COULOMB, DEFAULT_KD, DEFAULT_KP, VISCOUS};
use crate::gripper::Gripper;
use crate::inertia::joint_inertia;
use crate::ports::*;
use crate::reference::{Reference, Setpoint};
use crate::validate::{check, decode};
use agrisim_fmi::{InPort, Log, Model, OutPort, Store, Var};
use agrisim_math::Rng;
use agrisim_msgs::agrisim::{GripperState, TrajectoryStatus};
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::control_msgs::GripperCommand;
use agrisim_msgs::sensor_msgs::JointState;
use agrisim_msgs::std_msgs::Header;
use agrisim_msgs::Message;
use agrisim_schedule::{to_ns, Schedule};

/// Franka's "ready" pose (franka_ros / MoveIt panda config), inside every joint's limits.
pub const READY_POSE: [f64; N] = [
    0.0,
    -std::f64::consts::FRAC_PI_4,
    0.0,
    -3.0 * std::f64::consts::FRAC_PI_4,
    0.0,
    std::f64::consts::FRAC_PI_2,
    std::f64::consts::FRAC_PI_4,
];

/// Most control periods simulated in one communication step (100 s). A longer step holds
/// the arm for the excess and simulates only its last part, so an absurd step stays cheap.
pub const MAX_SUBSTEPS: i64 = 100_000;

/// Longest rejection reason a TrajectoryStatus carries [bytes]; a longer one (it can quote an
/// arbitrarily long joint name from the rejected message) is cut, so the message stays within
/// the trajectory_status port's maxSize.
pub const MAX_REASON: usize = 1024;

/// `text` cut to at most `max` bytes at a character boundary, "..." marking a cut.
fn clip(text: &str, max: usize) -> String {
    if text.len() <= max {
        return text.to_string();
    }
    let mut end = max - 3;
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    format!("{}...", &text[..end])
}

/// Executor state as in TrajectoryStatus (REJECTED is a flag on top of it).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Exec {
    #[default]
    Idle,
    Executing,
    Succeeded,
}

/// Tracking error over one trajectory.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ErrorStats {
    pub sum_sq: f64,
    pub samples: u64,
    pub max: f64,
}

impl ErrorStats {
    pub fn rms(&self) -> f64 {
        if self.samples == 0 {
            0.0
        } else {
            (self.sum_sq / (self.samples as f64 * N as f64)).sqrt()
        }
    }
}

/// Data sampled at a joint_states instant.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
struct Snapshot {
    stamp_ns: i64,
    joints: dynamics::JointState,
    gripper: Gripper,
}

#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Arm {
    /// Derived from the parameters: rebuilt, not serialized.
    #[serde(skip)]
    arm: Option<ArmDescription>,
    #[serde(skip)]
    params: [Option<JointParams>; N],
    mismatch: ModelMismatch,
    pub state: dynamics::JointState,
    pub reference: Reference,
    pub gripper: Gripper,
    exec: Exec,
    rejected_last: bool,
    pub accepted: u64,
    pub rejected: u64,
    pub reason: String,
    pub errors: ErrorStats,
    ports: Option<Ports>,
    window_ns: i64,
    now_ns: i64,
    js_schedule: Schedule,
    status_schedule: Schedule,
    snapshot: Option<Snapshot>,
    last_status: Option<(u8, u64, u64)>,
    noise: f64,
    rng: Rng,
}

/// The arm's message ports.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
struct Ports {
    trajectory: InPort,
    gripper_command: InPort,
    joint_states: OutPort,
    trajectory_status: OutPort,
    gripper_state: OutPort,
}

impl Ports {
    fn new() -> Ports {
        Ports {
            trajectory: InPort::new(TRAJECTORY, TRAJECTORY_SEQ),
            gripper_command: InPort::new(GRIPPER_COMMAND, GRIPPER_COMMAND_SEQ),
            joint_states: OutPort::new(JOINT_STATES, JOINT_STATES_SEQ),
            trajectory_status: OutPort::new(TRAJECTORY_STATUS, TRAJECTORY_STATUS_SEQ),
            gripper_state: OutPort::new(GRIPPER_STATE, GRIPPER_STATE_SEQ),
        }
    }
}

/// Parses "a,b,..." into exactly 7 finite numbers; empty -> `default`.
pub fn parse_list(text: &str, default: [f64; N], what: &str) -> Result<[f64; N], String> {
    if text.trim().is_empty() {
        return Ok(default);
    }
    let vals: Vec<f64> = text
        .split(',')
        .map(|s| s.trim().parse::<f64>().map_err(|e| format!("parameter {what}: {s:?} is not a number ({e})")))
        .collect::<Result<_, _>>()?;
    if vals.len() != N || vals.iter().any(|v| !v.is_finite()) {
        return Err(format!("parameter {what} must be {N} finite comma-separated numbers, got {text:?}"));
    }
    Ok(std::array::from_fn(|i| vals[i]))
}

impl Arm {
    pub fn description(&self) -> &ArmDescription {
        self.arm.as_ref().expect("initialized")
    }

    fn joint_params(&self) -> [JointParams; N] {
        std::array::from_fn(|i| self.params[i].expect("initialized"))
    }

    /// TrajectoryStatus state code.
    pub fn state_code(&self) -> u8 {
        if self.rejected_last {
            TrajectoryStatus::REJECTED
        } else {
            match self.exec {
                Exec::Idle => TrajectoryStatus::IDLE,
                Exec::Executing => TrajectoryStatus::EXECUTING,
                Exec::Succeeded => TrajectoryStatus::SUCCEEDED,
            }
        }
    }

    fn ports(&mut self) -> &mut Ports {
        self.ports.get_or_insert_with(Ports::new)
    }

    /// Takes the new trajectories at `t_ns`, in order (each replaces the one before).
    fn poll_trajectory(&mut self, io: &Store, t_ns: i64, log: &mut dyn Log) -> Result<(), String> {
        for bytes in self.ports().trajectory.take(io, "trajectory")? {
            self.take_trajectory(&bytes, t_ns, log);
        }
        Ok(())
    }

    /// Takes one trajectory message received at `t_ns`. It starts at its `header.stamp` when
    /// that lies ahead (a planner's result that becomes valid later), else at once; the
    /// trajectory it replaces runs until then.
    fn take_trajectory(&mut self, bytes: &[u8], t_ns: i64, log: &mut dyn Log) {
        let msg = decode(bytes);
        let start_ns = msg.as_ref().map_or(t_ns, |m| m.header.stamp.to_nanos().max(t_ns));
        let from: Setpoint = self.reference.sample(start_ns);
        match msg.and_then(|m| check(&m, self.description(), &from.q)) {
            Ok(points) => {
                let old = std::mem::replace(&mut self.reference, Reference::hold(from.q));
                self.reference = Reference::new(start_ns, &from, &points).after(old, t_ns);
                self.accepted += 1;
                self.rejected_last = false;
                self.exec = Exec::Executing;
                self.errors = ErrorStats::default();
                log.info(format_args!(
                    "{} arm: trajectory {} accepted at t={} s, starting at {} s ({} points, {} s)",
                    self.description().side,
                    self.accepted,
                    t_ns as f64 * 1e-9,
                    start_ns as f64 * 1e-9,
                    points.len(),
                    points.last().map_or(0, |p| p.t_ns) as f64 * 1e-9
                ));
            }
            Err(reason) => {
                self.rejected += 1;
                self.rejected_last = true;
                log.warning(format_args!(
                    "{} arm: trajectory {} rejected at t={} s: {reason}",
                    self.description().side,
                    self.accepted + self.rejected,
                    t_ns as f64 * 1e-9
                ));
                self.reason = reason;
            }
        }
    }

    /// Takes the new gripper commands at `t_ns`, in order.
    fn poll_gripper(&mut self, io: &Store, t_ns: i64, log: &mut dyn Log) -> Result<(), String> {
        for bytes in self.ports().gripper_command.take(io, "gripper_command")? {
            let res = GripperCommand::from_cdr(&bytes)
                .map_err(|e| format!("not a valid control_msgs/msg/GripperCommand CDR message: {e}"))
                .and_then(|c| self.gripper.command(c.position, c.max_effort));
            if let Err(e) = res {
                log.warning(format_args!(
                    "{} gripper: command refused at t={} s: {e}",
                    self.description().side,
                    t_ns as f64 * 1e-9
                ));
            }
        }
        Ok(())
    }

    /// Runs the control loop from `from_ns` to `to_ns` with no external load.
    pub fn advance(&mut self, from_ns: i64, to_ns: i64, grasp_width: f64) {
        self.advance_loaded(from_ns, to_ns, grasp_width, &[0.0; 6]);
    }

    /// Runs the control loop from `from_ns` to `to_ns` with the hand under `load` (force and
    /// moment about link0's origin, in link0), held over the step; its joint torques are
    /// taken at the step's start configuration.
    pub fn advance_loaded(&mut self, from_ns: i64, to_ns: i64, grasp_width: f64, load: &[f64; 6]) {
        let mut start = from_ns;
        let mut len = to_ns.saturating_sub(from_ns);
        if len <= 0 {
            return;
        }
        let mut n = (len + CONTROL_PERIOD_NS - 1) / CONTROL_PERIOD_NS;
        if n > MAX_SUBSTEPS {
            n = MAX_SUBSTEPS;
            len = MAX_SUBSTEPS * CONTROL_PERIOD_NS;
            start = to_ns - len;
        }
        let params = self.joint_params();
        let d = self.arm.take().expect("initialized");
        let ext = crate::load::joint_torques(&d, &self.state.q, load);
        let end_ref = self.reference.end_ns();
        for k in 0..n {
            let s0 = start + ((len as i128 * k as i128) / n as i128) as i64;
            let s1 = start + ((len as i128 * (k + 1) as i128) / n as i128) as i64;
            let dt = (s1 - s0) as f64 * 1e-9;
            let sp = self.reference.sample(s0);
            if self.exec == Exec::Executing {
                for i in 0..N {
                    let e = (sp.q[i] - self.state.q[i]).abs();
                    self.errors.sum_sq += e * e;
                    self.errors.max = self.errors.max.max(e);
                }
                self.errors.samples += 1;
            }
            let inertia = joint_inertia(&d, &self.state.q, 0.5 * self.gripper.width);
            dynamics::step(&params, &self.mismatch, &inertia, &mut self.state, &sp, &ext, dt);
            self.gripper.update(dt, grasp_width);
            if self.exec == Exec::Executing && s1 >= end_ref {
                self.exec = Exec::Succeeded;
            }
            if self.js_schedule.due(s1 as f64 * 1e-9).is_some() {
                self.snapshot = Some(Snapshot { stamp_ns: s1, joints: self.state, gripper: self.gripper });
            }
        }
        self.arm = Some(d);
        self.reference.prune(to_ns);
    }

    fn joint_state_message(&mut self, s: &Snapshot) -> JointState {
        let d = self.description();
        let mut name: Vec<String> = d.joint_names.to_vec();
        name.extend(d.finger_names.iter().cloned());
        let half = 0.5 * s.gripper.width;
        let mut position: Vec<f64> = s.joints.q.to_vec();
        if self.noise > 0.0 {
            for p in position.iter_mut() {
                *p += self.rng.gauss(self.noise);
            }
        }
        position.extend([half, half]);
        let mut velocity = s.joints.qd.to_vec();
        velocity.extend([0.5 * s.gripper.velocity; 2]);
        let mut effort = s.joints.tau.to_vec();
        effort.extend([s.gripper.force(); 2]);
        JointState { header: Header::new(Time::from_nanos(s.stamp_ns), ""), name, position, velocity, effort }
    }

    fn status_message(&self, stamp_ns: i64) -> TrajectoryStatus {
        TrajectoryStatus {
            header: Header::new(Time::from_nanos(stamp_ns), format!("{}_link0", self.description().side)),
            state: self.state_code(),
            trajectory_count: self.accepted,
            rejected_count: self.rejected,
            reason: if self.rejected_last { clip(&self.reason, MAX_REASON) } else { String::new() },
            rms_tracking_error: self.errors.rms(),
            max_tracking_error: self.errors.max,
        }
    }

    fn write_outputs(&mut self, io: &mut Store, t_ns: i64) {
        for i in 0..N {
            io.set_f64(Q[i], self.state.q[i]);
        }
        io.set_f64(FINGER_WIDTH, self.gripper.width);
        io.set_f64(GRIP_FORCE, self.gripper.force());
        io.set_f64(TRACKING_ERROR_RMS, self.errors.rms());
        let status = if self.rejected_last {
            2
        } else if self.exec == Exec::Executing {
            1
        } else {
            0
        };
        io.set_i32(STATUS, status);
        if let Some(s) = self.snapshot.take() {
            let js = self.joint_state_message(&s).to_cdr();
            self.ports().joint_states.publish(s.stamp_ns, js);
            let g = &s.gripper;
            let gs = GripperState {
                header: Header::new(Time::from_nanos(s.stamp_ns), format!("{}_hand", self.description().side)),
                position: g.width,
                effort: g.force(),
                stalled: g.stalled,
                reached_goal: g.reached_goal(),
            };
            self.ports().gripper_state.publish(s.stamp_ns, gs.to_cdr());
        }
        let key = (self.state_code(), self.accepted, self.rejected);
        let due = self.status_schedule.due(t_ns as f64 * 1e-9).is_some();
        if due || self.last_status != Some(key) {
            self.last_status = Some(key);
            let status = self.status_message(t_ns).to_cdr();
            self.ports().trajectory_status.publish(t_ns, status);
        }
        let w = self.window_ns;
        let p = self.ports();
        for port in [&mut p.joint_states, &mut p.trajectory_status, &mut p.gripper_state] {
            port.sync(io, t_ns, w);
        }
    }
}

fn positive_list(io: &Store, i: usize, default: [f64; N]) -> Result<[f64; N], String> {
    let v = parse_list(io.string(i), default, VARIABLES[i].name)?;
    if v.iter().any(|x| *x < 0.0) {
        return Err(format!("parameter {} must not be negative: {v:?}", VARIABLES[i].name));
    }
    Ok(v)
}

fn finite_param(io: &Store, i: usize, lo: f64, hi: f64) -> Result<f64, String> {
    let v = io.f64(i);
    if !(v.is_finite() && v >= lo && v <= hi) {
        return Err(format!("parameter {} must be in [{lo}, {hi}], got {v}", VARIABLES[i].name));
    }
    Ok(v)
}

impl Model for Arm {
    const NAME: &'static str = "Arm";
    const DESCRIPTION: &'static str = "7-DoF Panda-like arm with parallel gripper: JointTrajectory validation and interpolation, PD + feedforward joint dynamics at 1 kHz, GripperCommand, JointState";
    const VARIABLES: &'static [Var] = VARIABLES;

    fn save_state(&self, out: &mut Vec<u8>) -> Result<(), agrisim_fmi::ModelError> {
        agrisim_fmi::serial::write(self, out)
    }

    fn load_state(&mut self, bytes: &[u8]) -> Result<(), agrisim_fmi::ModelError> {
        agrisim_fmi::serial::load_keeping(self, bytes, |new, old| {
            new.arm = old.arm.take();
            new.params = old.params;
        })
    }

    fn new() -> Self {
        Self::default()
    }

    fn initialize(&mut self, io: &mut Store, start_time: f64, log: &mut dyn Log) -> Result<(), String> {
        let d = ArmDescription::load(io.string(SIDE))?;
        let q0 = parse_list(io.string(Q_INIT), READY_POSE, "q_init")?;
        for i in 0..N {
            if !d.limits[i].contains(q0[i]) {
                return Err(format!(
                    "q_init: {} = {} outside [{}, {}]",
                    d.joint_names[i], q0[i], d.limits[i].lower, d.limits[i].upper
                ));
            }
        }
        let kp = positive_list(io, KP, DEFAULT_KP)?;
        let kd = positive_list(io, KD, DEFAULT_KD)?;
        let mismatch = ModelMismatch {
            inertia: finite_param(io, INERTIA_SCALE, 0.0, 10.0)?,
            coulomb: finite_param(io, COULOMB_SCALE, 0.0, 10.0)?,
            viscous: finite_param(io, VISCOUS_SCALE, 0.0, 10.0)?,
        };
        let w0 = finite_param(io, GRIPPER_WIDTH0, 0.0, d.max_width())?;
        let speed = finite_param(io, GRIPPER_SPEED, 1e-6, 10.0)?;
        let noise = finite_param(io, POSITION_NOISE, 0.0, 1.0)?;
        let start_ns = to_ns(start_time);
        *self = Arm {
            params: std::array::from_fn(|i| {
                Some(JointParams {
                    lower: d.limits[i].lower,
                    upper: d.limits[i].upper,
                    effort: d.limits[i].effort,
                    kp: kp[i],
                    kd: kd[i],
                    coulomb: COULOMB[i],
                    viscous: VISCOUS[i],
                })
            }),
            mismatch,
            state: dynamics::JointState { q: q0, ..Default::default() },
            reference: Reference::hold(q0),
            gripper: Gripper {
                limit: finite_param(io, MAX_GRIP_FORCE, 0.0, 1000.0)?,
                ..Gripper::new(w0, d.max_width(), speed)
            },
            js_schedule: Schedule::new(finite_param(io, JOINT_STATE_RATE, 0.001, 1000.0)?, start_time)?,
            status_schedule: Schedule::new(finite_param(io, STATUS_RATE, 0.001, 1000.0)?, start_time)?,
            noise,
            rng: Rng::new(io.i32(SEED) as u32 as u64),
            now_ns: start_ns,
            window_ns: agrisim_fmi::port::window_ns(io, PORT_WINDOW)?,
            arm: Some(d),
            ..Default::default()
        };
        self.poll_trajectory(io, start_ns, log)?;
        self.poll_gripper(io, start_ns, log)?;
        if self.js_schedule.due(start_time).is_some() {
            self.snapshot = Some(Snapshot { stamp_ns: start_ns, joints: self.state, gripper: self.gripper });
        }
        self.write_outputs(io, start_ns);
        Ok(())
    }

    fn do_step(&mut self, io: &mut Store, t: f64, h: f64, log: &mut dyn Log) -> Result<(), String> {
        let t_ns = to_ns(t);
        let end_ns = to_ns(t + h);
        self.poll_trajectory(io, t_ns, log)?;
        self.poll_gripper(io, t_ns, log)?;
        let gw = io.f64(GRASP_WIDTH);
        let load: [f64; 6] = std::array::from_fn(|k| io.f64(LOAD[k]));
        if load.iter().any(|v| !v.is_finite()) {
            return Err(format!("load inputs (load_fx..load_mz) = {load:?} are not finite"));
        }
        self.advance_loaded(t_ns, end_ns, if gw.is_finite() { gw } else { 0.0 }, &load);
        self.now_ns = end_ns;
        self.write_outputs(io, end_ns);
        Ok(())
    }
}
