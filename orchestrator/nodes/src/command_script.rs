//! Plays a scenario's timed commands: a teleop-like publisher of geometry_msgs/Twist on
//! /cmd_vel at the message rate (the last command holds until the next, and `silent`
//! entries stop publishing so the chassis watchdog takes over), and lift set-points.

use super::Node;
use agrisim_bus::Bus;
use agrisim_error::Result;
use agrisim_msgs::geometry_msgs::{Twist, Vector3};
use serde::Deserialize;

#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct BaseCommand {
    /// From this time on [s].
    pub t: f64,
    #[serde(default)]
    pub vx: f64,
    #[serde(default)]
    pub vy: f64,
    #[serde(default)]
    pub wz: f64,
    /// Stop publishing (the chassis watchdog then stops the base).
    #[serde(default)]
    pub silent: bool,
}

#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LiftCommand {
    pub t: f64,
    pub position: f64,
}

pub const CMD_VEL: &str = "/cmd_vel";
pub const LIFT_SETPOINT: &str = "/lift/setpoint";

pub struct CommandScript {
    base: Vec<BaseCommand>,
    lift: Vec<LiftCommand>,
}

impl CommandScript {
    pub fn new(base: Vec<BaseCommand>, lift: Vec<LiftCommand>) -> CommandScript {
        CommandScript { base, lift }
    }
}

/// The last entry whose time has come (entries are sorted by time).
fn current<T>(entries: &[T], t_ns: i64, time: impl Fn(&T) -> f64) -> Option<&T> {
    entries.iter().take_while(|e| (time(e) * 1e9).round() as i64 <= t_ns).last()
}

impl Node for CommandScript {
    fn name(&self) -> &str {
        "command_script"
    }

    fn step(&mut self, t_ns: i64, bus: &mut Bus) -> Result<()> {
        if let Some(c) = current(&self.base, t_ns, |c| c.t) {
            if !c.silent {
                let msg = Twist {
                    linear: Vector3 { x: c.vx, y: c.vy, z: 0.0 },
                    angular: Vector3 { x: 0.0, y: 0.0, z: c.wz },
                };
                bus.publish(CMD_VEL, t_ns, &msg);
            }
        }
        if let Some(c) = current(&self.lift, t_ns, |c| c.t) {
            bus.set_scalar(LIFT_SETPOINT, c.position);
        }
        Ok(())
    }
}
