//! Oscillator FMU: a damped harmonic oscillator x'' + 2 zeta omega x' + omega^2 x = 0 with
//! one velocity kick at `kick_time` (a time event). It exists to test model-exchange
//! importers: its solution is known in closed form ([`analytic::solution`]), so an
//! importer's integration, its time-event handling and its restart after the jump can all
//! be checked against exact numbers.
//!
//! Model exchange only (FMI 3.0 and 2.0): it has no co-simulation interface, so an importer
//! that prefers co-simulation still has to take the model-exchange path (see
//! [`agrisim_fmi::Model::CONTINUOUS_STATES`] for why the export layer never offers both).
//!
//! Value references: 1 omega, 2 zeta, 3 x0, 4 v0, 5 kick_time, 6 kick_dv (fixed
//! parameters), 7 x, 8 v (continuous outputs and the states, in this order), 9 der(x),
//! 10 der(v) (locals, the derivatives). No event indicators.

pub mod analytic;

use agrisim_fmi::{ContinuousState, Log, Model, Start, Store, Var};

pub use analytic::{free_response, kick_applies, solution, Params};

agrisim_fmi::variables! { pub VARIABLES {
    OMEGA = Var::param("omega", Start::Float64(2.0)).unit("rad/s").range(1e-6, 1e6)
        .desc("Undamped natural frequency"),
    ZETA = Var::param("zeta", Start::Float64(0.1)).unit("1").range(0.0, 1e6)
        .desc("Damping ratio (<1 under-, 1 critically, >1 over-damped)"),
    X0 = Var::param("x0", Start::Float64(1.0)).unit("m").desc("Initial position"),
    V0 = Var::param("v0", Start::Float64(0.0)).unit("m/s").desc("Initial velocity"),
    KICK_TIME = Var::param("kick_time", Start::Float64(1.0)).unit("s")
        .desc("Time of the velocity kick (a time event); <= 0 or before the start time: no kick"),
    KICK_DV = Var::param("kick_dv", Start::Float64(0.5)).unit("m/s").desc("Velocity added at kick_time"),
    X = Var::output("x").unit("m").init_depends_on(&[X0]).desc("Position (continuous state)"),
    // Before the initial event iteration: a kick at the start time is not applied yet.
    V = Var::output("v").unit("m/s").init_depends_on(&[V0]).desc("Velocity (continuous state)"),
    DER_X = Var::local("der(x)").unit("m/s").desc("Time derivative of x"),
    DER_V = Var::local("der(v)").unit("m/s2").desc("Time derivative of v"),
}}

/// How close (relative) the importer's time must come to `kick_time` for the kick to be
/// due: importers that add up steps reach 1.0 as 0.9999999999999999.
const EVENT_TIME_TOLERANCE: f64 = 1e-9;

#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Oscillator {
    omega: f64,
    zeta: f64,
    kick_time: f64,
    kick_dv: f64,
    /// The kick is still ahead.
    kick_pending: bool,
}

impl Oscillator {
    fn kick_due(&self, t: f64) -> bool {
        self.kick_pending && t >= self.kick_time - EVENT_TIME_TOLERANCE * self.kick_time.abs().max(1.0)
    }
}

impl Model for Oscillator {
    const NAME: &'static str = "Oscillator";
    const DESCRIPTION: &'static str =
        "Damped harmonic oscillator with a velocity kick at a time event (model exchange, closed-form solution)";
    const VARIABLES: &'static [Var] = VARIABLES;
    const CONTINUOUS_STATES: &'static [ContinuousState] = &[
        ContinuousState { state: X, derivative: DER_X, nominal: 1.0 },
        ContinuousState { state: V, derivative: DER_V, nominal: 1.0 },
    ];

    agrisim_fmi::whole_state!();

    fn new() -> Self {
        Self::default()
    }

    fn initialize(&mut self, io: &mut Store, start_time: f64, _log: &mut dyn Log) -> Result<(), String> {
        let p = Params {
            omega: io.f64(OMEGA),
            zeta: io.f64(ZETA),
            x0: io.f64(X0),
            v0: io.f64(V0),
            kick_time: io.f64(KICK_TIME),
            kick_dv: io.f64(KICK_DV),
        };
        if !(p.omega > 0.0 && p.omega.is_finite() && p.zeta >= 0.0 && p.zeta.is_finite()) {
            return Err(format!("omega ({}) must be positive and zeta ({}) non-negative", p.omega, p.zeta));
        }
        *self = Oscillator {
            omega: p.omega,
            zeta: p.zeta,
            kick_time: p.kick_time,
            kick_dv: p.kick_dv,
            kick_pending: kick_applies(&p, start_time),
        };
        io.set_f64(X, p.x0);
        io.set_f64(V, p.v0);
        Ok(())
    }

    fn do_step(&mut self, _io: &mut Store, _t: f64, _h: f64, _log: &mut dyn Log) -> Result<(), String> {
        Err("the Oscillator is a model-exchange FMU: the importer integrates it".into())
    }

    fn evaluate(&mut self, io: &mut Store, _t: f64) -> Result<(), String> {
        let (x, v) = (io.f64(X), io.f64(V));
        io.set_f64(DER_X, v);
        io.set_f64(DER_V, -2.0 * self.zeta * self.omega * v - self.omega * self.omega * x);
        Ok(())
    }

    fn update_discrete_states(&mut self, io: &mut Store, t: f64, log: &mut dyn Log) -> Result<bool, String> {
        if !self.kick_due(t) {
            return Ok(false);
        }
        self.kick_pending = false;
        io.set_f64(V, io.f64(V) + self.kick_dv);
        log.info(format_args!("kick at t={t}: v += {} m/s", self.kick_dv));
        Ok(true)
    }

    fn next_event_time(&self, _io: &Store, t: f64) -> Option<f64> {
        (self.kick_pending && self.kick_time > t).then_some(self.kick_time)
    }
}

agrisim_fmi::export_fmu!(Oscillator);
