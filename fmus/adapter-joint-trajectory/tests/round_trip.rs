//! JointTrajectory messages in, set-points out, through the generic FMI 3 layer: the initial
//! set-points hold before any trajectory, linear and cubic Hermite segments match their
//! closed forms at several times, the last point holds, joint names map in any order, and a
//! trajectory naming an unknown joint is rejected with status 2 and a warning.

#[path = "../../adapter-twist/tests/common/mod.rs"]
mod common;

use agrisim_fmi::Status;
use agrisim_fmu_adapter_joint_trajectory::ports::*;
use agrisim_fmu_adapter_joint_trajectory::JointTrajectoryToScalars;
use agrisim_msgs::builtin_interfaces::{Duration, Time};
use agrisim_msgs::std_msgs::Header;
use agrisim_msgs::trajectory_msgs::{JointTrajectory, JointTrajectoryPoint};
use agrisim_msgs::Message;
use common::Fmu;

const H: f64 = 0.02;
const Q0: [f64; 7] = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785];

fn names(order: &[usize]) -> Vec<String> {
    order.iter().map(|j| format!("left_joint{}", j + 1)).collect()
}

fn point(q: [f64; 7], qd: Option<[f64; 7]>, t: f64) -> JointTrajectoryPoint {
    JointTrajectoryPoint {
        positions: q.to_vec(),
        velocities: qd.map_or(vec![], |v| v.to_vec()),
        time_from_start: Duration::from_secs_f64(t).unwrap(),
        ..Default::default()
    }
}

fn running() -> Fmu<JointTrajectoryToScalars> {
    let f = Fmu::new();
    for (i, q) in Q_INIT.into_iter().zip(Q0) {
        f.set_f64(i, q);
    }
    f.enter_init();
    f.exit_init();
    f
}

fn send(f: &Fmu<JointTrajectoryToScalars>, seq: i64, m: &JointTrajectory) {
    f.set_binary(TRAJECTORY, &m.to_cdr());
    f.set_i64(TRAJECTORY_SEQ, seq);
}

fn q(f: &Fmu<JointTrajectoryToScalars>) -> [f64; 7] {
    Q.map(|i| f.f64(i))
}

/// Steps from step `from` to step `to` (exclusive), each of H.
fn steps(f: &Fmu<JointTrajectoryToScalars>, from: usize, to: usize) {
    for k in from..to {
        assert_eq!(f.step(k as f64 * H, H), Status::Ok, "{:?}", f.logs);
    }
}

#[test]
fn the_initial_set_points_hold_before_any_trajectory() {
    let f = running();
    assert_eq!(q(&f), Q0);
    steps(&f, 0, 10);
    assert_eq!(q(&f), Q0);
    assert_eq!((f.i32(STATUS), f.i32(COUNT)), (status::HOLDING, 0));
}

#[test]
fn linear_segments_match_the_interpolation_and_the_last_point_holds() {
    // Taken at t = 0.1 s (start of the step from 0.1): from Q0 to A in 1 s, then to B in 0.5 s.
    let f = running();
    steps(&f, 0, 5);
    let a = [0.5, -0.5, 0.2, -2.0, 0.1, 1.2, 0.0];
    let b = [0.3, -0.4, 0.2, -1.8, -0.1, 1.0, 0.5];
    // Joint names in another order than the outputs: the columns are permuted.
    let order = [6, 5, 4, 3, 2, 1, 0];
    let perm = |v: [f64; 7]| order.map(|j| v[j]);
    let m = JointTrajectory {
        joint_names: names(&order),
        points: vec![point(perm(a), None, 1.0), point(perm(b), None, 1.5)],
        ..Default::default()
    };
    send(&f, 1, &m);
    let (t0, mut k0) = (0.1, 5);
    for (k_end, want) in [
        (10, lerp(Q0, a, (0.2 - t0) / 1.0)),
        (30, lerp(Q0, a, (0.6 - t0) / 1.0)),
        (55, a),
        (65, lerp(a, b, (1.3 - t0 - 1.0) / 0.5)),
        (80, b),
        (150, b),
    ] {
        steps(&f, k0, k_end);
        k0 = k_end;
        let got = q(&f);
        for j in 0..7 {
            assert!((got[j] - want[j]).abs() < 1e-12, "t={}: q{} = {} vs {}", k_end as f64 * H, j + 1, got[j], want[j]);
        }
    }
    assert_eq!((f.i32(STATUS), f.i32(COUNT)), (status::HOLDING, 1));
}

fn lerp(a: [f64; 7], b: [f64; 7], s: f64) -> [f64; 7] {
    std::array::from_fn(|j| a[j] + (b[j] - a[j]) * s)
}

#[test]
fn velocities_make_cubic_hermite_segments() {
    // Stamped to start at 0.2 s (ahead of its arrival at 0): Q0 holds until then.
    let f = running();
    let a = [1.0, 0.0, 0.5, -1.0, 0.3, 1.0, 0.2];
    let va = [0.2, -0.1, 0.0, 0.3, 0.0, -0.2, 0.1];
    let m = JointTrajectory {
        header: Header::new(Time::from_nanos(200_000_000), ""),
        joint_names: names(&[0, 1, 2, 3, 4, 5, 6]),
        points: vec![point(a, Some(va), 2.0)],
    };
    send(&f, 1, &m);
    steps(&f, 0, 5);
    assert_eq!(q(&f), Q0, "not started before its stamp");
    assert_eq!(f.i32(STATUS), status::EXECUTING);
    let mut k0 = 5;
    for k_end in [30, 55, 80, 109, 110, 140] {
        steps(&f, k0, k_end);
        k0 = k_end;
        let s = (k_end as f64 * H - 0.2).min(2.0);
        let got = q(&f);
        for j in 0..7 {
            // p(s) = p0 + v0 s + c2 s^2 + c3 s^3, v0 = 0 (the held set-point), T = 2.
            let (p0, p1, v1, t) = (Q0[j], a[j], va[j], 2.0);
            let c2 = (3.0 * (p1 - p0) - v1 * t) / (t * t);
            let c3 = (2.0 * (p0 - p1) + v1 * t) / (t * t * t);
            let want = p0 + s * s * (c2 + s * c3);
            assert!((got[j] - want).abs() < 1e-9, "t={}: q{} = {} vs {want}", k_end as f64 * H, j + 1, got[j]);
        }
    }
    assert_eq!(f.i32(STATUS), status::HOLDING);
}

#[test]
fn a_trajectory_naming_an_unknown_joint_is_rejected_with_status_and_log() {
    let f = running();
    let mut jn = names(&[0, 1, 2, 3, 4, 5, 6]);
    jn[3] = "right_joint4".into();
    let m = JointTrajectory { joint_names: jn, points: vec![point([0.1; 7], None, 1.0)], ..Default::default() };
    send(&f, 1, &m);
    steps(&f, 0, 60);
    assert_eq!(q(&f), Q0, "the set-points in force go on");
    assert_eq!((f.i32(STATUS), f.i32(COUNT)), (status::REJECTED, 0));
    let w = f.logged(Status::Warning);
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(w[0].contains("unknown joint name \"right_joint4\"") && w[0].contains("left_joint4"), "{w:?}");
}

#[test]
fn fewer_joints_drive_the_first_outputs_and_the_rest_hold() {
    let f = Fmu::<JointTrajectoryToScalars>::new();
    f.set_string(JOINTS, "wrist,elbow");
    f.set_f64(Q3_INIT, 0.7);
    f.enter_init();
    f.exit_init();
    let m = JointTrajectory {
        joint_names: vec!["elbow".into(), "wrist".into()],
        points: vec![JointTrajectoryPoint {
            positions: vec![0.4, -0.2],
            time_from_start: Duration::from_nanos(100_000_000),
            ..Default::default()
        }],
        ..Default::default()
    };
    send(&f, 1, &m);
    steps(&f, 0, 10);
    assert_eq!(q(&f), [-0.2, 0.4, 0.7, 0.0, 0.0, 0.0, 0.0]);
}
