//! Constant-velocity scalars in, Odometry and TF out, through the generic FMI 3 layer: with
//! noise 0 the published pose is the analytic integration (a straight line from an offset,
//! turned start, and a constant-rate circle past a full turn); the messages keep the chassis's
//! conventions; with noise the bytes depend on the seed and only on it.

#[path = "../../adapter-twist/tests/common/mod.rs"]
mod common;

use agrisim_fmi::Status;
use agrisim_fmu_adapter_odometry::ports::*;
use agrisim_fmu_adapter_odometry::ScalarsToOdometry;
use agrisim_msgs::nav_msgs::Odometry;
use agrisim_msgs::tf2_msgs::TFMessage;
use agrisim_msgs::Message;
use common::{payloads, Fmu};

const H: f64 = 0.02;

/// Runs `steps` steps from pose `p0` at the constant twist `v`, after `setup`; returns the
/// instance.
fn run(p0: [f64; 3], v: [f64; 3], steps: usize, setup: impl Fn(&Fmu<ScalarsToOdometry>)) -> Fmu<ScalarsToOdometry> {
    let f = Fmu::new();
    setup(&f);
    f.enter_init();
    for (i, x) in [X, Y, YAW].into_iter().zip(p0) {
        f.set_f64(i, x);
    }
    for (i, x) in [VX, VY, WZ].into_iter().zip(v) {
        f.set_f64(i, x);
    }
    f.exit_init();
    for k in 0..steps {
        assert_eq!(f.step(k as f64 * H, H), Status::Ok, "{:?}", f.logs);
    }
    f
}

fn odom_messages(f: &Fmu<ScalarsToOdometry>) -> Vec<(u64, i64, Odometry)> {
    payloads(&f.binary(ODOM)).into_iter().map(|(s, t, p)| (s, t, Odometry::from_cdr(&p).unwrap())).collect()
}

fn yaw_of(m: &Odometry) -> f64 {
    let q = m.pose.pose.orientation;
    2.0 * q.z.atan2(q.w)
}

fn angle_diff(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(std::f64::consts::TAU);
    d.min(std::f64::consts::TAU - d)
}

#[test]
fn a_straight_line_from_a_turned_start_matches_the_closed_form() {
    let (p0, v) = ([1.0, 2.0, 0.3], [0.5, 0.1, 0.0]);
    let f = run(p0, v, 100, |_| {});
    // 10 Hz from t = 0: 21 messages in 2 s; the 0.1 s window holds the newest.
    assert_eq!(f.i64(ODOM_SEQ), 21);
    assert_eq!(f.i64(TF_SEQ), 21);
    let msgs = odom_messages(&f);
    let (seq, stamp, m) = msgs.last().unwrap();
    assert_eq!((*seq, *stamp), (21, 2_000_000_000));
    let t = 2.0;
    let (s, c) = p0[2].sin_cos();
    let want = [p0[0] + (c * v[0] - s * v[1]) * t, p0[1] + (s * v[0] + c * v[1]) * t];
    let p = &m.pose.pose.position;
    assert!((p.x - want[0]).abs() < 1e-12 && (p.y - want[1]).abs() < 1e-12, "{p:?} vs {want:?}");
    assert_eq!(p.z, 0.0);
    assert!((yaw_of(m) - p0[2]).abs() < 1e-15);
    // The chassis's conventions: frames, stamp, twist in the base frame, zero covariances.
    assert_eq!((m.header.frame_id.as_str(), m.child_frame_id.as_str()), ("odom", "base_link"));
    assert_eq!(m.header.stamp.to_nanos(), 2_000_000_000);
    let tw = &m.twist.twist;
    assert_eq!([tw.linear.x, tw.linear.y, tw.angular.z], v);
    assert_eq!(m.pose.covariance, [0.0; 36]);
    assert_eq!(m.twist.covariance, [0.0; 36]);
    assert_eq!([f.f64(ODOM_X), f.f64(ODOM_Y)], [p.x, p.y]);
}

#[test]
fn a_constant_rate_circle_matches_the_closed_form_past_a_full_turn() {
    let (r, w) = (2.0, 0.5);
    let f = run([0.0, 0.0, 0.0], [r * w, 0.0, w], 0, |_| {});
    for k in 0..700usize {
        assert_eq!(f.step(k as f64 * H, H), Status::Ok);
        if !(k + 1).is_multiple_of(5) {
            continue;
        }
        // A message every 0.1 s: the pose on the circle of radius r about (0, r).
        let t = (k + 1) as f64 * H;
        let (_, stamp, m) = odom_messages(&f).pop().unwrap();
        assert_eq!(stamp, ((k + 1) as i64) * 20_000_000);
        let p = &m.pose.pose.position;
        let (wx, wy) = (r * (w * t).sin(), r * (1.0 - (w * t).cos()));
        assert!((p.x - wx).abs() < 1e-9 && (p.y - wy).abs() < 1e-9, "t={t}: {p:?} vs ({wx}, {wy})");
        assert!(angle_diff(yaw_of(&m), w * t) < 1e-9, "t={t}");
        assert!(f.f64(ODOM_YAW).abs() <= std::f64::consts::PI, "yaw is wrapped");
        // The transform states the same pose, with the same header.
        let tf = TFMessage::from_cdr(&payloads(&f.binary(TF)).pop().unwrap().2).unwrap();
        let ts = &tf.transforms[0];
        assert_eq!(ts.header, m.header);
        assert_eq!(ts.child_frame_id, "base_link");
        assert_eq!([ts.transform.translation.x, ts.transform.translation.y], [p.x, p.y]);
        assert_eq!(ts.transform.rotation, m.pose.pose.orientation);
    }
    assert!(700.0 * H * w > std::f64::consts::TAU, "the run went past a full turn");
}

/// Every odom and tf frame of a noisy run, as published.
fn noisy_bytes(seed: i32) -> Vec<Vec<u8>> {
    let f = run([0.5, -1.0, 1.0], [0.8, 0.0, 0.3], 0, |f| {
        f.set_i32(SEED, seed);
        f.set_f64(V_NOISE, 0.05);
        f.set_f64(WZ_NOISE, 0.02);
        f.set_f64(V_SCALE_ERROR, 0.01);
    });
    let mut out = vec![];
    for k in 0..150usize {
        assert_eq!(f.step(k as f64 * H, H), Status::Ok);
        if (k + 1).is_multiple_of(5) {
            out.extend(payloads(&f.binary(ODOM)).into_iter().map(|x| x.2));
            out.extend(payloads(&f.binary(TF)).into_iter().map(|x| x.2));
        }
    }
    out
}

#[test]
fn noise_gives_the_same_bytes_for_the_same_seed_and_others_for_another() {
    let a = noisy_bytes(7);
    assert_eq!(a, noisy_bytes(7));
    let b = noisy_bytes(8);
    assert_eq!(a.len(), b.len());
    assert_ne!(a, b);
    // And it is noise: away from the exact pose, but not far (3 s at 0.05 m/s per step).
    let exact = run([0.5, -1.0, 1.0], [0.8, 0.0, 0.3], 150, |_| {});
    let m_exact = odom_messages(&exact).pop().unwrap().2;
    let m_noisy = Odometry::from_cdr(&a[a.len() - 2]).unwrap();
    let d = (m_exact.pose.pose.position.x - m_noisy.pose.pose.position.x)
        .hypot(m_exact.pose.pose.position.y - m_noisy.pose.pose.position.y);
    assert!(d > 1e-4 && d < 0.3, "drift {d} m");
}

#[test]
fn a_scale_error_alone_stretches_the_path() {
    let f = run([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], 50, |f| f.set_f64(V_SCALE_ERROR, 0.02));
    assert!((f.f64(ODOM_X) - 1.02).abs() < 1e-12, "{}", f.f64(ODOM_X));
}
