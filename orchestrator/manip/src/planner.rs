//! `plan`: validate the start and goals, RRT-Connect to the goal set, shortcut, then the exact
//! (parry) check of the final path. Budgets are iteration counts; wall time is measured for
//! the statistics only and never changes the result.

use crate::checker::{Checker, Context};
use crate::exact::{exact_check, PathContact, EXACT_RESOLUTION};
use crate::layout::DOF;
use crate::rrt_connect::{rrt_connect, RrtConfig};
use crate::shortcut::{path_length, shortcut};
use agrisim_math::Rng;
use std::time::Instant;

type Q = [f64; DOF];

#[derive(Debug, Clone, Copy)]
pub struct PlannerConfig {
    pub rrt: RrtConfig,
    /// Random shortcut attempts after a path is found.
    pub shortcut_iterations: usize,
    /// Run the exact check on the final path (recommended; it is what makes a plan safe).
    pub exact_check: bool,
    /// Joint resolution of the exact check (rad).
    pub exact_resolution: f64,
}

impl Default for PlannerConfig {
    fn default() -> Self {
        PlannerConfig {
            rrt: RrtConfig::default(),
            shortcut_iterations: 100,
            exact_check: true,
            exact_resolution: EXACT_RESOLUTION,
        }
    }
}

/// Plan statistics (times are measured, informative only).
#[derive(Debug, Clone, Default)]
pub struct PlanStats {
    pub iterations: usize,
    pub tree_nodes: usize,
    /// Sphere-model configuration checks.
    pub collision_checks: u64,
    pub raw_waypoints: usize,
    /// Joint-space length before and after shortcutting (rad).
    pub raw_length: f64,
    pub length: f64,
    /// Goals left after removing invalid ones.
    pub valid_goals: usize,
    pub planning_time_s: f64,
    /// Part of `planning_time_s` spent in the exact check.
    pub exact_time_s: f64,
}

/// A collision-free joint path from the start to one of the goals.
#[derive(Debug, Clone)]
pub struct Plan {
    /// Start first, goal last.
    pub waypoints: Vec<Q>,
    /// Index into the `goals` passed to `plan`.
    pub goal_index: usize,
    pub stats: PlanStats,
}

#[derive(Debug, Clone, PartialEq)]
pub enum PlanError {
    /// Start outside the joint limits.
    StartOutOfLimits,
    /// The start is in collision (with what).
    StartInCollision(String),
    /// No goal given, or every goal is out of limits or in collision.
    NoValidGoal,
    /// RRT-Connect used its iteration budget.
    NoPath { iterations: usize },
    /// The final path failed the exact check.
    ExactCheckFailed(PathContact),
}

impl std::fmt::Display for PlanError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PlanError::StartOutOfLimits => {
                write!(f, "start configuration outside the joint limits")
            }
            PlanError::StartInCollision(c) => write!(f, "start configuration in collision: {c}"),
            PlanError::NoValidGoal => {
                write!(f, "no valid goal configuration (none, or all in collision or out of limits)")
            }
            PlanError::NoPath { iterations } => {
                write!(f, "no path found in {iterations} RRT-Connect iterations")
            }
            PlanError::ExactCheckFailed(c) => {
                write!(f, "final path fails the exact check at segment {}: {}", c.segment, c.description)
            }
        }
    }
}

impl std::error::Error for PlanError {}

/// The motion planner of one arm.
#[derive(Debug, Clone, Copy, Default)]
pub struct Planner {
    pub config: PlannerConfig,
}

impl Planner {
    pub fn new(config: PlannerConfig) -> Planner {
        Planner { config }
    }

    /// Plans from `start` to any of `goals` in `ctx`. Deterministic for a given `rng` state.
    pub fn plan(&self, ctx: &Context, start: &Q, goals: &[Q], rng: &mut Rng) -> Result<Plan, PlanError> {
        let t0 = Instant::now();
        let checker = Checker::new(*ctx);
        let cfg = &self.config;
        if !ctx.arm.within_limits(start) {
            return Err(PlanError::StartOutOfLimits);
        }
        if let Some(c) = checker.contact(start) {
            return Err(PlanError::StartInCollision(c.describe(ctx)));
        }
        let valid: Vec<(usize, Q)> = goals.iter().copied().enumerate().filter(|(_, g)| checker.is_valid(g)).collect();
        if valid.is_empty() {
            return Err(PlanError::NoValidGoal);
        }
        let mut stats = PlanStats { valid_goals: valid.len(), ..Default::default() };
        // Direct connection first: in open space it is the whole answer.
        let direct = valid.iter().find(|(_, g)| checker.edge_valid(start, g, cfg.rrt.resolution));
        let (mut path, goal_index) = if let Some((i, g)) = direct {
            (vec![*start, *g], *i)
        } else {
            let goal_qs: Vec<Q> = valid.iter().map(|(_, g)| *g).collect();
            let r = rrt_connect(&checker, start, &goal_qs, &cfg.rrt, rng)
                .ok_or(PlanError::NoPath { iterations: cfg.rrt.max_iterations })?;
            stats.iterations = r.iterations;
            stats.tree_nodes = r.nodes;
            (r.waypoints, valid[r.goal].0)
        };
        stats.raw_waypoints = path.len();
        stats.raw_length = path_length(&path);
        shortcut(&mut path, &checker, cfg.rrt.resolution, cfg.shortcut_iterations, rng);
        stats.length = path_length(&path);
        stats.collision_checks = checker.checks();
        if cfg.exact_check {
            let te = Instant::now();
            let r = exact_check(ctx, &path, cfg.exact_resolution);
            stats.exact_time_s = te.elapsed().as_secs_f64();
            r.map_err(PlanError::ExactCheckFailed)?;
        }
        stats.planning_time_s = t0.elapsed().as_secs_f64();
        Ok(Plan { waypoints: path, goal_index, stats })
    }

    /// [`Planner::plan`] from a start that touches something (a hand ended against a leaf,
    /// or within the padding of the other hand after a handover), which `plan` refuses, and
    /// with it every later plan from there; what MoveIt's FixStartStateCollision adapter
    /// does. Configurations are drawn about the start, at most [`UNSTICK_STEPS`] rad per
    /// joint, the smallest first; the first valid one whose straight way from the start is
    /// valid beyond its first third (it leaves the contact, not through it) is planned from,
    /// and the start put before it. Other errors of `plan` are returned as they are.
    pub fn plan_out_of_contact(&self, ctx: &Context, start: &Q, goals: &[Q], rng: &mut Rng) -> Result<Plan, PlanError> {
        let first = match self.plan(ctx, start, goals, rng) {
            Err(PlanError::StartInCollision(what)) => PlanError::StartInCollision(what),
            r => return r,
        };
        let checker = Checker::new(*ctx);
        let res = self.config.rrt.resolution;
        for scale in UNSTICK_STEPS {
            for _ in 0..UNSTICK_DRAWS {
                let q: Q = std::array::from_fn(|i| start[i] + scale * (2.0 * rng.uniform() - 1.0));
                let n = crate::checker::steps(start, &q, res);
                let leaves =
                    (n / 3..=n).all(|k| checker.is_valid(&crate::checker::lerp(start, &q, k as f64 / n as f64)));
                if !leaves {
                    continue;
                }
                let mut p = self.plan(ctx, &q, goals, rng)?;
                p.waypoints.insert(0, *start);
                return Ok(p);
            }
        }
        Err(first)
    }
}

/// How far [`Planner::plan_out_of_contact`] looks about a start in contact [rad per joint],
/// step by step.
pub const UNSTICK_STEPS: [f64; 4] = [0.02, 0.05, 0.1, 0.2];
/// Configurations drawn at each step.
pub const UNSTICK_DRAWS: usize = 20;
