//! The controller seam (Nav2's `nav2_core::Controller`): what the executor asks of a local
//! planner each control period, so another one can replace the DWA without touching the
//! executor. Here too: the base-frame velocity command, the motion it makes, and the obstacle
//! distance lookup a controller checks its roll-outs against.

use super::costmap::{ClearanceGrid, GlobalCostmap};
use super::local_costmap::LocalCostmap;
use agrisim_math::pose2::{wrap_angle, Pose2};

/// A base-frame velocity command (REP 103: x forward, y left, z up).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Velocity {
    pub vx: f64,
    pub vy: f64,
    pub wz: f64,
}

impl Velocity {
    pub const ZERO: Velocity = Velocity { vx: 0.0, vy: 0.0, wz: 0.0 };
}

/// Pose after driving `v` for `dt` from `p` (midpoint heading).
pub fn integrate(p: &Pose2, v: &Velocity, dt: f64) -> Pose2 {
    let yaw_mid = p.yaw + 0.5 * v.wz * dt;
    let (s, c) = yaw_mid.sin_cos();
    Pose2 {
        x: p.x + (v.vx * c - v.vy * s) * dt,
        y: p.y + (v.vx * s + v.vy * c) * dt,
        yaw: wrap_angle(p.yaw + v.wz * dt),
    }
}

/// What the controller is asked to do this period.
#[derive(Debug, Clone, Copy)]
pub struct Request<'a> {
    pub pose: Pose2,
    /// The last command sent.
    pub current: Velocity,
    /// The plan from the robot's projection onward (map frame).
    pub path: &'a [(f64, f64)],
    pub carrot: (f64, f64),
    pub desired_yaw: f64,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Decision {
    pub cmd: Velocity,
    /// False when every roll-out collides; `cmd` then brakes as hard as allowed.
    pub valid: bool,
    /// Footprint clearance along the chosen roll-out [m].
    pub clearance: f64,
}

/// Obstacle distance for a controller's roll-outs: static, blocked and sensed obstacles
/// combined, read from one grid over the local window (built once per period, since the
/// roll-outs query it many thousand times) and from both costmaps beyond it.
pub struct Obstacles<'a> {
    global: &'a GlobalCostmap,
    local: &'a LocalCostmap,
    grid: ClearanceGrid,
}

impl<'a> Obstacles<'a> {
    pub fn new(global: &'a GlobalCostmap, local: &'a LocalCostmap) -> Obstacles<'a> {
        Obstacles { global, local, grid: ClearanceGrid::from_costmaps(global, local) }
    }

    /// Distance from the map point (x, y) to the nearest obstacle [m].
    #[inline]
    pub fn distance_at(&self, x: f64, y: f64) -> f64 {
        self.grid.get(x, y).unwrap_or_else(|| self.global.distance_at(x, y).min(self.local.distance_at(x, y)))
    }
}

/// A local planner behind the executor. Its limits are the
/// [`ControllerConfig`](super::dwa::ControllerConfig) the executor also shapes its own
/// commands with (recovery back-off, shifts at the goal), so every command obeys one set of
/// limits.
pub trait Controller: Send {
    /// The command that follows `req.path` towards `req.carrot` for one period without
    /// bringing the footprint `outline` (base frame) into an obstacle.
    fn compute_velocity(&mut self, req: &Request, outline: &[(f64, f64)], obstacles: &Obstacles) -> Decision;

    /// The command that turns in place by `yaw_error` (target minus current) while
    /// translation brakes: the goal's rotate phase.
    fn rotate_in_place(&mut self, current: Velocity, yaw_error: f64) -> Velocity;

    /// The hardest braking the limits allow.
    fn brake(&self, current: Velocity) -> Velocity;
}
