//! Lift FMU: the prismatic joint that raises both arms. A position set-point input is
//! followed with a time-optimal velocity/acceleration-limited profile. A set-point outside
//! the range is refused (status output, log message) and the lift keeps its last valid
//! target: clamping silently would hide a planner bug.

mod profile;

pub use profile::Profile;

use agrisim_fmi::{Log, Model, Start, Store, Var};

/// `status` output values.
pub mod status {
    /// At rest on the target.
    pub const AT_TARGET: i32 = 0;
    /// Moving toward the target.
    pub const MOVING: i32 = 1;
    /// The last set-point was out of range and refused; the lift follows the previous one.
    pub const REFUSED: i32 = 2;
}

agrisim_fmi::variables! { pub VARIABLES {
    POS_MIN = Var::param("position_min", Start::Float64(0.0)).unit("m").desc("Lower end of travel"),
    POS_MAX = Var::param("position_max", Start::Float64(0.8)).unit("m").desc("Upper end of travel"),
    VEL_MAX = Var::param("velocity_max", Start::Float64(0.2)).unit("m/s").range(1e-9, 1e6),
    ACC_MAX = Var::param("acceleration_max", Start::Float64(0.5)).unit("m/s2").range(1e-9, 1e9),
    POS0 = Var::param("position0", Start::Float64(0.2)).unit("m").desc("Initial position"),
    CARRIED_MASS = Var::param("carried_mass", Start::Float64(45.0)).unit("kg")
        .desc("Mass of carriage, arms and grippers moved by the lift"),
    BASE_HEIGHT = Var::param("base_height", Start::Float64(0.45)).unit("m")
        .desc("Height of the carried mass's centre above the floor at position 0"),
    SETPOINT = Var::input("setpoint", 0.2).unit("m").desc("Position set-point"),
    // Initially the lift rests at position0; a set-point present at initialization only
    // selects the target (and so status), it has not moved the lift yet.
    POSITION = Var::output("position").unit("m").init_depends_on(&[POS0]),
    VELOCITY = Var::output("velocity").unit("m/s").init_depends_on(&[]),
    STATUS = Var::output_discrete("status", Start::Int32(0)).init_depends_on(SETPOINT_CHOICE)
        .desc("0 at target, 1 moving, 2 last set-point refused (out of range or not finite)"),
    TARGET = Var::output("target").unit("m").init_depends_on(SETPOINT_CHOICE).desc("Target being followed (last valid set-point)"),
    PAYLOAD_MASS = Var::output("payload_mass").unit("kg").init_depends_on(&[CARRIED_MASS]).desc("Carried mass, for the chassis"),
    PAYLOAD_HEIGHT = Var::output("payload_height").unit("m").init_depends_on(&[BASE_HEIGHT, POS0])
        .desc("Carried mass's centre height, for the chassis"),
}}

/// What the target chosen at initialization depends on: the set-point, its valid range and
/// where the lift starts.
const SETPOINT_CHOICE: &[usize] = &[POS_MIN, POS_MAX, POS0, SETPOINT];

#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Lift {
    profile: Profile,
    target: f64,
    last_setpoint: f64,
    refused: bool,
    range: (f64, f64),
    limits: (f64, f64),
}

impl Lift {
    /// Accepts or refuses the set-point present at time `t`.
    fn take_setpoint(&mut self, io: &Store, t: f64, log: &mut dyn Log) {
        let sp = io.f64(SETPOINT);
        if sp.to_bits() == self.last_setpoint.to_bits() {
            return;
        }
        self.last_setpoint = sp;
        if !(sp.is_finite() && sp >= self.range.0 && sp <= self.range.1) {
            self.refused = true;
            log.warning(format_args!(
                "setpoint {sp} m refused at t={t}: outside [{}, {}] m; keeping target {} m",
                self.range.0, self.range.1, self.target
            ));
            return;
        }
        self.refused = false;
        if sp != self.target {
            let (p, v) = self.profile.eval(t);
            self.target = sp;
            self.profile = Profile::plan(t, p, v, sp, self.limits.0, self.limits.1);
        }
    }

    fn write_outputs(&self, io: &mut Store, t: f64) {
        let (p, v) = self.profile.eval(t);
        io.set_f64(POSITION, p);
        io.set_f64(VELOCITY, v);
        io.set_f64(TARGET, self.target);
        let st = if self.refused {
            status::REFUSED
        } else if t < self.profile.end_time() {
            status::MOVING
        } else {
            status::AT_TARGET
        };
        io.set_i32(STATUS, st);
        io.set_f64(PAYLOAD_MASS, io.f64(CARRIED_MASS));
        io.set_f64(PAYLOAD_HEIGHT, io.f64(BASE_HEIGHT) + p);
    }
}

impl Model for Lift {
    const NAME: &'static str = "Lift";
    const DESCRIPTION: &'static str =
        "Prismatic lift with position set-point, velocity/acceleration limits and range check";
    const VARIABLES: &'static [Var] = VARIABLES;

    agrisim_fmi::whole_state!();

    fn new() -> Self {
        Self::default()
    }

    fn initialize(&mut self, io: &mut Store, start_time: f64, log: &mut dyn Log) -> Result<(), String> {
        let (lo, hi) = (io.f64(POS_MIN), io.f64(POS_MAX));
        if !(lo.is_finite() && hi.is_finite() && lo < hi) {
            return Err(format!("position_min ({lo}) must be below position_max ({hi})"));
        }
        let (vmax, amax) = (io.f64(VEL_MAX), io.f64(ACC_MAX));
        if !(vmax.is_finite() && vmax > 0.0 && amax.is_finite() && amax > 0.0) {
            return Err(format!("velocity_max ({vmax}) and acceleration_max ({amax}) must be positive and finite"));
        }
        let p0 = io.f64(POS0);
        if !(p0 >= lo && p0 <= hi) {
            return Err(format!("position0 {p0} outside [{lo}, {hi}]"));
        }
        *self = Lift {
            profile: Profile::hold(start_time, p0),
            target: p0,
            last_setpoint: f64::NAN,
            refused: false,
            range: (lo, hi),
            limits: (vmax, amax),
        };
        self.take_setpoint(io, start_time, log);
        self.write_outputs(io, start_time);
        Ok(())
    }

    fn do_step(&mut self, io: &mut Store, t: f64, h: f64, log: &mut dyn Log) -> Result<(), String> {
        self.take_setpoint(io, t, log);
        self.write_outputs(io, t + h);
        Ok(())
    }
}

agrisim_fmi::export_fmu!(Lift);
