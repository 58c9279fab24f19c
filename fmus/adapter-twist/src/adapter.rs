//! The model: takes every new Twist in order, keeps the newest valid one, and writes its
//! fields to the outputs until the watchdog expires.
//!
//! Timing matches the chassis's command intake (`agrisim_chassis::command`): messages are
//! taken and the watchdog is evaluated at the step's start `t`, and the outputs written at
//! `t + h` are the command the built-in chassis would follow over [t, t + h]. With the
//! master's Gauss-Seidel order (adapter before the model it feeds), that model reads them for
//! its own step [t, t + h], so it sees exactly what the built-in chassis would.
//!
//! A message that is not a valid, finite Twist is refused with a warning and the last valid
//! command stays in force (as in the chassis: a bad message must not stop the run).

use crate::fields::{field_values, N};
use crate::ports::*;
use agrisim_fmi::{InPort, Log, Model, Store, Var};
use agrisim_msgs::geometry_msgs::Twist;
use agrisim_msgs::Message;

#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct TwistToScalars {
    input: InPort,
    /// The newest valid command's field values (zeros before the first).
    latest: [f64; N],
    /// When the newest valid command was taken; `None` before the first.
    received_at: Option<f64>,
    count: i32,
}

impl Default for TwistToScalars {
    fn default() -> Self {
        TwistToScalars { input: InPort::new(CMD_VEL, CMD_VEL_SEQ), latest: [0.0; N], received_at: None, count: 0 }
    }
}

/// The field values of one message, or why it is refused.
fn decode(bytes: &[u8]) -> Result<[f64; N], String> {
    let m = Twist::from_cdr(bytes)
        .map_err(|e| format!("not a valid geometry_msgs/msg/Twist CDR message ({} bytes): {e}", bytes.len()))?;
    let v = field_values(&m);
    if v.iter().all(|x| x.is_finite()) {
        Ok(v)
    } else {
        Err(format!("non-finite command {v:?}"))
    }
}

impl TwistToScalars {
    /// Takes every new message on cmd_vel at `t`, in order.
    fn take(&mut self, io: &Store, t: f64, log: &mut dyn Log) {
        let msgs = match self.input.take(io, "cmd_vel") {
            Ok(m) => m,
            Err(e) => {
                log.warning(format_args!("t={t} s: {e}; refused, the last valid command stays in force"));
                return;
            }
        };
        for bytes in &msgs {
            match decode(bytes) {
                Ok(v) => {
                    self.latest = v;
                    self.received_at = Some(t);
                    self.count = self.count.saturating_add(1);
                }
                Err(e) => {
                    log.warning(format_args!("t={t} s: cmd_vel: {e}; refused, the last valid command stays in force"))
                }
            }
        }
    }

    /// Whether the newest command is still in force at `t` (same rule as the chassis).
    fn active(&self, t: f64, timeout: f64) -> bool {
        self.received_at.is_some_and(|r| !(timeout > 0.0 && t - r >= timeout - 1e-12))
    }

    fn write_outputs(&self, io: &mut Store, t: f64) {
        let active = self.active(t, io.f64(TIMEOUT));
        for (k, v) in self.latest.iter().enumerate() {
            io.set_f64(FIRST_FIELD + k, if active { *v } else { 0.0 });
        }
        io.set_i32(COUNT, self.count);
        io.set_bool(ACTIVE, active);
    }
}

impl Model for TwistToScalars {
    const NAME: &'static str = "TwistToScalars";
    const DESCRIPTION: &'static str =
        "Adapter: geometry_msgs/Twist commands in, one Float64 output per message field out, with a command watchdog";
    const VARIABLES: &'static [Var] = VARIABLES;

    agrisim_fmi::whole_state!();

    fn new() -> Self {
        Self::default()
    }

    fn initialize(&mut self, io: &mut Store, start_time: f64, log: &mut dyn Log) -> Result<(), String> {
        *self = Self::default();
        self.take(io, start_time, log);
        self.write_outputs(io, start_time);
        Ok(())
    }

    fn do_step(&mut self, io: &mut Store, t: f64, _h: f64, log: &mut dyn Log) -> Result<(), String> {
        self.take(io, t, log);
        self.write_outputs(io, t);
        Ok(())
    }
}
