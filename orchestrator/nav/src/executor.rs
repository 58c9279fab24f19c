//! The navigation executor: what a behaviour-tree navigator does for one goal, as an
//! explicit state machine. Plan, follow with the local planner, replan when sensed obstacles
//! close the path or the robot strays from it, latch the goal position and rotate to the
//! goal yaw, recover when no progress is made, and report why it failed.
//!
//! ```text
//! idle -> planning -> following -> rotating -> succeeded
//!            ^  |        |  ^         |
//!            |  +-> failed (no_path)  +-> following (pushed out of the xy tolerance)
//!            +-- recovering <- (no progress; after max_recoveries: failed "stuck")
//! ```
//!
//! It plans through a [`GlobalPlanner`] and drives through a [`Controller`] (A* and DWA
//! unless the configuration's `plugins` name others), as a Nav2 BT navigator calls its
//! planner and controller servers.

use super::config::NavConfig;
use super::controller::{integrate, Controller, Obstacles, Request, Velocity};
use super::costmap::GlobalCostmap;
use super::dwa::ControllerConfig;
use super::global_planner::{GlobalPlanner, PlanError};
use super::local_costmap::LocalCostmap;
use super::tracking::TrackedPath;
use agrisim_math::pose2::{wrap_angle, Pose2};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum State {
    Idle,
    Planning,
    Following,
    Rotating,
    Recovering,
    Succeeded,
    Failed,
}

impl State {
    pub fn as_str(&self) -> &'static str {
        match self {
            State::Idle => "idle",
            State::Planning => "planning",
            State::Following => "following",
            State::Rotating => "rotating",
            State::Recovering => "recovering",
            State::Succeeded => "succeeded",
            State::Failed => "failed",
        }
    }

    pub fn is_active(&self) -> bool {
        matches!(self, State::Planning | State::Following | State::Rotating | State::Recovering)
    }
}

/// A navigation goal in the map frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Goal {
    pub pose: Pose2,
    /// Whether the final heading matters.
    pub use_yaw: bool,
}

/// The costmaps the executor plans and checks against.
pub struct World<'a> {
    pub global: &'a mut GlobalCostmap,
    pub local: &'a mut LocalCostmap,
}

/// What one tick produced.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TickOutput {
    /// The command to publish on /cmd_vel, if any.
    pub cmd: Option<Velocity>,
    /// A new plan to publish.
    pub plan: Option<Vec<(f64, f64)>>,
}

/// Counters for tests and the benchmark's report.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ExecutorStats {
    pub plans: u64,
    pub replans_blocked: u64,
    pub replans_deviation: u64,
    pub recoveries: u64,
    pub controller_failures: u64,
}

#[derive(Debug, Clone, Copy)]
struct Backup {
    until_ns: i64,
    /// Base-frame unit direction of the back-off.
    dir: (f64, f64),
}

/// A turn at the goal made elsewhere ([`turn_spot`](super::turn_spot)): shift out at the
/// arrival heading, turn, shift back at the goal's heading.
#[derive(Debug, Clone, Copy)]
struct Turn {
    spot: (f64, f64),
    /// Where it ends, at most `turn_spot::END_RADIUS` from the goal.
    back: (f64, f64),
    out_yaw: f64,
    phase: TurnPhase,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum TurnPhase {
    Out,
    Turn,
    Back,
}

/// Position tolerance of the turning spot [m].
const SPOT_TOLERANCE: f64 = 0.03;
/// Speed and gain of the shifts to and from the turning spot [m/s, 1/s].
const SHIFT_SPEED: f64 = 0.3;
const SHIFT_GAIN: f64 = 0.8;

/// How much nearer the other travel direction must be before the executor switches to it [rad].
const REVERSE_HYSTERESIS: f64 = 0.3;

pub struct Executor {
    cfg: NavConfig,
    planner: Box<dyn GlobalPlanner>,
    controller: Box<dyn Controller>,
    outline: Vec<(f64, f64)>,
    state: State,
    detail: String,
    goal: Option<Goal>,
    goal_start_ns: i64,
    path: TrackedPath,
    last_cmd: Velocity,
    last_plan_ns: Option<i64>,
    anchor: (Pose2, i64),
    rotate_start_ns: i64,
    recoveries: usize,
    backup: Option<Backup>,
    stop_until_ns: i64,
    /// Driving the path backwards (heading = path tangent + pi).
    reverse: bool,
    /// A turn at the goal made at a spot beside it.
    turn: Option<Turn>,
    pub stats: ExecutorStats,
    /// Why the last failed plan failed (the status detail stays "no_path").
    pub last_plan_error: Option<PlanError>,
}

impl Executor {
    /// With the planner and controller `cfg.plugins` names.
    pub fn new(cfg: &NavConfig) -> Executor {
        let planner = cfg.plugins.planner.build(&cfg.planner);
        Executor::with(cfg, planner, cfg.plugins.controller.build(&cfg.controller))
    }

    /// With a planner and a controller of the caller's (`cfg.plugins` is not read).
    pub fn with(cfg: &NavConfig, planner: Box<dyn GlobalPlanner>, controller: Box<dyn Controller>) -> Executor {
        Executor {
            cfg: *cfg,
            planner,
            controller,
            outline: cfg.robot.footprint.outline(0.05),
            state: State::Idle,
            detail: String::new(),
            goal: None,
            goal_start_ns: 0,
            path: TrackedPath::default(),
            last_cmd: Velocity::ZERO,
            last_plan_ns: None,
            anchor: (Pose2::default(), 0),
            rotate_start_ns: 0,
            recoveries: 0,
            backup: None,
            stop_until_ns: i64::MIN,
            reverse: false,
            turn: None,
            stats: ExecutorStats::default(),
            last_plan_error: None,
        }
    }

    pub fn state(&self) -> State {
        self.state
    }

    pub fn detail(&self) -> &str {
        &self.detail
    }

    pub fn goal(&self) -> Option<Goal> {
        self.goal
    }

    pub fn path(&self) -> &[(f64, f64)] {
        &self.path.points
    }

    /// Starts (or preempts with) a new goal.
    pub fn set_goal(&mut self, goal: Goal, t_ns: i64) {
        self.goal = Some(goal);
        self.reverse = false;
        self.turn = None;
        self.goal_start_ns = t_ns;
        self.recoveries = 0;
        self.backup = None;
        self.path = TrackedPath::default();
        self.last_plan_ns = None;
        self.set(State::Planning, "");
    }

    /// Plans again from scratch for the goal in hand (e.g. after a new map), keeping its
    /// timer and recovery count.
    pub fn restart_planning(&mut self) {
        if self.state.is_active() {
            self.backup = None;
            self.path = TrackedPath::default();
            self.last_plan_ns = None;
            self.set(State::Planning, "");
        }
    }

    /// Rejects a goal it cannot take (e.g. wrong frame).
    pub fn reject(&mut self, goal: Goal, detail: &str, t_ns: i64) {
        self.goal = Some(goal);
        self.reverse = false;
        self.turn = None;
        self.goal_start_ns = t_ns;
        self.finish(State::Failed, detail, t_ns);
    }

    fn set(&mut self, s: State, detail: &str) {
        self.state = s;
        self.detail = detail.to_string();
    }

    fn finish(&mut self, s: State, detail: &str, t_ns: i64) {
        self.set(s, detail);
        self.last_cmd = Velocity::ZERO;
        self.backup = None;
        self.stop_until_ns = t_ns + (self.cfg.executor.stop_publish_time * 1e9) as i64;
    }

    /// One control period. `pose` is the localization estimate (map frame); `world` is
    /// `None` until a map has arrived.
    pub fn tick(&mut self, t_ns: i64, pose: Option<Pose2>, world: Option<World>) -> TickOutput {
        let mut out = TickOutput::default();
        if !self.state.is_active() {
            if t_ns < self.stop_until_ns {
                out.cmd = Some(Velocity::ZERO);
            }
            return out;
        }
        let ec = self.cfg.executor;
        let goal = self.goal.expect("active without goal");
        if ec.goal_timeout > 0.0 && (t_ns - self.goal_start_ns) as f64 * 1e-9 > ec.goal_timeout {
            self.finish(State::Failed, "timeout", t_ns);
            out.cmd = Some(Velocity::ZERO);
            return out;
        }
        let (Some(pose), Some(world)) = (pose, world) else {
            let why = if pose.is_none() { "waiting for localization" } else { "waiting for map" };
            self.set(State::Planning, why);
            self.last_cmd = Velocity::ZERO;
            out.cmd = Some(Velocity::ZERO);
            return out;
        };
        let d_goal = pose.dist(&goal.pose);
        let use_yaw = goal.use_yaw && ec.yaw_goal_tolerance.is_some();

        if self.state == State::Recovering {
            match self.backup {
                Some(b) if t_ns < b.until_ns => {
                    let c = &self.cfg.controller;
                    let target = Velocity { vx: b.dir.0 * ec.backup_speed, vy: b.dir.1 * ec.backup_speed, wz: 0.0 };
                    let cmd = step_towards(c, self.last_cmd, target);
                    // Stop backing into something.
                    let next = integrate(&pose, &cmd, 0.5);
                    let clear = footprint_clearance(&self.outline, &next, &world);
                    let cmd = if clear < c.collision_margin { self.controller.brake(self.last_cmd) } else { cmd };
                    self.last_cmd = cmd;
                    out.cmd = Some(cmd);
                    return out;
                }
                _ => {
                    self.backup = None;
                    self.set(State::Planning, "");
                }
            }
        }

        if self.state == State::Planning && !self.replan(t_ns, &pose, &goal, world.global, world.local, &mut out) {
            return out;
        }

        if self.state == State::Rotating {
            if let Some(turn) = self.turn {
                out.cmd = Some(self.turn_elsewhere(turn, &pose, &goal, &world, t_ns));
                return out;
            }
            if d_goal > ec.xy_goal_tolerance {
                self.set(State::Following, "");
                self.anchor = (pose, t_ns);
            } else {
                let stuck = (t_ns - self.rotate_start_ns) as f64 * 1e-9 > 2.0 * ec.progress_timeout;
                out.cmd = Some(self.settle_yaw(&pose, &goal, &world, t_ns, stuck));
                return out;
            }
        }

        // Following.
        let deviation = self.path.project(pose.x, pose.y, 2.0);
        let stalled = (t_ns - self.anchor.1) as f64 * 1e-9 > ec.progress_timeout;
        if pose.dist(&self.anchor.0) >= ec.progress_radius {
            self.anchor = (pose, t_ns);
        }
        if d_goal <= ec.xy_latch_tolerance || (stalled && d_goal <= ec.xy_goal_tolerance) {
            self.set(State::Rotating, "");
            self.rotate_start_ns = t_ns;
            out.cmd = Some(self.settle_yaw(&pose, &goal, &world, t_ns, false));
            return out;
        }
        if stalled {
            return self.start_recovery(t_ns, &pose, world, out);
        }
        let can_replan = self.last_plan_ns.is_none_or(|t| (t_ns - t) as f64 * 1e-9 >= ec.replan_interval);
        if can_replan {
            let blocked = self.path_blocked(world.local);
            let periodic = ec.periodic_replan > 0.0
                && self.last_plan_ns.is_some_and(|t| (t_ns - t) as f64 * 1e-9 >= ec.periodic_replan);
            if blocked || deviation > ec.max_path_deviation || periodic {
                if blocked {
                    self.stats.replans_blocked += 1;
                } else if deviation > ec.max_path_deviation {
                    self.stats.replans_deviation += 1;
                }
                if !self.replan(t_ns, &pose, &goal, world.global, world.local, &mut out) {
                    return out;
                }
                self.path.project(pose.x, pose.y, 2.0);
            }
        }

        let ia = self.path.index_ahead(self.cfg.controller.lookahead);
        let carrot = self.path.points[ia];
        let near_goal =
            self.path.remaining() <= ec.goal_heading_distance.max(1e-9) || d_goal <= ec.goal_heading_distance;
        let desired_yaw = if near_goal {
            if use_yaw {
                goal.pose.yaw
            } else {
                pose.yaw
            }
        } else {
            self.travel_heading(self.path.tangent(ia), pose.yaw)
        };
        let req = Request {
            pose,
            current: self.last_cmd,
            path: self.path.ahead(self.cfg.controller.lookahead + 0.5),
            carrot,
            desired_yaw,
        };
        let d = self.controller.compute_velocity(&req, &self.outline, &Obstacles::new(world.global, world.local));
        if !d.valid {
            self.stats.controller_failures += 1;
        }
        self.last_cmd = d.cmd;
        out.cmd = Some(d.cmd);
        out
    }

    /// The heading to follow a path of tangent `tangent` with: the tangent, or its reverse
    /// when that is nearer the robot's heading (by more than `REVERSE_HYSTERESIS` to switch).
    /// The base is omnidirectional and its LiDAR sees all around, so it never has to turn
    /// about in an aisle (a 1.2 m base turning in a 2 m aisle off its centre line wedged
    /// itself against a row with no valid roll-out: blocked-aisles trial 132).
    fn travel_heading(&mut self, tangent: f64, yaw: f64) -> f64 {
        let forward = wrap_angle(tangent - yaw).abs();
        let backward = wrap_angle(tangent + std::f64::consts::PI - yaw).abs();
        let (now, other) = if self.reverse { (backward, forward) } else { (forward, backward) };
        if other + REVERSE_HYSTERESIS < now {
            self.reverse = !self.reverse;
        }
        if self.reverse {
            wrap_angle(tangent + std::f64::consts::PI)
        } else {
            tangent
        }
    }

    /// The rotate phase's command: turn in place if the footprint sweeps clear of obstacles
    /// on the way to the goal yaw, else let the local planner turn and shift at once (goal as
    /// carrot, goal yaw as heading) so a long base can still turn near a row.
    /// At the goal position: succeeded when the yaw is right (or not asked for), failed when
    /// `stuck`, else the command that turns toward the goal yaw.
    fn settle_yaw(&mut self, pose: &Pose2, goal: &Goal, world: &World, t_ns: i64, stuck: bool) -> Velocity {
        let ec = &self.cfg.executor;
        let use_yaw = goal.use_yaw && ec.yaw_goal_tolerance.is_some();
        let err = wrap_angle(goal.pose.yaw - pose.yaw);
        if !use_yaw || err.abs() <= ec.yaw_goal_tolerance.unwrap_or(f64::INFINITY) {
            self.finish(State::Succeeded, "", t_ns);
            return Velocity::ZERO;
        }
        if stuck {
            self.finish(State::Failed, "stuck", t_ns);
            return Velocity::ZERO;
        }
        let cmd = self.rotate(pose, goal, err, world, t_ns);
        self.last_cmd = cmd;
        cmd
    }

    fn rotate(&mut self, pose: &Pose2, goal: &Goal, err: f64, world: &World, t_ns: i64) -> Velocity {
        let margin = self.cfg.controller.collision_margin;
        let clearance = |p: &Pose2| footprint_clearance(&self.outline, p, world);
        if super::turn_spot::turn_clear(pose.x, pose.y, pose.yaw, pose.yaw + err, margin, &clearance) {
            return self.controller.rotate_in_place(self.last_cmd, err);
        }
        if let Some((spot, back)) = super::turn_spot::find(pose, &goal.pose, margin, clearance) {
            let turn = Turn { spot, back, out_yaw: pose.yaw, phase: TurnPhase::Out };
            self.turn = Some(turn);
            self.rotate_start_ns = t_ns;
            return self.turn_elsewhere(turn, pose, goal, world, t_ns);
        }
        let path = [(pose.x, pose.y), (goal.pose.x, goal.pose.y)];
        let req = Request {
            pose: *pose,
            current: self.last_cmd,
            path: &path,
            carrot: (goal.pose.x, goal.pose.y),
            desired_yaw: goal.pose.yaw,
        };
        self.controller.compute_velocity(&req, &self.outline, &Obstacles::new(world.global, world.local)).cmd
    }

    /// The command of a turn made at a spot beside the goal; fails "stuck" when it takes
    /// longer than a turn in place may.
    fn turn_elsewhere(&mut self, mut turn: Turn, pose: &Pose2, goal: &Goal, world: &World, t_ns: i64) -> Velocity {
        let ec = self.cfg.executor;
        if (t_ns - self.rotate_start_ns) as f64 * 1e-9 > 2.0 * ec.progress_timeout {
            self.turn = None;
            self.finish(State::Failed, "stuck", t_ns);
            return Velocity::ZERO;
        }
        if turn.phase == TurnPhase::Out && (pose.x - turn.spot.0).hypot(pose.y - turn.spot.1) <= SPOT_TOLERANCE {
            turn.phase = TurnPhase::Turn;
        }
        let err = wrap_angle(goal.pose.yaw - pose.yaw);
        if turn.phase == TurnPhase::Turn && err.abs() <= 0.5 * ec.yaw_goal_tolerance.unwrap_or(0.1) {
            turn.phase = TurnPhase::Back;
        }
        if turn.phase == TurnPhase::Back && (pose.x - turn.back.0).hypot(pose.y - turn.back.1) <= SPOT_TOLERANCE {
            self.turn = None;
            return self.settle_yaw(pose, goal, world, t_ns, false);
        }
        self.turn = Some(turn);
        let cmd = match turn.phase {
            TurnPhase::Out => self.shift(pose, turn.spot, turn.out_yaw),
            TurnPhase::Turn => self.controller.rotate_in_place(self.last_cmd, err),
            TurnPhase::Back => self.shift(pose, turn.back, goal.pose.yaw),
        };
        self.last_cmd = cmd;
        cmd
    }

    /// A straight holonomic shift towards `to` holding heading `yaw` (checked clear when the
    /// turning spot was chosen), within the controller's limits.
    fn shift(&self, pose: &Pose2, to: (f64, f64), yaw: f64) -> Velocity {
        let c = &self.cfg.controller;
        let (dx, dy) = (to.0 - pose.x, to.1 - pose.y);
        let (s, co) = pose.yaw.sin_cos();
        let (bx, by) = (co * dx + s * dy, -s * dx + co * dy);
        let d = bx.hypot(by);
        let speed = (SHIFT_GAIN * d).min(SHIFT_SPEED);
        let (vx, vy) = if d > 1e-9 { (bx / d * speed, by / d * speed) } else { (0.0, 0.0) };
        let wz = (c.rotate_gain * wrap_angle(yaw - pose.yaw)).clamp(-c.max_wz, c.max_wz);
        step_towards(c, self.last_cmd, Velocity { vx, vy, wz })
    }

    /// Plans from `pose` after taking the sensed obstacles into the global costmap. Returns
    /// false (and fails the goal) when there is no path.
    fn replan(
        &mut self,
        t_ns: i64,
        pose: &Pose2,
        goal: &Goal,
        global: &mut GlobalCostmap,
        local: &LocalCostmap,
        out: &mut TickOutput,
    ) -> bool {
        sync_blocked(global, local);
        self.last_plan_ns = Some(t_ns);
        self.stats.plans += 1;
        match self.planner.plan(global, pose, &goal.pose) {
            Ok(pts) => {
                self.path = TrackedPath::new(pts.clone());
                out.plan = Some(pts);
                if self.state != State::Following {
                    self.anchor = (*pose, t_ns);
                }
                self.set(State::Following, "");
                true
            }
            Err(e) => {
                self.last_plan_error = Some(e);
                self.finish(State::Failed, "no_path", t_ns);
                out.cmd = Some(Velocity::ZERO);
                out.plan = Some(Vec::new());
                false
            }
        }
    }

    /// Is a sensed obstacle within the inscribed radius of the path ahead?
    fn path_blocked(&self, local: &LocalCostmap) -> bool {
        if local.occupied_count() == 0 {
            return false;
        }
        let r = self.cfg.robot.footprint.inscribed_radius();
        self.path.ahead(self.cfg.executor.blocked_lookahead).iter().any(|&(x, y)| local.center_distance_at(x, y) <= r)
    }

    /// Clear the local costmap, back off towards the most open side, then replan; fail
    /// "stuck" when out of attempts.
    fn start_recovery(&mut self, t_ns: i64, pose: &Pose2, world: World, mut out: TickOutput) -> TickOutput {
        if self.recoveries >= self.cfg.executor.max_recoveries {
            self.finish(State::Failed, "stuck", t_ns);
            out.cmd = Some(Velocity::ZERO);
            return out;
        }
        self.recoveries += 1;
        self.stats.recoveries += 1;
        world.local.clear();
        let ec = self.cfg.executor;
        let dist = ec.backup_speed * ec.backup_time;
        let mut best: Option<(f64, (f64, f64))> = None;
        for k in 0..16 {
            let a = k as f64 * std::f64::consts::TAU / 16.0;
            let dir = (a.cos(), a.sin());
            let mut clear = f64::INFINITY;
            for s in 1..=4 {
                let p = pose.compose(&Pose2::new(dir.0 * dist * s as f64 / 4.0, dir.1 * dist * s as f64 / 4.0, 0.0));
                clear = clear.min(footprint_clearance(&self.outline, &p, &world));
            }
            if best.is_none_or(|(b, _)| clear > b + 1e-9) {
                best = Some((clear, dir));
            }
        }
        let (_, dir) = best.unwrap();
        self.backup = Some(Backup { until_ns: t_ns + (ec.backup_time * 1e9) as i64, dir });
        self.anchor = (*pose, t_ns);
        self.set(State::Recovering, "");
        self.last_cmd = self.controller.brake(self.last_cmd);
        out.cmd = Some(self.last_cmd);
        out
    }
}

/// Carries the local costmap's knowledge into the global one: cells seen occupied become
/// blocked, blocked cells seen free are released.
pub fn sync_blocked(global: &mut GlobalCostmap, local: &LocalCostmap) {
    let cells: Vec<(f64, f64, bool)> = local.observed_cells().collect();
    for (x, y, occ) in cells {
        if let Some(i) = global.geom.index_of(x, y) {
            if occ {
                global.add_blocked(i);
            } else {
                global.clear_blocked(i);
            }
        }
    }
    global.update();
}

fn footprint_clearance(outline: &[(f64, f64)], p: &Pose2, world: &World) -> f64 {
    super::footprint::Footprint::clearance(outline, p, |x, y| {
        world.global.distance_at(x, y).min(world.local.distance_at(x, y))
    })
}

/// One acceleration-limited step from `current` towards `target`.
fn step_towards(c: &ControllerConfig, current: Velocity, target: Velocity) -> Velocity {
    let lim =
        |cur: f64, tgt: f64, max: f64, acc: f64| tgt.clamp(-max, max).clamp(cur - acc * c.period, cur + acc * c.period);
    Velocity {
        vx: lim(current.vx, target.vx, c.max_vx, c.acc_xy),
        vy: lim(current.vy, target.vy, c.max_vy, c.acc_xy),
        wz: lim(current.wz, target.wz, c.max_wz, c.acc_wz),
    }
}
