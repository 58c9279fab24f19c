//! Base velocity command intake: two sources (scalar ports with a counter, and a Twist
//! message port with its sequence counter), latest command wins, plus a watchdog that stops
//! the base when commands stop arriving (like a real base controller's cmd_vel timeout).
//! A message that is not a valid, finite Twist is refused with a warning and the last valid
//! command stays in force (a bad message from the network must not stop the run); the
//! watchdog still stops the base when no valid command comes.

use crate::ports::*;
use crate::se2::Twist2;
use agrisim_fmi::{InPort, Log, Store};
use agrisim_msgs::geometry_msgs::Twist;
use agrisim_msgs::Message;

#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct CommandIntake {
    cmd_seq: i32,
    cmd_vel: InPort,
    latest: Twist2,
    received_at: f64,
}

impl Default for CommandIntake {
    fn default() -> Self {
        CommandIntake {
            cmd_seq: 0,
            cmd_vel: InPort::new(CMD_VEL, CMD_VEL_SEQ),
            latest: Twist2::default(),
            received_at: 0.0,
        }
    }
}

impl CommandIntake {
    /// Takes the command present at initialization (scalar ports, or the message if one is set).
    pub fn initialize(&mut self, io: &Store, t: f64, log: &mut dyn Log) -> Result<(), String> {
        self.cmd_seq = io.i32(CMD_SEQ);
        self.cmd_vel.clear();
        self.latest = scalar_command(io)?;
        self.take_messages(io, t, log)?;
        self.received_at = t;
        Ok(())
    }

    /// Looks for a fresh command at time `t` (start of a step). When both sources changed in
    /// the same step the message wins.
    pub fn poll(&mut self, io: &Store, t: f64, log: &mut dyn Log) -> Result<(), String> {
        if io.i32(CMD_SEQ) != self.cmd_seq {
            self.cmd_seq = io.i32(CMD_SEQ);
            self.latest = scalar_command(io)?;
            self.received_at = t;
        }
        if self.take_messages(io, t, log)? {
            self.received_at = t;
        }
        Ok(())
    }

    /// Every new Twist on cmd_vel, in order (the last valid one wins); whether a valid one came.
    fn take_messages(&mut self, io: &Store, t: f64, log: &mut dyn Log) -> Result<bool, String> {
        let msgs = match self.cmd_vel.take(io, "cmd_vel") {
            Ok(m) => m,
            Err(e) => {
                log.warning(format_args!("t={t} s: {e}; refused, the last valid command stays in force"));
                return Ok(false);
            }
        };
        let mut valid = false;
        for m in &msgs {
            match decode_twist(m) {
                Ok(c) => {
                    self.latest = c;
                    valid = true;
                }
                Err(e) => log.warning(format_args!("t={t} s: {e}; refused, the last valid command stays in force")),
            }
        }
        Ok(valid)
    }

    /// The command to follow at `t`, or `None` when the watchdog has expired.
    pub fn active(&self, t: f64, timeout: f64) -> Option<Twist2> {
        if timeout > 0.0 && t - self.received_at >= timeout - 1e-12 {
            None
        } else {
            Some(self.latest)
        }
    }
}

fn checked(t: Twist2, source: &str) -> Result<Twist2, String> {
    if t.vx.is_finite() && t.vy.is_finite() && t.wz.is_finite() {
        Ok(t)
    } else {
        Err(format!("{source}: non-finite velocity command {t:?} refused"))
    }
}

fn scalar_command(io: &Store) -> Result<Twist2, String> {
    checked(Twist2 { vx: io.f64(CMD_VX), vy: io.f64(CMD_VY), wz: io.f64(CMD_WZ) }, "cmd_vx/cmd_vy/cmd_wz")
}

fn decode_twist(bytes: &[u8]) -> Result<Twist2, String> {
    let m = Twist::from_cdr(bytes).map_err(|e| {
        format!("cmd_vel: not a valid geometry_msgs/msg/Twist CDR message ({} bytes): {e}", bytes.len())
    })?;
    checked(Twist2 { vx: m.linear.x, vy: m.linear.y, wz: m.angular.z }, "cmd_vel")
}
