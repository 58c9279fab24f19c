//! The load a held object puts on the hand, as joint torques.
//!
//! The world FMU reports the wrench its attached fruit (still on its plant, pulling through its
//! pedicel) exerts on the hand: force `F` and moment `M0` about the origin of the arm's link0,
//! both in link0. Joint i (axis `a_i` through `p_i`, link0 frame) then carries
//! `tau_i = a_i . (M0 - p_i x F)`, the moment of the wrench about its axis: `J^T w` without
//! forming the Jacobian.

use crate::description::{ArmDescription, N};
use agrisim_math::vec3::{cross, dot, sub};
use agrisim_robot::Pose;

/// Joint torques [N m] of wrench `w` = (F, M0) at configuration `q`.
pub fn joint_torques(d: &ArmDescription, q: &[f64; N], w: &[f64; 6]) -> [f64; N] {
    let (f, m0) = ([w[0], w[1], w[2]], [w[3], w[4], w[5]]);
    let mut out = [0.0; N];
    if w.iter().all(|v| *v == 0.0) {
        return out;
    }
    let mut pose = Pose::IDENTITY;
    let mut i = 0usize;
    for j in &d.chain {
        let qj = if j.kind.is_movable() {
            let frame = pose.mul(&j.origin);
            let (a, p) = (frame.rotate(j.axis), frame.trans);
            if i < N {
                out[i] = dot(a, sub(m0, cross(p, f)));
            }
            i += 1;
            q[i - 1]
        } else {
            0.0
        };
        pose = pose.mul(&j.transform(qj));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The torques equal the work of the wrench along a small joint motion (virtual work):
    /// finite differences of the hand pose give the same figures.
    #[test]
    fn torques_are_the_virtual_work_of_the_wrench() {
        let d = ArmDescription::load("left").unwrap();
        // Any configuration away from singularities (the identity holds everywhere).
        let q: [f64; N] = [0.3, -0.5, 0.2, -1.9, 0.1, 1.6, 0.4];
        let end = |q: &[f64; N]| {
            let mut pose = Pose::IDENTITY;
            let mut i = 0;
            for j in &d.chain {
                let qj = if j.kind.is_movable() {
                    i += 1;
                    q[i - 1]
                } else {
                    0.0
                };
                pose = pose.mul(&j.transform(qj));
            }
            pose
        };
        // A pure force at the chain's end point: M0 = p_end x F.
        let f = [3.0, -2.0, 5.0];
        let p_end = end(&q).trans;
        let m0 = cross(p_end, f);
        let tau = joint_torques(&d, &q, &[f[0], f[1], f[2], m0[0], m0[1], m0[2]]);
        for k in 0..N {
            let mut q2 = q;
            q2[k] += 1e-6;
            let dp = sub(end(&q2).trans, p_end);
            let work = dot(f, dp) / 1e-6;
            assert!((work - tau[k]).abs() < 1e-4, "joint {k}: {work} vs {}", tau[k]);
        }
    }
}
