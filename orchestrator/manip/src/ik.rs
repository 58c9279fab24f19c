//! Inverse kinematics with a high success rate on reachable targets.
//!
//! Plain Newton-Raphson with clamping (KDL, see [`crate::kdl`]) fails mostly for two reasons
//! (Beeson & Ames, "TRAC-IK", Humanoids 2015): it stalls against a joint limit, and it
//! never leaves a bad basin. This solver fixes both the way TRAC-IK does, but sequentially
//! and deterministically instead of with two racing threads:
//! - attempts alternate between two local methods: (A) Levenberg-Marquardt with
//!   error-dependent damping (Sugihara, IEEE T-RO 2011), robust near singularities, and
//!   (B) active-set Gauss-Newton, which solves the bounded least-squares step by freezing
//!   joints that would cross a limit and re-solving with the others, so a limit does not stall
//!   it, plus a backtracking line search;
//! - the first attempt starts from the caller's seed, every later one from a uniform random
//!   configuration drawn from the caller's seeded [`Rng`];
//! - the budget is a total count of iterations (never wall time), so results are repeatable.

use crate::chain::ArmModel;
use crate::layout::{join, split, DOF};
use crate::target::Target;
use agrisim_math::Rng;
use nalgebra::{SMatrix, SVector, Vector6};

type Vec8 = SVector<f64, 8>;
type Mat8 = SMatrix<f64, 8, 8>;
type Jac = SMatrix<f64, 6, 8>;

/// Weight of rotation errors (rad) relative to position errors (m) in the least squares:
/// about the lever arm of the wrist, so 1 rad matters like 0.2 m.
const ROT_WEIGHT: f64 = 0.2;
/// Iterations of one local attempt before a restart.
pub const ATTEMPT_ITERS: usize = 60;

/// Default total iteration budget of one [`Ik::solve`]: far above what reachable targets
/// need (typically < 20), a bound for unreachable ones.
pub const DEFAULT_BUDGET: usize = 3000;

/// The IK of one arm at a lift height (or with the lift free).
#[derive(Debug, Clone)]
pub struct Ik<'a> {
    pub arm: &'a ArmModel,
    /// Lift height (m) used when the lift is not free; the start value when it is.
    pub lift: f64,
    /// Let the lift move within its limits as an 8th joint.
    pub free_lift: bool,
    /// Where iterations are counted (planning work), if anywhere.
    pub meter: Option<&'a crate::Meter>,
}

struct Problem<'a> {
    arm: &'a ArmModel,
    target: &'a Target,
    lo: Vec8,
    hi: Vec8,
    /// 1 for free variables, 0 for the locked lift.
    mask: Vec8,
}

impl<'a> Ik<'a> {
    pub fn new(arm: &'a ArmModel, lift: f64) -> Ik<'a> {
        Ik { arm, lift, free_lift: false, meter: None }
    }

    /// Counts this solver's iterations in `meter`.
    pub fn metered(self, meter: Option<&'a crate::Meter>) -> Ik<'a> {
        Ik { meter, ..self }
    }

    /// Same, with the lift as an 8th joint ([`Ik::solve_lift`] returns its value).
    pub fn with_free_lift(arm: &'a ArmModel, lift: f64) -> Ik<'a> {
        Ik { arm, lift, free_lift: true, meter: None }
    }

    /// Joint configuration reaching `target` within its tolerances and the joint limits,
    /// starting from `seed` and then random restarts, within `budget` iterations in total.
    pub fn solve(&self, target: &Target, seed: &[f64; DOF], rng: &mut Rng, budget: usize) -> Option<[f64; DOF]> {
        self.solve_lift(target, seed, rng, budget).map(|(_, q)| q)
    }

    /// Like [`Ik::solve`] and also returns the lift (different from `self.lift` only with
    /// a free lift).
    pub fn solve_lift(
        &self,
        target: &Target,
        seed: &[f64; DOF],
        rng: &mut Rng,
        budget: usize,
    ) -> Option<(f64, [f64; DOF])> {
        self.solve_counted(target, seed, rng, budget).0
    }

    /// [`Ik::solve_lift`] plus the number of iterations used.
    pub fn solve_counted(
        &self,
        target: &Target,
        seed: &[f64; DOF],
        rng: &mut Rng,
        budget: usize,
    ) -> (Option<(f64, [f64; DOF])>, usize) {
        let (r, used) = self.search(target, seed, rng, budget);
        if let Some(m) = self.meter {
            m.add_ik_iterations(used);
        }
        (r, used)
    }

    fn search(
        &self,
        target: &Target,
        seed: &[f64; DOF],
        rng: &mut Rng,
        budget: usize,
    ) -> (Option<(f64, [f64; DOF])>, usize) {
        let pb = self.problem(target);
        let mut left = budget;
        let mut attempt = 0usize;
        while left > 0 {
            let x0 = if attempt == 0 {
                join(self.lift, seed)
            } else {
                let q = self.arm.random_q(rng);
                let lift = if self.free_lift { pb.lo[0] + (pb.hi[0] - pb.lo[0]) * rng.uniform() } else { self.lift };
                join(lift, &q)
            };
            let x0 = pb.clamp(&Vec8::from(x0));
            let n = left.min(ATTEMPT_ITERS);
            let (x, used, ok) =
                if attempt.is_multiple_of(2) { pb.levenberg_marquardt(x0, n) } else { pb.active_set_gn(x0, n) };
            left -= used.max(1).min(left);
            if ok {
                let x: [f64; 8] = x.into();
                return (Some(split(&x)), budget - left);
            }
            attempt += 1;
        }
        (None, budget)
    }

    /// Up to `n` distinct solutions (pairwise joint-space distance >= `min_dist` rad,
    /// Euclidean) accepted by `valid` (e.g. collision-free), found within `budget` total
    /// iterations. The first search starts from `seed`, so the solution nearest the current
    /// arm state tends to come first. Always at the fixed lift `self.lift`.
    #[allow(clippy::too_many_arguments)] // public API the harvest node calls
    pub fn goal_set(
        &self,
        target: &Target,
        seed: &[f64; DOF],
        rng: &mut Rng,
        n: usize,
        min_dist: f64,
        budget: usize,
        mut valid: impl FnMut(&[f64; DOF]) -> bool,
    ) -> Vec<[f64; DOF]> {
        let fixed = Ik { free_lift: false, ..self.clone() };
        let mut out: Vec<[f64; DOF]> = Vec::new();
        let mut left = budget;
        let mut first = true;
        // Each search gets at most a slice of the budget so one hard target cannot starve
        // the set; a search that succeeds quickly leaves the rest for more searches.
        let per = (budget / n.max(1)).clamp(ATTEMPT_ITERS, DEFAULT_BUDGET);
        while out.len() < n && left > 0 {
            let s = if first { *seed } else { self.arm.random_q(rng) };
            first = false;
            let b = per.min(left);
            let (r, used) = fixed.solve_counted(target, &s, rng, b);
            left -= used.clamp(1, b);
            if let Some((_, q)) = r {
                let far = out.iter().all(|o| dist(o, &q) >= min_dist);
                if far && valid(&q) {
                    out.push(q);
                }
            }
        }
        out
    }

    fn problem<'t>(&'t self, target: &'t Target) -> Problem<'t> {
        let mut lo = Vec8::zeros();
        let mut hi = Vec8::zeros();
        let mut mask = Vec8::repeat(1.0);
        if self.free_lift {
            lo[0] = self.arm.lift_limits.lower;
            hi[0] = self.arm.lift_limits.upper;
        } else {
            lo[0] = self.lift;
            hi[0] = self.lift;
            mask[0] = 0.0;
        }
        for (i, l) in self.arm.limits.iter().enumerate() {
            lo[i + 1] = l.lower;
            hi[i + 1] = l.upper;
        }
        Problem { arm: self.arm, target, lo, hi, mask }
    }
}

/// Euclidean joint-space distance.
pub fn dist(a: &[f64; DOF], b: &[f64; DOF]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>().sqrt()
}

impl Problem<'_> {
    fn clamp(&self, x: &Vec8) -> Vec8 {
        Vec8::from_fn(|i, _| x[i].clamp(self.lo[i], self.hi[i]))
    }

    fn eval(&self, x: &Vec8) -> (Vector6<f64>, f64) {
        let xa: [f64; 8] = (*x).into();
        let e = self.target.error(&self.arm.fk_x(&xa));
        let w = weighted(&e);
        (e, 0.5 * w.norm_squared())
    }

    fn jac(&self, x: &Vec8) -> Jac {
        let xa: [f64; 8] = (*x).into();
        let j = self.arm.jacobian_x(&xa);
        let mut out = Jac::zeros();
        for c in 0..8 {
            for r in 0..6 {
                let w = if r < 3 { 1.0 } else { ROT_WEIGHT };
                out[(r, c)] = j[(r, c)] * w * self.mask[c];
            }
        }
        out
    }

    /// (A) Levenberg-Marquardt, damping E + small constant (Sugihara 2011), steps projected
    /// onto the limits; a rejected step raises the damping.
    fn levenberg_marquardt(&self, mut x: Vec8, iters: usize) -> (Vec8, usize, bool) {
        let (mut e, mut err) = self.eval(&x);
        let mut boost = 1.0;
        for it in 0..iters {
            if self.target.reached(&e) {
                return (x, it, true);
            }
            let j = self.jac(&x);
            let g = j.transpose() * weighted(&e);
            let lambda = (err + 1e-6) * boost;
            let a: Mat8 = j.transpose() * j + Mat8::identity() * lambda;
            let Some(dx) = a.cholesky().map(|c| c.solve(&g)) else {
                return (x, it + 1, false);
            };
            let xn = self.clamp(&(x + dx));
            let (en, errn) = self.eval(&xn);
            if errn < err {
                // Stalled: progress too small to finish within the attempt.
                let stalled = errn > 0.999 * err && !self.target.reached(&en);
                x = xn;
                e = en;
                err = errn;
                boost = (boost * 0.3).max(1e-3);
                if stalled && boost <= 1e-3 {
                    return (x, it + 1, false);
                }
            } else {
                boost *= 10.0;
                if boost > 1e6 {
                    return (x, it + 1, false);
                }
            }
        }
        let ok = self.target.reached(&e);
        (x, iters, ok)
    }

    /// (B) Active-set Gauss-Newton: the step solves min |J dx - e| subject to the limits by
    /// freezing the joints whose unconstrained step would cross a limit and re-solving for
    /// the rest; backtracking halves a step that does not reduce the error.
    fn active_set_gn(&self, mut x: Vec8, iters: usize) -> (Vec8, usize, bool) {
        let (mut e, mut err) = self.eval(&x);
        let mut used = 0;
        while used < iters {
            if self.target.reached(&e) {
                return (x, used, true);
            }
            used += 1;
            let j = self.jac(&x);
            let r = weighted(&e);
            let mut free = self.mask;
            let mut dx = Vec8::zeros();
            for _ in 0..8 {
                let mut jf = j;
                for c in 0..8 {
                    if free[c] == 0.0 {
                        jf.column_mut(c).fill(0.0);
                    }
                }
                dx = dls_step(&jf, &r, 1e-4);
                let mut changed = false;
                for c in 0..8 {
                    if free[c] != 0.0 {
                        let v = x[c] + dx[c];
                        if v < self.lo[c] || v > self.hi[c] {
                            free[c] = 0.0;
                            changed = true;
                        }
                    }
                }
                if !changed {
                    break;
                }
            }
            // Trust region: a step beyond 0.6 rad leaves the linearisation's validity.
            let m = dx.amax();
            if m > 0.6 {
                dx *= 0.6 / m;
            }
            let mut step = 1.0;
            let mut accepted = false;
            for _ in 0..5 {
                let xn = self.clamp(&(x + dx * step));
                let (en, errn) = self.eval(&xn);
                if errn < err {
                    x = xn;
                    e = en;
                    err = errn;
                    accepted = true;
                    break;
                }
                step *= 0.5;
            }
            if !accepted {
                return (x, used, false);
            }
        }
        let ok = self.target.reached(&e);
        (x, used, ok)
    }
}

fn weighted(e: &Vector6<f64>) -> Vector6<f64> {
    Vector6::new(e[0], e[1], e[2], e[3] * ROT_WEIGHT, e[4] * ROT_WEIGHT, e[5] * ROT_WEIGHT)
}

/// Damped least-squares step J^T (J J^T + mu I)^-1 r (6x6 solve).
fn dls_step(j: &Jac, r: &Vector6<f64>, mu: f64) -> Vec8 {
    let a = j * j.transpose() + SMatrix::<f64, 6, 6>::identity() * mu;
    match a.cholesky() {
        Some(c) => j.transpose() * c.solve(r),
        // Only with non-finite input; a zero step ends the attempt.
        None => Vec8::zeros(),
    }
}
