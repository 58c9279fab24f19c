//! Time-optimal path parameterization by reachability analysis (TOPP-RA).
//!
//! Pham & Pham, "A New Approach to Time-Optimal Path Parameterization Based on Reachability
//! Analysis", IEEE T-RO 34(3), 2018. With x = ṡ² and u = s̈ (constant on each grid segment,
//! so x_{i+1} = x_i + 2 Δ_i u_i), joint velocity and acceleration limits are linear in (u, x):
//!   |q'_j(s_i)| ṡ <= v_j        ->  x_i <= (v_j / |q'_j(s_i)|)²
//!   |q'_j u + q''_j x| <= a_j    (q̈ = q' s̈ + q'' ṡ²)
//! A backward pass computes the controllable sets K_i (states from which the end state is
//! reachable) with two 2-variable LPs per stage; a greedy forward pass then takes the largest
//! u that keeps x_{i+1} in K_{i+1}. Matching toppra 0.6.10 (the cross-check reference):
//! - the acceleration constraint uses toppra's default *interpolation* discretization: the
//!   constraint at stage i also holds at s_{i+1} with x_{i+1} = x_i + 2 Δ_i u_i
//!   ([`Discretization::Collocation`] constrains s_i only);
//! - forward-pass safeguards: each x_{i+1} is shrunk by max(1e-8, 0.01 %) and clamped into
//!   K_{i+1}; a failed step retries with x_i reduced by max(1e-8, 0.1 %), at most 10 times;
//! - duration = Σ Δ_i / ((ṡ_i + ṡ_{i+1}) / 2) (exact for constant s̈ per segment);
//! - variables boxed to |u|, x <= 1e8 as toppra's Seidel solver wrapper does.
//!
//! The returned trajectory is the exact constant-s̈-per-segment motion (toppra's
//! `ParametrizeConstAccel`), so sampled accelerations are those the constraints saw.

use std::fmt;

use crate::grid::{gridpoints, GridSpec};
use crate::lp2d::{max_u_at_x, maximize, Row};
use crate::path::JointPath;
use crate::sampled::Trajectory;

/// Box on u and x (toppra's Seidel wrapper VAR_MIN/VAR_MAX).
const VAR_MAX: f64 = 1e8;
/// Initial-state tolerance on K_0 (toppra constants.SMALL).
const SMALL: f64 = 1e-5;
/// toppra constants.TINY.
const TINY: f64 = 1e-8;
/// toppra constants.MAX_TRIES.
const MAX_TRIES: usize = 10;

/// How the acceleration constraint is imposed on the grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Discretization {
    /// toppra's default for joint acceleration: stage i constrains s_i and s_{i+1}.
    #[default]
    Interpolation,
    /// Stage i constrains s_i only.
    Collocation,
}

/// TOPP-RA inputs besides the path. Limits are symmetric per joint (|qd_j| <= v_j, |qdd_j| <= a_j).
#[derive(Debug, Clone, PartialEq)]
pub struct ToppraProblem {
    pub max_velocity: Vec<f64>,
    pub max_acceleration: Vec<f64>,
    pub grid: GridSpec,
    pub discretization: Discretization,
}

impl ToppraProblem {
    /// Velocity and acceleration limits with toppra's defaults (automatic grid, interpolation).
    pub fn new(max_velocity: Vec<f64>, max_acceleration: Vec<f64>) -> Self {
        ToppraProblem {
            max_velocity,
            max_acceleration,
            grid: GridSpec::Auto,
            discretization: Discretization::Interpolation,
        }
    }
}

/// Why no parameterization was produced.
#[derive(Debug, Clone, PartialEq)]
pub enum ToppraError {
    /// Limits missing, of the wrong length, non-finite or not positive.
    BadLimits(String),
    /// The grid could not be built.
    BadGrid(String),
    /// The backward pass found an empty controllable set at this stage.
    Uncontrollable { stage: usize },
    /// Rest is not a controllable start state (K_0 excludes 0).
    StartNotControllable { k0: (f64, f64) },
    /// The forward pass failed at this stage after the allowed retries (numerical trouble).
    ForwardPassFailed { stage: usize },
    /// Path velocity is ~0 over a segment, the duration would be unbounded.
    Stalled { stage: usize },
    /// [`parameterize_within_limits`] still saw samples beyond the limits after its rounds.
    LimitsNotMet { rounds: usize },
}

impl fmt::Display for ToppraError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ToppraError::BadLimits(m) => write!(f, "TOPP-RA: bad limits: {m}"),
            ToppraError::BadGrid(m) => write!(f, "TOPP-RA: bad grid: {m}"),
            ToppraError::Uncontrollable { stage } => {
                write!(f, "TOPP-RA: path not controllable (empty set at stage {stage})")
            }
            ToppraError::StartNotControllable { k0 } => {
                write!(f, "TOPP-RA: rest start not controllable, K0 = [{}, {}]", k0.0, k0.1)
            }
            ToppraError::ForwardPassFailed { stage } => {
                write!(f, "TOPP-RA: forward pass failed at stage {stage}")
            }
            ToppraError::Stalled { stage } => {
                write!(f, "TOPP-RA: path velocity vanishes on segment {stage}")
            }
            ToppraError::LimitsNotMet { rounds } => {
                write!(f, "TOPP-RA: samples still beyond the limits after {rounds} rounds")
            }
        }
    }
}

impl std::error::Error for ToppraError {}

/// A time-parameterized path: owns the path and the ṡ² profile on the grid.
#[derive(Debug, Clone)]
pub struct ToppraTrajectory<P> {
    path: P,
    s: Vec<f64>,
    x: Vec<f64>,
    u: Vec<f64>,
    t: Vec<f64>,
    controllable: Vec<(f64, f64)>,
}

impl<P> ToppraTrajectory<P> {
    /// Gridpoints s_0..s_N.
    pub fn gridpoints(&self) -> &[f64] {
        &self.s
    }
    /// ṡ² at the gridpoints (0 at both ends).
    pub fn sd_squared(&self) -> &[f64] {
        &self.x
    }
    /// s̈ on each of the N segments, consistent with [`Self::sd_squared`].
    pub fn sdd(&self) -> &[f64] {
        &self.u
    }
    /// Time at each gridpoint (0 at s_0).
    pub fn grid_times(&self) -> &[f64] {
        &self.t
    }
    /// Controllable sets K_i = [lo, hi] of ṡ² from the backward pass.
    pub fn controllable_sets(&self) -> &[(f64, f64)] {
        &self.controllable
    }
    /// The parameterized path.
    pub fn path(&self) -> &P {
        &self.path
    }
}

/// Time-optimal rest-to-rest parameterization of `path` under `problem`'s limits.
pub fn parameterize<P: JointPath>(path: P, problem: &ToppraProblem) -> Result<ToppraTrajectory<P>, ToppraError> {
    let dof = path.dof();
    for (name, lim) in [("velocity", &problem.max_velocity), ("acceleration", &problem.max_acceleration)] {
        if lim.len() != dof {
            return Err(ToppraError::BadLimits(format!("{} {name} limits for {dof} joints", lim.len())));
        }
        if let Some(j) = lim.iter().position(|v| !(v.is_finite() && *v > 0.0)) {
            return Err(ToppraError::BadLimits(format!("{name} limit of joint {j} is {}", lim[j])));
        }
    }
    let s = gridpoints(&path, &problem.grid).map_err(ToppraError::BadGrid)?;
    let n = s.len() - 1;
    let delta: Vec<f64> = s.windows(2).map(|w| w[1] - w[0]).collect();

    // Path derivatives at the gridpoints.
    let (mut q, mut dq, mut ddq) = (vec![0.0; dof], vec![0.0; dof], vec![0.0; dof]);
    let mut d1 = vec![0.0; (n + 1) * dof];
    let mut d2 = vec![0.0; (n + 1) * dof];
    let mut x_max = vec![VAR_MAX; n + 1];
    for i in 0..=n {
        path.eval(s[i], &mut q, &mut dq, &mut ddq);
        d1[i * dof..(i + 1) * dof].copy_from_slice(&dq);
        d2[i * dof..(i + 1) * dof].copy_from_slice(&ddq);
        for (d, v) in dq.iter().zip(&problem.max_velocity) {
            if d.abs() > TINY {
                x_max[i] = x_max[i].min((v / d).powi(2));
            }
        }
    }

    // Stage rows: 2 slots for the K_{i+1} constraint first, then the acceleration rows.
    let per_point = 2 * dof;
    let stride = 2 + 2 * per_point;
    let mut rows = vec![Row { a: 0.0, b: 0.0, g: 1.0 }; (n + 1) * stride];
    let mut nrows = vec![0usize; n + 1];
    for i in 0..=n {
        let base = i * stride;
        let mut k = 2;
        for j in 0..dof {
            let (a, b, lim) = (d1[i * dof + j], d2[i * dof + j], problem.max_acceleration[j]);
            rows[base + k] = Row { a, b, g: lim };
            rows[base + k + 1] = Row { a: -a, b: -b, g: lim };
            k += 2;
        }
        if i < n && problem.discretization == Discretization::Interpolation {
            for j in 0..dof {
                let (a1, b1, lim) = (d1[(i + 1) * dof + j], d2[(i + 1) * dof + j], problem.max_acceleration[j]);
                let a = a1 + 2.0 * delta[i] * b1;
                rows[base + k] = Row { a, b: b1, g: lim };
                rows[base + k + 1] = Row { a: -a, b: -b1, g: lim };
                k += 2;
            }
        }
        nrows[i] = k;
    }
    let set_next = |rows: &mut [Row], i: usize, lo: f64, hi: f64| {
        let base = i * stride;
        rows[base] = Row { a: 2.0 * delta[i], b: 1.0, g: hi };
        rows[base + 1] = Row { a: -2.0 * delta[i], b: -1.0, g: -lo };
    };

    // Backward pass: controllable sets, ending at rest.
    let mut kset = vec![(0.0, 0.0); n + 1];
    for i in (0..n).rev() {
        let (lo_next, hi_next) = kset[i + 1];
        set_next(&mut rows, i, lo_next, hi_next);
        let stage = &rows[i * stride..i * stride + nrows[i]];
        let (blo, bhi) = ([-VAR_MAX, 0.0], [VAR_MAX, x_max[i]]);
        let up = maximize([-1e-9, 1.0], stage, blo, bhi).ok_or(ToppraError::Uncontrollable { stage: i })?;
        let down = maximize([1e-9, -1.0], stage, blo, bhi).ok_or(ToppraError::Uncontrollable { stage: i })?;
        kset[i] = (down[1].max(0.0), up[1]);
    }

    // Forward pass: greedy, from rest.
    let mut x = vec![0.0; n + 1];
    if x[0] + SMALL < kset[0].0 || kset[0].1 + SMALL < x[0] {
        return Err(ToppraError::StartNotControllable { k0: kset[0] });
    }
    let mut tries = 0;
    let mut i = 0;
    while i < n {
        let (lo_next, hi_next) = kset[i + 1];
        set_next(&mut rows, i, lo_next, hi_next);
        let stage = &rows[i * stride..i * stride + nrows[i]];
        let step = if x[i] <= x_max[i] { max_u_at_x(x[i], stage, -VAR_MAX, VAR_MAX) } else { None };
        match step {
            None => {
                if tries >= MAX_TRIES {
                    return Err(ToppraError::ForwardPassFailed { stage: i });
                }
                x[i] = (x[i] - TINY).max(0.999 * x[i]);
                tries += 1;
            }
            Some(u) => {
                tries = 0;
                let next = x[i] + 2.0 * delta[i] * u;
                let next = (next - TINY).max(0.9999 * next);
                x[i + 1] = next.max(lo_next).min(hi_next);
                i += 1;
            }
        }
    }

    // Segment accelerations consistent with the (clamped) x, and grid times.
    let u: Vec<f64> = (0..n).map(|i| (x[i + 1] - x[i]) / (2.0 * delta[i])).collect();
    let mut t = vec![0.0; n + 1];
    for i in 0..n {
        let sd_avg = 0.5 * (x[i].max(0.0).sqrt() + x[i + 1].max(0.0).sqrt());
        if sd_avg <= TINY {
            return Err(ToppraError::Stalled { stage: i });
        }
        t[i + 1] = t[i] + delta[i] / sd_avg;
    }
    Ok(ToppraTrajectory { path, s, x, u, t, controllable: kset })
}

/// TOPP-RA constrains the gridpoints only; between them a joint may exceed its velocity or
/// acceleration limit by O(Δs) (up to ~1 % on toppra's default grid). This solves, samples at
/// `dt` (the period the trajectory will be sent at), and while some joint's samples exceed
/// its limit·(1 + rel_tol) re-solves with that joint's limit lowered by the excess (0.1 %
/// more), at most `max_rounds` solves. The result then passes [`crate::limits::check`] at `dt`.
pub fn parameterize_within_limits<P: JointPath + Clone>(
    path: P,
    problem: &ToppraProblem,
    dt: f64,
    rel_tol: f64,
    max_rounds: usize,
) -> Result<ToppraTrajectory<P>, ToppraError> {
    let mut p = problem.clone();
    for _ in 0..max_rounds {
        let traj = parameterize(path.clone(), &p)?;
        let smp = crate::sampled::sample(&traj, dt);
        let dof = traj.path.dof();
        let mut peak_v = vec![0.0_f64; dof];
        let mut peak_a = vec![0.0_f64; dof];
        for k in 0..smp.len() {
            for j in 0..dof {
                peak_v[j] = peak_v[j].max(smp.qd[k][j].abs());
                peak_a[j] = peak_a[j].max(smp.qdd[k][j].abs());
            }
        }
        let mut ok = true;
        for j in 0..dof {
            if peak_v[j] > problem.max_velocity[j] * (1.0 + rel_tol) {
                p.max_velocity[j] *= problem.max_velocity[j] / peak_v[j] * 0.999;
                ok = false;
            }
            if peak_a[j] > problem.max_acceleration[j] * (1.0 + rel_tol) {
                p.max_acceleration[j] *= problem.max_acceleration[j] / peak_a[j] * 0.999;
                ok = false;
            }
        }
        if ok {
            return Ok(traj);
        }
    }
    Err(ToppraError::LimitsNotMet { rounds: max_rounds })
}

impl<P: JointPath> Trajectory for ToppraTrajectory<P> {
    fn dof(&self) -> usize {
        self.path.dof()
    }

    fn duration(&self) -> f64 {
        self.t[self.t.len() - 1]
    }

    fn state_at(&self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]) {
        let n = self.s.len() - 1;
        let t = t.clamp(0.0, self.duration());
        let i = self.t[1..n].partition_point(|&ti| ti <= t);
        let tau = t - self.t[i];
        let sd0 = self.x[i].max(0.0).sqrt();
        let u = self.u[i];
        let s = (self.s[i] + sd0 * tau + 0.5 * u * tau * tau).clamp(self.s[i], self.s[i + 1]);
        let sd = (sd0 + u * tau).max(0.0);
        let dof = self.path.dof();
        let mut dq = vec![0.0; dof];
        let mut ddq = vec![0.0; dof];
        self.path.eval(s, q, &mut dq, &mut ddq);
        for j in 0..dof {
            qd[j] = dq[j] * sd;
            qdd[j] = dq[j] * u + ddq[j] * sd * sd;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spline::{CubicSplinePath, SplineEnd};

    /// Rest-to-rest minimum time over distance d with |v| <= v, |a| <= a (trapezoid or triangle).
    fn bang_bang_time(d: f64, v: f64, a: f64) -> f64 {
        if d * a <= v * v {
            2.0 * (d / a).sqrt()
        } else {
            d / v + v / a
        }
    }

    #[test]
    fn straight_line_matches_closed_form_trapezoid_and_triangle() {
        for &(d, v, a) in &[(1.0, 0.5, 2.0), (2.0, 2.175, 15.0), (0.1, 2.0, 1.0), (3.0, 1.0, 0.7)] {
            let path = CubicSplinePath::new(&[0.0, 1.0], &[vec![0.0], vec![d]], SplineEnd::NotAKnot).unwrap();
            for (grid, tol) in [(GridSpec::Uniform(101), 2e-2), (GridSpec::Uniform(1001), 2e-3)] {
                let problem = ToppraProblem { grid: grid.clone(), ..ToppraProblem::new(vec![v], vec![a]) };
                let tr = parameterize(path.clone(), &problem).unwrap();
                let want = bang_bang_time(d, v, a);
                let rel = (tr.duration() - want) / want;
                // Grid discretization only makes TOPP-RA slower (never faster than optimal).
                assert!(rel > -1e-9 && rel < tol, "d={d} v={v} a={a} {grid:?}: {} vs {want}", tr.duration());
            }
        }
    }

    #[test]
    fn sampled_trajectory_respects_limits_and_reaches_the_end() {
        let ss = [0.0, 0.4, 1.0, 1.3];
        let w = vec![vec![0.0, 1.0], vec![0.5, 0.2], vec![0.9, -0.4], vec![1.5, 0.0]];
        let path = CubicSplinePath::new(&ss, &w, SplineEnd::NotAKnot).unwrap();
        let problem = ToppraProblem::new(vec![1.0, 0.8], vec![3.0, 2.0]);
        let tr = parameterize(path, &problem).unwrap();
        let smp = crate::sampled::sample(&tr, 0.001);
        let last = smp.q.last().unwrap();
        assert!((last[0] - 1.5).abs() < 1e-9 && last[1].abs() < 1e-9);
        assert!(smp.qd[0].iter().chain(smp.qd.last().unwrap()).all(|v| v.abs() < 1e-9));
        let mut vmax_seen = 0.0_f64;
        for k in 0..smp.len() {
            for j in 0..2 {
                assert!(smp.qd[k][j].abs() <= problem.max_velocity[j] * 1.01);
                assert!(smp.qdd[k][j].abs() <= problem.max_acceleration[j] * 1.02);
                vmax_seen = vmax_seen.max(smp.qd[k][j].abs() / problem.max_velocity[j]);
            }
        }
        // Time-optimal: some limit is active (here the velocity limit is reached).
        assert!(vmax_seen > 0.97, "{vmax_seen}");
    }

    #[test]
    fn within_limits_variant_passes_the_checker_at_its_sample_rate() {
        let ss = [0.0, 0.3, 0.5, 1.0];
        let w = vec![vec![0.0, 1.0, -0.5], vec![1.2, 0.2, 0.4], vec![0.3, -0.9, 1.1], vec![1.5, 0.0, 0.2]];
        let path = CubicSplinePath::new(&ss, &w, SplineEnd::NotAKnot).unwrap();
        let problem = ToppraProblem {
            grid: GridSpec::Uniform(40),
            ..ToppraProblem::new(vec![1.0, 0.8, 1.2], vec![3.0, 2.0, 4.0])
        };
        let lim = crate::limits::JointLimits {
            velocity: problem.max_velocity.clone(),
            acceleration: problem.max_acceleration.clone(),
            ..Default::default()
        };
        // The coarse grid lets the plain solution overshoot between gridpoints ...
        let plain = parameterize(path.clone(), &problem).unwrap();
        assert!(crate::limits::check(&crate::sampled::sample(&plain, 0.001), &lim, 1e-6).is_err());
        // ... the verified one does not, at a small cost in duration.
        let safe = parameterize_within_limits(path, &problem, 0.001, 1e-6, 8).unwrap();
        crate::limits::check(&crate::sampled::sample(&safe, 0.001), &lim, 1e-6).unwrap();
        assert!(safe.duration() >= plain.duration() && safe.duration() < 1.1 * plain.duration());
    }

    #[test]
    fn bad_limits_are_rejected() {
        let path = CubicSplinePath::new(&[0.0, 1.0], &[vec![0.0], vec![1.0]], SplineEnd::NotAKnot).unwrap();
        assert!(matches!(
            parameterize(path.clone(), &ToppraProblem::new(vec![1.0, 1.0], vec![1.0])),
            Err(ToppraError::BadLimits(_))
        ));
        assert!(matches!(
            parameterize(path, &ToppraProblem::new(vec![0.0], vec![1.0])),
            Err(ToppraError::BadLimits(_))
        ));
    }
}
