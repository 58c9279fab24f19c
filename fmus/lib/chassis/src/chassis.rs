//! What both chassis models share: command intake, wheel set-points with steering-rate,
//! spin-rate and acceleration limits, odometry, outputs. A [`Drive`] decides how the wheels
//! and the base actually move (kinematic or dynamic), so the two models differ only there.

use crate::command::CommandIntake;
use crate::odometry::WheelOdometry;
use crate::ports::*;
use crate::schedule::Schedule;
use crate::se2::{integrate, Twist2};
use crate::wheels::{approach, WheelLayout, WheelState};
use agrisim_fmi::{Log, Model, OutPort, Store, Var};
use agrisim_math::{Pose2, Rng};
use agrisim_msgs::Message;
use agrisim_schedule::to_ns;

/// Limits and geometry read from the parameters at initialization.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Limits {
    pub steer_max: f64,
    pub steer_rate_max: f64,
    pub spin_max: f64,
    pub spin_accel_max: f64,
}

/// One step of wheel set-points handed to a drive.
pub struct StepInput<'a> {
    pub layout: &'a WheelLayout,
    /// Wheel set-points at the end of the step (already rate-limited).
    pub reference: &'a [WheelState; 4],
    /// Per wheel, the fraction of the step spent ramping toward the set-point (0: the set-point
    /// is reached at once; 1: the ramp lasts the whole step). See [`mean_contact_velocities`].
    pub ramp: &'a [f64; 4],
    pub h: f64,
    pub rng: &'a mut Rng,
    pub io: &'a Store,
}

/// How wheels and base respond to the wheel set-points.
pub trait Drive: Clone + Send + Default + serde::Serialize + serde::de::DeserializeOwned + 'static {
    const NAME: &'static str;
    const DESCRIPTION: &'static str;
    /// Longest communication step the drive integrates [s] (a dynamic model substeps).
    const MAX_STEP: f64 = f64::INFINITY;
    /// Reads the drive's own parameters.
    fn initialize(&mut self, io: &Store) -> Result<(), String>;
    /// Advances the wheels (`wheels`, updated in place) and the base over one step.
    fn step(&mut self, wheels: &mut [WheelState; 4], base: Twist2, input: StepInput<'_>) -> StepOutput;
}

/// What a drive step produced.
pub struct StepOutput {
    /// Mean body twist of the base over the step (integrated into the ground-truth pose).
    pub mean: Twist2,
    /// Body twist at the step's end.
    pub end: Twist2,
    /// Mean contact-point velocity each wheel's rotation implies (what its encoder counts).
    pub wheel_travel: [(f64, f64); 4],
}

/// Mean contact velocity of each wheel over a step whose set-point ramp took `ramp[i]` of the
/// step and then held: exact for an instant change (0) and for a full-step linear ramp (1).
pub fn mean_contact_velocities(
    layout: &WheelLayout,
    start: &[WheelState; 4],
    end: &[WheelState; 4],
    ramp: &[f64; 4],
) -> [(f64, f64); 4] {
    let (va, vb) = (layout.wheel_velocities(start), layout.wheel_velocities(end));
    std::array::from_fn(|i| {
        let f = ramp[i];
        (f * (va[i].0 + vb[i].0) / 2.0 + (1.0 - f) * vb[i].0, f * (va[i].1 + vb[i].1) / 2.0 + (1.0 - f) * vb[i].1)
    })
}

/// A chassis model: the shared part plus a drive.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
#[serde(bound = "")]
pub struct Chassis<D: Drive> {
    drive: D,
    layout: Option<WheelLayout>,
    limits: Limits,
    commands: CommandIntake,
    /// Actual wheel states (steer from the steering servo, spin measured at the wheel).
    wheels: [WheelState; 4],
    /// Commanded spin profile (acceleration-limited), the wheel controllers' set-point.
    spin_ref: [f64; 4],
    pose: Pose2,
    twist: Twist2,
    odom: WheelOdometry,
    odom_schedule: Schedule,
    rng: Rng,
    odom_port: Option<OutPort>,
    window_ns: i64,
}

fn positive(io: &Store, i: usize) -> Result<f64, String> {
    let v = io.f64(i);
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(format!("parameter {} must be positive and finite, got {v}", VARIABLES[i].name))
    }
}

fn non_negative(io: &Store, i: usize) -> Result<f64, String> {
    let v = io.f64(i);
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(format!("parameter {} must be >= 0 and finite, got {v}", VARIABLES[i].name))
    }
}

impl<D: Drive> Chassis<D> {
    fn layout(&self) -> &WheelLayout {
        self.layout.as_ref().expect("initialized")
    }

    fn write_outputs(&self, io: &mut Store) {
        io.set_f64(X, self.pose.x);
        io.set_f64(Y, self.pose.y);
        io.set_f64(YAW, self.pose.yaw);
        io.set_f64(VX, self.twist.vx);
        io.set_f64(VY, self.twist.vy);
        io.set_f64(WZ, self.twist.wz);
        for i in 0..4 {
            io.set_f64(STEER[i], self.wheels[i].steer);
            io.set_f64(SPIN[i], self.wheels[i].spin);
        }
        io.set_f64(ODOM_X, self.odom.pose.x);
        io.set_f64(ODOM_Y, self.odom.pose.y);
        io.set_f64(ODOM_YAW, self.odom.pose.yaw);
        io.set_f64(ODOM_VX, self.odom.twist.vx);
        io.set_f64(ODOM_VY, self.odom.twist.vy);
        io.set_f64(ODOM_WZ, self.odom.twist.wz);
    }

    fn publish_odom(&mut self, io: &mut Store, t: f64) {
        let port = self.odom_port.get_or_insert_with(|| OutPort::new(ODOM, ODOM_SEQ));
        if let Some(stamp) = self.odom_schedule.due(t) {
            port.publish(stamp, self.odom.message(stamp).to_cdr());
        }
        port.sync(io, to_ns(t), self.window_ns);
    }
}

impl<D: Drive> Model for Chassis<D> {
    const NAME: &'static str = D::NAME;
    const DESCRIPTION: &'static str = D::DESCRIPTION;
    const VARIABLES: &'static [Var] = VARIABLES;

    agrisim_fmi::whole_state!();

    fn new() -> Self {
        Self::default()
    }

    fn initialize(&mut self, io: &mut Store, start_time: f64, log: &mut dyn Log) -> Result<(), String> {
        self.layout = Some(WheelLayout::rectangular(
            positive(io, WHEEL_BASE)?,
            positive(io, TRACK)?,
            positive(io, WHEEL_RADIUS)?,
        ));
        self.limits = Limits {
            steer_max: non_negative(io, STEER_MAX)?,
            steer_rate_max: non_negative(io, STEER_RATE_MAX)?,
            spin_max: non_negative(io, WHEEL_SPEED_MAX)?,
            spin_accel_max: non_negative(io, WHEEL_ACCEL_MAX)?,
        };
        for p in [ENC_NOISE, STEER_NOISE, SLIP_STD] {
            non_negative(io, p)?;
        }
        self.drive.initialize(io)?;
        self.commands.initialize(io, start_time, log)?;
        self.pose = Pose2 { x: io.f64(X0), y: io.f64(Y0), yaw: io.f64(YAW0) };
        self.odom = WheelOdometry { pose: self.pose, twist: Twist2::default() };
        self.odom_schedule = Schedule::new(io.f64(ODOM_RATE), start_time)?;
        self.rng = Rng::new(io.i32(SEED) as u32 as u64);
        self.window_ns = agrisim_fmi::port::window_ns(io, PORT_WINDOW)?;
        self.odom_port = None;
        self.write_outputs(io);
        io.set_bool(CMD_ACTIVE, self.commands.active(start_time, io.f64(CMD_TIMEOUT)).is_some());
        self.publish_odom(io, start_time);
        Ok(())
    }

    fn do_step(&mut self, io: &mut Store, t: f64, h: f64, log: &mut dyn Log) -> Result<(), String> {
        if !(h > 0.0 && h <= D::MAX_STEP) {
            return Err(format!("communication step {h} s outside (0, {}] s that {} integrates", D::MAX_STEP, D::NAME));
        }
        self.commands.poll(io, t, log)?;
        let command = self.commands.active(t, io.f64(CMD_TIMEOUT));
        let l = self.limits.clone();
        let target = self.layout().inverse(command.unwrap_or_default(), &self.wheels, l.steer_max);
        let start = self.wheels;
        let mut reference = [WheelState::default(); 4];
        let mut ramp = [0.0; 4];
        for i in 0..4 {
            let steer =
                approach(start[i].steer, target[i].steer, l.steer_rate_max * h).clamp(-l.steer_max, l.steer_max);
            // Drive a wheel only as far as it points the right way: no sideways scrubbing
            // while the steering servo is still turning.
            let aligned = (target[i].steer - steer).cos().max(0.0);
            let spin_target = (target[i].spin * aligned).clamp(-l.spin_max, l.spin_max);
            let spin = approach(self.spin_ref[i], spin_target, l.spin_accel_max * h);
            let duration = ((spin - self.spin_ref[i]).abs() / l.spin_accel_max)
                .max((steer - start[i].steer).abs() / l.steer_rate_max);
            ramp[i] = if duration.is_finite() { (duration / h).min(1.0) } else { 1.0 };
            self.spin_ref[i] = spin;
            reference[i] = WheelState { steer, spin };
        }
        let layout = *self.layout();
        let input = StepInput { layout: &layout, reference: &reference, ramp: &ramp, h, rng: &mut self.rng, io };
        let out = self.drive.step(&mut self.wheels, self.twist, input);
        integrate(&mut self.pose, out.mean, h);
        self.twist = out.end;
        let (enc, steer) = (io.f64(ENC_NOISE), io.f64(STEER_NOISE));
        self.odom.update(&layout, &out.wheel_travel, enc, steer, &mut self.rng, h);
        self.write_outputs(io);
        io.set_bool(CMD_ACTIVE, command.is_some());
        self.publish_odom(io, t + h);
        Ok(())
    }
}
