//! FK against an independent modified-DH product of the Panda (figures from
//! models/robot/generate_urdf.py, not from the URDF reader), Jacobian against finite
//! differences, limits.

use agrisim_manip::{ArmModel, Rng, Side};
use nalgebra::{Isometry3, Matrix4, Vector3};
use std::f64::consts::PI;

const DH: [(f64, f64, f64); 7] = [
    (0.0, 0.333, 0.0),
    (0.0, 0.0, -PI / 2.0),
    (0.0, 0.316, PI / 2.0),
    (0.0825, 0.0, PI / 2.0),
    (-0.0825, 0.384, -PI / 2.0),
    (0.0, 0.0, PI / 2.0),
    (0.088, 0.0, PI / 2.0),
];

fn rot_x(a: f64) -> Matrix4<f64> {
    let (s, c) = a.sin_cos();
    Matrix4::new(1.0, 0.0, 0.0, 0.0, 0.0, c, -s, 0.0, 0.0, s, c, 0.0, 0.0, 0.0, 0.0, 1.0)
}
fn rot_z(a: f64) -> Matrix4<f64> {
    let (s, c) = a.sin_cos();
    Matrix4::new(c, -s, 0.0, 0.0, s, c, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0)
}
fn tr(x: f64, y: f64, z: f64) -> Matrix4<f64> {
    Matrix4::new_translation(&Vector3::new(x, y, z))
}

/// base_link -> lift carriage (x 0.2, z 0.45 + lift) -> arm mount (y +-0.25, z 0.025) ->
/// Craig DH joints -> flange 0.107 -> hand rotated -45 deg -> TCP 0.1034.
fn dh_tcp(side: Side, lift: f64, q: &[f64; 7]) -> Matrix4<f64> {
    let y = if side == Side::Left { 0.25 } else { -0.25 };
    let mut t = tr(0.2, 0.0, 0.45 + lift) * tr(0.0, y, 0.025);
    for (i, (a, d, alpha)) in DH.iter().enumerate() {
        t = t * rot_x(*alpha) * tr(*a, 0.0, 0.0) * rot_z(q[i]) * tr(0.0, 0.0, *d);
    }
    t * tr(0.0, 0.0, 0.107) * rot_z(-PI / 4.0) * tr(0.0, 0.0, 0.1034)
}

fn max_diff(a: &Isometry3<f64>, b: &Matrix4<f64>) -> f64 {
    (a.to_homogeneous() - b).abs().max()
}

#[test]
fn fk_matches_modified_dh_for_both_arms() {
    let mut rng = Rng::new(11);
    for side in [Side::Left, Side::Right] {
        let arm = ArmModel::new(side);
        let mut worst: f64 = 0.0;
        for _ in 0..500 {
            let q = arm.random_q(&mut rng);
            let lift = 0.8 * rng.uniform();
            worst = worst.max(max_diff(&arm.fk_iso(lift, &q), &dh_tcp(side, lift, &q)));
            // The agrisim_robot::Pose variant is the same transform.
            let p = arm.fk(lift, &q);
            let i = arm.fk_iso(lift, &q);
            assert!((p.trans[2] - i.translation.vector.z).abs() < 1e-12);
        }
        assert!(worst < 1e-9, "{side:?}: FK differs from DH by {worst}");
    }
}

#[test]
fn body_frames_agree_with_the_generic_urdf_fk() {
    // The crate's chain against agrisim-robot's whole-tree FK, for every body.
    let robot = agrisim_robot::Robot::from_urdf_str(agrisim_manip::chain::URDF).unwrap();
    let arm = ArmModel::new(Side::Right);
    let mut rng = Rng::new(5);
    for _ in 0..50 {
        let q = arm.random_q(&mut rng);
        let lift = 0.8 * rng.uniform();
        let finger = 0.04 * rng.uniform();
        let mut m = std::collections::BTreeMap::from([("lift_joint".to_string(), lift)]);
        for (i, n) in arm.joint_names.iter().enumerate() {
            m.insert(n.clone(), q[i]);
        }
        m.insert("right_finger_joint1".into(), finger);
        m.insert("right_finger_joint2".into(), finger);
        let all = robot.fk(&m).unwrap();
        let fr = arm.frames(lift, &q, finger);
        for (b, name) in agrisim_manip::layout::BODY_NAMES.iter().enumerate() {
            let want = agrisim_manip::iso::to_iso(&all[&format!("right_{name}")]);
            let d = (fr.bodies[b].to_homogeneous() - want.to_homogeneous()).abs().max();
            assert!(d < 1e-9, "{name}: {d}");
        }
    }
}

#[test]
fn jacobian_matches_finite_differences() {
    let arm = ArmModel::new(Side::Left);
    let mut rng = Rng::new(3);
    let h = 1e-6;
    for _ in 0..200 {
        let q = arm.random_q(&mut rng);
        let lift = 0.5;
        let j = arm.jacobian(lift, &q);
        let f0 = arm.fk_iso(lift, &q);
        for c in 0..7 {
            let mut qp = q;
            qp[c] += h;
            let mut qm = q;
            qm[c] -= h;
            let (fp, fm) = (arm.fk_iso(lift, &qp), arm.fk_iso(lift, &qm));
            let v = (fp.translation.vector - fm.translation.vector) / (2.0 * h);
            let w = (fp.rotation * fm.rotation.inverse()).scaled_axis() / (2.0 * h);
            for r in 0..3 {
                assert!((j[(r, c)] - v[r]).abs() < 1e-6, "linear r{r} c{c}: {} vs {}", j[(r, c)], v[r]);
                assert!((j[(r + 3, c)] - w[r]).abs() < 1e-6, "angular r{r} c{c}: {} vs {}", j[(r + 3, c)], w[r]);
            }
        }
        let _ = f0;
    }
}

#[test]
fn limits_are_the_franka_figures_and_random_q_respects_them() {
    let arm = ArmModel::new(Side::Left);
    assert_eq!(arm.lower()[3], -3.0718);
    assert_eq!(arm.upper()[5], 3.7525);
    assert_eq!((arm.lift_limits.lower, arm.lift_limits.upper), (0.0, 0.8));
    let mut rng = Rng::new(1);
    for _ in 0..1000 {
        assert!(arm.within_limits(&arm.random_q(&mut rng)));
    }
    assert!(!arm.within_limits(&[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]), "joint 4 upper limit is -0.0698");
}
