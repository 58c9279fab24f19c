//! Local planner: the Dynamic Window Approach (D. Fox, W. Burgard, S. Thrun, "The Dynamic
//! Window Approach to Collision Avoidance", IEEE RAM 4(1), 1997), extended to the holonomic
//! base: it samples (vx, vy, wz) in the window reachable within one control period from the
//! last command, rolls each out at constant velocity, drops those whose oriented footprint
//! comes closer than a margin to an obstacle, and scores the rest.
//!
//! Scores (lower is better): distance of the roll-out's end to a carrot ahead on the plan
//! (progress), to the plan itself (path following), heading error, an obstacle term that
//! grows as footprint clearance shrinks, and a little spin. The window is taken from the last
//! command, not measured odometry (open-loop, like a velocity smoother), so limits hold exactly.
//! Also here: the rotate-in-place law of the goal's rotate phase, and [`Dwa`], the
//! [`Controller`] the executor runs by default.

use super::controller::{integrate, Controller, Decision, Obstacles, Request, Velocity};
use super::footprint::Footprint;
use agrisim_math::pose2::wrap_angle;
use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ControllerConfig {
    /// Velocity limits, base frame [m/s, rad/s].
    pub max_vx: f64,
    pub max_vy: f64,
    /// Limit on the planar speed hypot(vx, vy) [m/s].
    pub max_speed_xy: f64,
    pub max_wz: f64,
    /// Acceleration limits [m/s², rad/s²].
    pub acc_xy: f64,
    pub acc_wz: f64,
    /// Control period (the message rate) [s].
    pub period: f64,
    /// Samples per axis in the dynamic window (odd values include the current velocity).
    pub vx_samples: usize,
    pub vy_samples: usize,
    pub wz_samples: usize,
    /// Roll-out horizon and step [s].
    pub sim_time: f64,
    pub sim_dt: f64,
    /// Distance of the carrot ahead of the robot along the plan [m].
    pub lookahead: f64,
    pub w_progress: f64,
    pub w_path: f64,
    pub w_heading: f64,
    pub w_obstacle: f64,
    pub w_spin: f64,
    /// Roll-outs with less footprint clearance are rejected [m].
    pub collision_margin: f64,
    /// Decay length of the obstacle term [m].
    pub clearance_scale: f64,
    /// Proportional gain of the rotate-in-place law [1/s].
    pub rotate_gain: f64,
}

impl Default for ControllerConfig {
    fn default() -> Self {
        ControllerConfig {
            max_vx: 0.8,
            max_vy: 0.8,
            max_speed_xy: 0.8,
            max_wz: 0.8,
            acc_xy: 1.0,
            acc_wz: 2.0,
            period: 0.1,
            vx_samples: 5,
            vy_samples: 5,
            wz_samples: 7,
            sim_time: 2.0,
            sim_dt: 0.1,
            lookahead: 2.0,
            w_progress: 1.0,
            w_path: 0.6,
            w_heading: 0.3,
            w_obstacle: 0.3,
            w_spin: 0.02,
            collision_margin: 0.06,
            clearance_scale: 0.15,
            rotate_gain: 1.5,
        }
    }
}

/// Per-axis reachable interval [lo, hi] within one period, inside the limits.
fn window(current: f64, limit: f64, acc: f64, period: f64) -> (f64, f64) {
    let (lo, hi) = ((current - acc * period).max(-limit), (current + acc * period).min(limit));
    if lo > hi {
        let c = current.clamp(-limit, limit);
        (c, c)
    } else {
        (lo, hi)
    }
}

fn samples(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    let mut v: Vec<f64> = if n <= 1 || hi - lo < 1e-12 {
        vec![0.5 * (lo + hi)]
    } else {
        (0..n).map(|i| lo + (hi - lo) * i as f64 / (n - 1) as f64).collect()
    };
    if lo <= 0.0 && hi >= 0.0 && v.iter().all(|x| x.abs() > 1e-9) {
        v.push(0.0);
    }
    v
}

/// Moves `current` towards `target` by at most `acc * period`, within `±limit`.
fn approach(current: f64, target: f64, limit: f64, acc: f64, period: f64) -> f64 {
    let (lo, hi) = window(current, limit, acc, period);
    target.clamp(lo, hi)
}

/// The hardest braking the limits allow (all axes towards zero).
pub fn brake(cfg: &ControllerConfig, current: Velocity) -> Velocity {
    let mut v = Velocity {
        vx: approach(current.vx, 0.0, cfg.max_vx, cfg.acc_xy, cfg.period),
        vy: approach(current.vy, 0.0, cfg.max_vy, cfg.acc_xy, cfg.period),
        wz: approach(current.wz, 0.0, cfg.max_wz, cfg.acc_wz, cfg.period),
    };
    let s = v.vx.hypot(v.vy);
    if s > cfg.max_speed_xy {
        v.vx *= cfg.max_speed_xy / s;
        v.vy *= cfg.max_speed_xy / s;
    }
    v
}

/// How much closer than it is now a robot inside the collision margin may come [m].
pub const ESCAPE_SLACK: f64 = 0.005;

/// One DWA step. `distance(x, y)` is the obstacle distance field (static, sensed and
/// blocked obstacles combined), `outline` the footprint outline (base frame).
pub fn dwa(
    cfg: &ControllerConfig,
    req: &Request,
    outline: &[(f64, f64)],
    distance: impl Fn(f64, f64) -> f64,
) -> Decision {
    let (vx_lo, vx_hi) = window(req.current.vx, cfg.max_vx, cfg.acc_xy, cfg.period);
    let (vy_lo, vy_hi) = window(req.current.vy, cfg.max_vy, cfg.acc_xy, cfg.period);
    let (wz_lo, wz_hi) = window(req.current.wz, cfg.max_wz, cfg.acc_wz, cfg.period);
    let steps = ((cfg.sim_time / cfg.sim_dt).round() as usize).max(1);
    // A robot already inside the margin (an estimate a few cm off, a wheel slip) may take
    // any roll-out that does not bring it closer: else every roll-out fails at its first step
    // and it stays wedged for good.
    let now = Footprint::clearance(outline, &req.pose, &distance);
    let margin = cfg.collision_margin.min((now - ESCAPE_SLACK).max(0.0));
    let mut best: Option<(f64, Velocity, f64)> = None;
    for &vx in &samples(vx_lo, vx_hi, cfg.vx_samples) {
        for &vy in &samples(vy_lo, vy_hi, cfg.vy_samples) {
            if vx.hypot(vy) > cfg.max_speed_xy + 1e-9 {
                continue;
            }
            for &wz in &samples(wz_lo, wz_hi, cfg.wz_samples) {
                let v = Velocity { vx, vy, wz };
                let mut p = req.pose;
                let mut clearance = f64::INFINITY;
                for _ in 0..steps {
                    p = integrate(&p, &v, cfg.sim_dt);
                    clearance = clearance.min(Footprint::clearance(outline, &p, &distance));
                    if clearance < margin {
                        break;
                    }
                }
                if clearance < margin {
                    continue;
                }
                let progress = (p.x - req.carrot.0).hypot(p.y - req.carrot.1);
                let path = req.path.iter().map(|q| (q.0 - p.x).hypot(q.1 - p.y)).fold(f64::INFINITY, f64::min);
                let path = if path.is_finite() { path } else { 0.0 };
                let heading = wrap_angle(p.yaw - req.desired_yaw).abs();
                let obstacle = (-(clearance - margin) / cfg.clearance_scale).exp();
                let score = cfg.w_progress * progress
                    + cfg.w_path * path
                    + cfg.w_heading * heading
                    + cfg.w_obstacle * obstacle
                    + cfg.w_spin * wz.abs();
                if best.is_none_or(|(b, _, _)| score < b) {
                    best = Some((score, v, clearance));
                }
            }
        }
    }
    match best {
        Some((_, cmd, clearance)) => Decision { cmd, valid: true, clearance },
        None => Decision { cmd: brake(cfg, req.current), valid: false, clearance: 0.0 },
    }
}

/// Rotate-in-place towards `yaw_error` (target minus current): translation brakes to zero,
/// the turn rate follows a proportional law capped so the robot can stop at the target.
pub fn rotate_in_place(cfg: &ControllerConfig, current: Velocity, yaw_error: f64) -> Velocity {
    let e = wrap_angle(yaw_error);
    let stop_rate = (2.0 * 0.5 * cfg.acc_wz * e.abs()).sqrt();
    let target = e.signum() * (cfg.rotate_gain * e.abs()).min(stop_rate).min(cfg.max_wz);
    let b = brake(cfg, current);
    Velocity { vx: b.vx, vy: b.vy, wz: approach(current.wz, target, cfg.max_wz, cfg.acc_wz, cfg.period) }
}

/// The DWA behind the [`Controller`] seam.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dwa {
    pub cfg: ControllerConfig,
}

impl Controller for Dwa {
    fn compute_velocity(&mut self, req: &Request, outline: &[(f64, f64)], obstacles: &Obstacles) -> Decision {
        dwa(&self.cfg, req, outline, |x, y| obstacles.distance_at(x, y))
    }

    fn rotate_in_place(&mut self, current: Velocity, yaw_error: f64) -> Velocity {
        rotate_in_place(&self.cfg, current, yaw_error)
    }

    fn brake(&self, current: Velocity) -> Velocity {
        brake(&self.cfg, current)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use agrisim_math::pose2::Pose2;

    #[test]
    fn drives_towards_the_carrot_in_free_space() {
        let cfg = ControllerConfig::default();
        let outline = Footprint::default().outline(0.05);
        let path: Vec<(f64, f64)> = (0..60).map(|i| (0.05 * i as f64, 0.0)).collect();
        let mut req = Request {
            pose: Pose2::default(),
            current: Velocity::ZERO,
            path: &path,
            carrot: (2.0, 0.0),
            desired_yaw: 0.0,
        };
        let mut v = Velocity::ZERO;
        for _ in 0..10 {
            req.current = v;
            let d = dwa(&cfg, &req, &outline, |_, _| 10.0);
            assert!(d.valid);
            v = d.cmd;
        }
        assert!(v.vx > 0.45 && v.vy.abs() < 0.05 && v.wz.abs() < 0.1, "{v:?}");
        // Sideways carrot: the omni base strafes.
        req.carrot = (0.0, 2.0);
        req.current = Velocity::ZERO;
        let d = dwa(&cfg, &req, &outline, |_, _| 10.0);
        assert!(d.cmd.vy > 0.05, "{:?}", d.cmd);
    }

    #[test]
    fn wall_ahead_rejects_forward_rollouts() {
        let cfg = ControllerConfig::default();
        let outline = Footprint::default().outline(0.05);
        let path: Vec<(f64, f64)> = (0..60).map(|i| (0.05 * i as f64, 0.0)).collect();
        let req = Request {
            pose: Pose2::default(),
            current: Velocity { vx: 0.3, vy: 0.0, wz: 0.0 },
            path: &path,
            carrot: (2.0, 0.0),
            desired_yaw: 0.0,
        };
        // Wall at x = 1.0.
        let d = dwa(&cfg, &req, &outline, |x, _| (1.0 - x).max(0.0));
        assert!(!d.valid || d.cmd.vx < 0.3);
    }

    #[test]
    fn rotate_in_place_converges_without_overshoot() {
        let cfg = ControllerConfig::default();
        let (mut yaw, mut v) = (0.0, Velocity::ZERO);
        let mut max_yaw: f64 = 0.0;
        for _ in 0..100 {
            v = rotate_in_place(&cfg, v, 1.5 - yaw);
            yaw += v.wz * cfg.period;
            max_yaw = max_yaw.max(yaw);
        }
        assert!((yaw - 1.5).abs() < 0.02 && max_yaw < 1.55, "yaw {yaw} max {max_yaw}");
    }
}
