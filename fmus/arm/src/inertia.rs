//! Effective joint inertias: the diagonal of the arm's joint-space mass matrix at the current
//! configuration, from the URDF inertials, plus each joint's reflected rotor inertia.
//!
//! Simplification (documented in the crate docs): the plant is 7 decoupled rigid joints, each
//! with inertia `M_ii(q)`; the off-diagonal (inertial coupling) and Coriolis/centrifugal terms
//! are left out, and gravity is assumed compensated exactly (as Franka's controller does,
//! libfranka adds gravity before sending torques). For joint i,
//! `M_ii = sum over bodies k moved by i of m_k |a_i x (c_k - p_i)|^2 + a_i . I_k a_i`
//! (a_i, p_i: joint axis and origin, c_k, I_k: body centre and inertia, all in one frame),
//! which is exactly the diagonal of `sum_k m_k Jv_k^T Jv_k + Jw_k^T I_k Jw_k`.

use crate::description::{rotate_inertia, ArmDescription, Body, N};
use agrisim_math::vec3::{cross, dot, mat_vec, sub, Mat3};
use agrisim_robot::Pose;

/// Reflected rotor (motor + gear) inertia per joint [kg m^2], as Franka gives it for the FR3
/// (quoted in Drake's franka_description README, "Rotor Inertia and Gear Ratio"). The Panda's
/// values are not published; the FR3's are used as the closest available figure.
pub const ROTOR_INERTIA: [f64; N] =
    [0.605721456, 0.605721456, 0.462474144, 0.462474144, 0.205544064, 0.205544064, 0.205544064];

/// A body's centre and inertia in the arm base frame.
fn placed(pose: &Pose, b: &Body) -> (f64, [f64; 3], [[f64; 3]; 3]) {
    (b.mass, pose.transform_point(b.com), rotate_inertia(&pose.rot, &b.inertia))
}

/// Link-only diagonal of the mass matrix at arm configuration `q` with the fingers each at
/// `finger` m (rotor inertia not included).
pub fn link_inertia_diagonal(d: &ArmDescription, q: &[f64; N], finger: f64) -> [f64; N] {
    // Joint frames (axis, origin) and body placements along the chain, in the link0 frame.
    let mut axes = [([0.0; 3], [0.0; 3]); N];
    let mut bodies: Vec<(usize, f64, [f64; 3], Mat3)> = Vec::with_capacity(d.chain_bodies.len() + 2);
    let mut pose = Pose::IDENTITY;
    let mut movable = 0usize;
    let mut next_body = 0usize;
    for (k, j) in d.chain.iter().enumerate() {
        let qj = if j.kind.is_movable() {
            let frame = pose.mul(&j.origin);
            axes[movable] = (frame.rotate(j.axis), frame.trans);
            movable += 1;
            q[movable - 1]
        } else {
            0.0
        };
        pose = pose.mul(&j.transform(qj));
        while next_body < d.chain_bodies.len() && d.chain_bodies[next_body].0 == k {
            let (m, c, i) = placed(&pose, &d.chain_bodies[next_body].1);
            // Bodies after chain joint k are moved by every movable joint up to it.
            bodies.push((movable, m, c, i));
            next_body += 1;
        }
    }
    for (fj, fb) in d.finger_joints.iter().zip(&d.finger_bodies) {
        let (m, c, i) = placed(&pose.mul(&fj.transform(finger)), fb);
        bodies.push((movable, m, c, i));
    }
    let mut out = [0.0; N];
    for (i, (a, p)) in axes.iter().enumerate() {
        for &(moved_by, m, c, inertia) in &bodies {
            if moved_by > i {
                let r = cross(*a, sub(c, *p));
                out[i] += m * dot(r, r) + dot(*a, mat_vec(&inertia, *a));
            }
        }
    }
    out
}

/// Plant inertia per joint: link diagonal plus rotor inertia.
pub fn joint_inertia(d: &ArmDescription, q: &[f64; N], finger: f64) -> [f64; N] {
    let l = link_inertia_diagonal(d, q, finger);
    std::array::from_fn(|i| l[i] + ROTOR_INERTIA[i])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Independent check: the diagonal equals the kinetic energy 2T of a unit velocity of one
    /// joint, computed by finite differences of body poses (no axis/Jacobian formula).
    #[test]
    fn diagonal_matches_finite_difference_kinetic_energy() {
        let d = ArmDescription::load("left").unwrap();
        let qs = [[0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785], [0.3, 0.5, -1.0, -1.2, 2.0, 0.5, -2.0]];
        for q in qs {
            let m = link_inertia_diagonal(&d, &q, 0.02);
            for i in 0..N {
                let eps = 1e-6;
                let mut qp = q;
                qp[i] += eps;
                let poses = |q: &[f64; N]| -> Vec<(f64, Pose, Body)> {
                    let mut out = vec![];
                    let mut pose = Pose::IDENTITY;
                    let mut mv = 0;
                    for (k, j) in d.chain.iter().enumerate() {
                        let qj = if j.kind.is_movable() {
                            mv += 1;
                            q[mv - 1]
                        } else {
                            0.0
                        };
                        pose = pose.mul(&j.transform(qj));
                        for (kk, b) in &d.chain_bodies {
                            if *kk == k {
                                out.push((b.mass, pose, b.clone()));
                            }
                        }
                    }
                    for (fj, fb) in d.finger_joints.iter().zip(&d.finger_bodies) {
                        out.push((fb.mass, pose.mul(&fj.transform(0.02)), fb.clone()));
                    }
                    out
                };
                let (a, b) = (poses(&q), poses(&qp));
                let mut two_t = 0.0;
                for ((mass, p0, body), (_, p1, _)) in a.iter().zip(&b) {
                    let c0 = p0.transform_point(body.com);
                    let c1 = p1.transform_point(body.com);
                    let v = sub(c1, c0).map(|x| x / eps);
                    // Angular velocity from R1 R0^T ~ I + [w]x eps.
                    let mut w = [0.0; 3];
                    let r = |i: usize, j: usize| (0..3).map(|k| p1.rot[i][k] * p0.rot[j][k]).sum::<f64>();
                    w[0] = (r(2, 1) - r(1, 2)) / (2.0 * eps);
                    w[1] = (r(0, 2) - r(2, 0)) / (2.0 * eps);
                    w[2] = (r(1, 0) - r(0, 1)) / (2.0 * eps);
                    let iw = rotate_inertia(&p0.rot, &body.inertia);
                    two_t += mass * dot(v, v) + dot(w, mat_vec(&iw, w));
                }
                assert!((two_t - m[i]).abs() < 1e-4 * m[i].max(1e-3), "joint {i}: {two_t} vs {}", m[i]);
            }
        }
    }

    #[test]
    fn shoulder_sees_more_inertia_than_wrist() {
        let d = ArmDescription::load("right").unwrap();
        let m = link_inertia_diagonal(&d, &[0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785], 0.04);
        assert!(m[0] > m[4] && m[1] > m[6] && m.iter().all(|&x| x > 0.0), "{m:?}");
    }
}
