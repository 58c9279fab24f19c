//! Straight-line TCP motions (approach to the fruit, retreat after the grasp, descent into the
//! crate): the TCP moves along a line with fixed orientation, solved by IK step by step from
//! the previous configuration. Only the seeded local attempt is used (no random restarts),
//! so consecutive configurations stay on one IK branch; a joint jump above `max_jump`
//! (a branch switch or singularity) or a collision ends the motion with an error telling how
//! far it got (like MoveIt's computeCartesianPath fraction).

use crate::checker::Checker;
use crate::ik::{Ik, ATTEMPT_ITERS};
use crate::layout::DOF;
use crate::target::Target;
use agrisim_math::Rng;
use nalgebra::{Translation3, Vector3};

#[derive(Debug, Clone, PartialEq)]
pub struct CartesianError {
    /// Fraction of the line achieved before the failure (0..1).
    pub fraction: f64,
    pub reason: String,
    /// The valid part of the path (start first).
    pub partial: Vec<[f64; DOF]>,
}

impl std::fmt::Display for CartesianError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "cartesian motion stopped at {:.0} %: {}", 100.0 * self.fraction, self.reason)
    }
}

impl std::error::Error for CartesianError {}

/// Joint path moving the TCP from its pose at `start` by `offset` (planning frame, m; for a
/// tool-frame offset `v` pass `tcp.rotation * v`), orientation kept, with TCP steps of at
/// most `step` m. Every waypoint is valid and every edge is checked at `resolution` rad.
pub fn cartesian_path(
    checker: &Checker,
    start: &[f64; DOF],
    offset: Vector3<f64>,
    step: f64,
    max_jump: f64,
    resolution: f64,
) -> Result<Vec<[f64; DOF]>, CartesianError> {
    let ctx = &checker.ctx;
    let ik = Ik::new(ctx.arm, ctx.lift).metered(ctx.meter);
    let p0 = ctx.arm.fk_iso(ctx.lift, start);
    let n = ((offset.norm() / step).ceil() as usize).max(1);
    let mut path = vec![*start];
    // Unused: one seeded attempt draws no random numbers; kept for the solve signature.
    let mut rng = Rng::new(0);
    let fail = |path: Vec<[f64; DOF]>, k: usize, reason: String| CartesianError {
        fraction: (k - 1) as f64 / n as f64,
        reason,
        partial: path,
    };
    for k in 1..=n {
        let t = Target::pose(Translation3::from(offset * (k as f64 / n as f64)) * p0);
        let prev = *path.last().unwrap();
        let Some(q) = ik.solve(&t, &prev, &mut rng, ATTEMPT_ITERS) else {
            return Err(fail(path, k, format!("IK failed at step {k}/{n}")));
        };
        let jump = q.iter().zip(&prev).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        if jump > max_jump {
            return Err(fail(path, k, format!("joint jump {jump:.3} rad at step {k}/{n}")));
        }
        if !checker.edge_valid(&prev, &q, resolution) {
            return Err(fail(path, k, format!("collision at step {k}/{n}")));
        }
        path.push(q);
    }
    Ok(path)
}
