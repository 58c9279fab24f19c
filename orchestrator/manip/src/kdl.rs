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
pub fn kdl_nr_jl(
    arm: &ArmModel,
    lift: f64,
    target: &Target,
    seed: &[f64; DOF],
) -> Option<[f64; DOF]> {
    let lo = arm.lower();
    let hi = arm.upper();
    let mut x = join(lift, seed);
    let full = Target {
        free_roll: false,
        ..*target
    };
    for _ in 0..KDL_MAX_ITER {
        let f = arm.fk_x(&x);
        let dtwist: Vector6<f64> = full.error(&f);
        if dtwist.iter().all(|v| v.abs() < KDL_EPS) {
            return Some(split(&x).1);
        }
        let jx = arm.jacobian_x(&x);
        let j: SMatrix<f64, 6, DOF> = jx.fixed_columns::<DOF>(1).into_owned();
        let svd = j.svd(true, true);
        let dq = svd.solve(&dtwist, KDL_EPS).ok()?;
        for i in 0..DOF {
            x[i + 1] = (x[i + 1] + dq[i]).clamp(lo[i], hi[i]);
        }
    }
    // KDL checks the error once more on exit only through the loop condition: not converged.
    None
}
