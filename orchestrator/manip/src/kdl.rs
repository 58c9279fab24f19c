//! Baseline: KDL's `ChainIkSolverPos_NR_JL` re-implemented from its documented semantics
//! (orocos_kinematics_dynamics, chainiksolverpos_nr_jl.cpp): Newton-Raphson on the pose
//! error twist with the Jacobian pseudo-inverse (`ChainIkSolverVel_pinv`, SVD with singular
//! values below eps treated as zero), joints clamped to their limits after every step, at
//! most 100 iterations, converged when every twist component is below eps = 1e-5, started
//! from one seed. It exists to measure our solver against the figure TRAC-IK compares with.

use crate::chain::ArmModel;
use crate::layout::{join, split, DOF};
use crate::target::Target;
use nalgebra::{SMatrix, Vector6};

pub const KDL_MAX_ITER: usize = 100;
pub const KDL_EPS: f64 = 1e-5;

/// Solves a 6-D target from `seed` with KDL NR_JL semantics; `None` when not converged.
pub fn kdl_nr_jl(arm: &ArmModel, lift: f64, target: &Target, seed: &[f64; DOF]) -> Option<[f64; DOF]> {
    nr_jl(arm, lift, target, seed, KDL_MAX_ITER, &|e| e.iter().all(|v| v.abs() < KDL_EPS)).0
}

/// KDL NR_JL given what our solver gets, for a like-for-like comparison: it stops at the
/// target's own tolerances and, like TRAC-IK's KDL thread, restarts from random
/// configurations until `budget` iterations are spent.
pub fn kdl_nr_jl_restarts(
    arm: &ArmModel,
    lift: f64,
    target: &Target,
    seed: &[f64; DOF],
    rng: &mut agrisim_math::Rng,
    budget: usize,
) -> Option<[f64; DOF]> {
    let mut start = *seed;
    let mut spent = 0;
    while spent < budget {
        let (q, used) = nr_jl(arm, lift, target, &start, KDL_MAX_ITER.min(budget - spent), &|e| target.reached(e));
        if q.is_some() {
            return q;
        }
        spent += used.max(1);
        start = arm.random_q(rng);
    }
    None
}

/// NR_JL from `seed` for at most `max_iter` iterations until `converged` holds for the error
/// twist; returns the solution (if any) and the iterations used.
fn nr_jl(
    arm: &ArmModel,
    lift: f64,
    target: &Target,
    seed: &[f64; DOF],
    max_iter: usize,
    converged: &dyn Fn(&Vector6<f64>) -> bool,
) -> (Option<[f64; DOF]>, usize) {
    let lo = arm.lower();
    let hi = arm.upper();
    let mut x = join(lift, seed);
    let full = Target { free_roll: false, ..*target };
    for it in 0..max_iter {
        let f = arm.fk_x(&x);
        let dtwist: Vector6<f64> = full.error(&f);
        if converged(&dtwist) {
            return (Some(split(&x).1), it);
        }
        let jx = arm.jacobian_x(&x);
        let j: SMatrix<f64, 6, DOF> = jx.fixed_columns::<DOF>(1).into_owned();
        let svd = j.svd(true, true);
        let Ok(dq) = svd.solve(&dtwist, KDL_EPS) else { return (None, it + 1) };
        for i in 0..DOF {
            x[i + 1] = (x[i + 1] + dq[i]).clamp(lo[i], hi[i]);
        }
    }
    // KDL checks the error once more on exit only through the loop condition: not converged.
    (None, max_iter)
}
