//! The Imu model against analytic answers (gravity, circular motion, acceleration from
//! successive inputs, orientation), its sample clock, determinism, and a run through the
//! generic FMI 3 layer.

use agrisim_fmi::port::{latest, messages};
use agrisim_fmi::{fmi3, Model, Quiet, Status, Store};
use agrisim_fmu_imu::ports::*;
use agrisim_fmu_imu::Imu;
use agrisim_msgs::sensor_msgs;
use agrisim_msgs::Message;
use std::f64::consts::FRAC_PI_2;

const H: f64 = 0.02;
const G: f64 = 9.80665;

/// Every noise source off.
fn noiseless(io: &mut Store) {
    for i in [
        GYRO_NOISE_DENSITY,
        GYRO_BIAS_MEAN,
        GYRO_BIAS_STDDEV,
        GYRO_DYNAMIC_BIAS_STDDEV,
        GYRO_BIAS_INSTABILITY,
        ACCEL_NOISE_DENSITY,
        ACCEL_BIAS_MEAN,
        ACCEL_BIAS_STDDEV,
        ACCEL_DYNAMIC_BIAS_STDDEV,
        ACCEL_BIAS_INSTABILITY,
    ] {
        io.set_f64(i, 0.0);
    }
}

fn start(setup: impl FnOnce(&mut Store)) -> (Imu, Store) {
    let mut io = Store::new(Imu::VARIABLES);
    setup(&mut io);
    let mut m = Imu::new();
    m.initialize(&mut io, 0.0, &mut Quiet).unwrap();
    (m, io)
}

fn msg(io: &Store) -> sensor_msgs::Imu {
    sensor_msgs::Imu::from_cdr(latest(io, IMU)).unwrap()
}

fn accel(io: &Store) -> [f64; 3] {
    ACCEL.map(|i| io.f64(i))
}

fn gyro(io: &Store) -> [f64; 3] {
    GYRO.map(|i| io.f64(i))
}

fn close(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
    (0..3).all(|i| (a[i] - b[i]).abs() <= tol)
}

#[test]
fn at_rest_it_reads_plus_g_on_z_exactly_without_noise() {
    let (mut m, mut io) = start(noiseless);
    for k in 0..50 {
        m.do_step(&mut io, k as f64 * H, H, &mut Quiet).unwrap();
        assert_eq!(accel(&io), [0.0, 0.0, G]);
        assert_eq!(gyro(&io), [0.0; 3]);
    }
    let q = msg(&io).orientation;
    assert_eq!((q.x, q.y, q.z, q.w), (0.0, 0.0, 0.0, 1.0));
}

#[test]
fn at_rest_with_default_noise_the_mean_is_g_within_the_turn_on_bias() {
    let (mut m, mut io) = start(|_| {});
    let (mut sum, n) = ([0.0; 3], 500);
    for k in 0..n {
        m.do_step(&mut io, k as f64 * H, H, &mut Quiet).unwrap();
        let a = accel(&io);
        for i in 0..3 {
            sum[i] += a[i] / n as f64;
        }
    }
    // Turn-on bias 1 sigma = 1.5 mg = 0.0147 m/s^2: allow 5 sigma.
    assert!(close(sum, [0.0, 0.0, G], 0.074), "{sum:?}");
    assert_ne!(accel(&io)[2], G, "noise is on by default");
}

#[test]
fn constant_circle_gives_the_analytic_specific_force_in_a_rotated_mount() {
    // vx = 1.2 m/s, vy = -0.3 m/s, wz = 0.4 rad/s from the start: body acceleration w x v.
    // Mount at r = (0.3, -0.2, 1.0), yawed +90 deg: IMU x = base y, IMU y = -base x.
    let (vx, vy, wz, r) = (1.2, -0.3, 0.4, [0.3, -0.2, 1.0]);
    let (mut m, mut io) = start(|io| {
        noiseless(io);
        io.set_f64(VX, vx);
        io.set_f64(VY, vy);
        io.set_f64(WZ, wz);
        io.set_f64(MOUNT_X, r[0]);
        io.set_f64(MOUNT_Y, r[1]);
        io.set_f64(MOUNT_Z, r[2]);
        io.set_f64(MOUNT_YAW, FRAC_PI_2);
    });
    // Base frame: a = w x v + w x (w x r) = (-wz vy, wz vx, 0) - wz^2 (rx, ry, 0).
    let a = [-wz * vy - wz * wz * r[0], wz * vx - wz * wz * r[1], 0.0];
    let want_accel = [a[1], -a[0], G];
    for k in 0..100 {
        m.do_step(&mut io, k as f64 * H, H, &mut Quiet).unwrap();
        assert!(close(accel(&io), want_accel, 1e-12), "{:?} vs {want_accel:?}", accel(&io));
        assert!(close(gyro(&io), [0.0, 0.0, wz], 1e-15));
    }
}

#[test]
fn acceleration_comes_from_successive_velocity_inputs() {
    // The chassis speeds up at 0.5 m/s^2 and turns at a rate rising 0.1 rad/s^2.
    let (mut m, mut io) = start(noiseless);
    for k in 0..100 {
        let t = k as f64 * H;
        io.set_f64(VX, 0.5 * t);
        io.set_f64(WZ, 0.1 * t);
        m.do_step(&mut io, t, H, &mut Quiet).unwrap();
        if k >= 1 {
            let (v, w) = (0.5 * t, 0.1 * t);
            // dv/dt + w x v: (0.5, w v, 0); the mount at z = 1 m sees no dw/dt x r term.
            let want = [0.5, w * v, G];
            assert!(close(accel(&io), want, 1e-9), "t={t}: {:?} vs {want:?}", accel(&io));
        }
    }
}

#[test]
fn orientation_is_base_yaw_advanced_by_the_rate_then_the_mount() {
    let (mut m, mut io) = start(|io| {
        noiseless(io);
        io.set_f64(MOUNT_PITCH, 0.3);
    });
    io.set_f64(BASE_YAW, 1.0);
    io.set_f64(WZ, 0.5);
    m.do_step(&mut io, 0.0, H, &mut Quiet).unwrap();
    let q = msg(&io).orientation;
    // Yaw at the sample (t = 0.02): 1.0 + 0.5 * 0.02; then pitch 0.3 about the mount's y.
    let (y, p): (f64, f64) = ((1.0 + 0.5 * H) / 2.0, 0.3 / 2.0);
    let want = (-y.sin() * p.sin(), y.cos() * p.sin(), y.sin() * p.cos(), y.cos() * p.cos());
    assert!(
        (q.x - want.0).abs() < 1e-12
            && (q.y - want.1).abs() < 1e-12
            && (q.z - want.2).abs() < 1e-12
            && (q.w - want.3).abs() < 1e-12,
        "{q:?} vs {want:?}"
    );
}

#[test]
fn samples_follow_the_rate_on_simulation_time() {
    // 200 Hz on a 0.02 s step: every step publishes its 4 samples, 5 ms apart, and the port
    // holds those of the last 0.1 s (port_window).
    let (mut m, mut io) = start(|_| {});
    assert_eq!(io.i64(IMU_SEQ), 1, "a sample at the start");
    for k in 0..10 {
        m.do_step(&mut io, k as f64 * H, H, &mut Quiet).unwrap();
        assert_eq!(io.i64(IMU_SEQ), 4 * k + 5);
        assert_eq!(msg(&io).header.stamp.to_nanos(), (k + 1) * 20_000_000);
        let stamps: Vec<i64> =
            messages(&io, IMU).iter().map(|b| sensor_msgs::Imu::from_cdr(b).unwrap().header.stamp.to_nanos()).collect();
        let first = if k < 4 { 0 } else { (k - 4) * 20_000_000 + 5_000_000 };
        assert_eq!(stamps, (first..=(k + 1) * 20_000_000).step_by(5_000_000).collect::<Vec<_>>(), "step {k}");
    }
    // 30 Hz: samples at multiples of 33.333 ms; steps without one publish nothing.
    let (mut m, mut io) = start(|io| io.set_f64(RATE, 30.0));
    let mut stamps = vec![];
    for k in 0..50 {
        let before = io.i64(IMU_SEQ);
        m.do_step(&mut io, k as f64 * H, H, &mut Quiet).unwrap();
        let new = (io.i64(IMU_SEQ) - before) as usize;
        let all = messages(&io, IMU);
        stamps.extend(
            all[all.len() - new..].iter().map(|b| sensor_msgs::Imu::from_cdr(b).unwrap().header.stamp.to_nanos()),
        );
    }
    let want: Vec<i64> = (1..=30).map(|k| k * 33_333_333).collect();
    assert_eq!(stamps, want);
}

#[test]
fn message_carries_frame_and_covariances() {
    let (_, io) = start(|io| io.set_bool(ENABLE_ORIENTATION, false));
    let m = msg(&io);
    assert_eq!(m.header.frame_id, "imu_link");
    assert_eq!(m.orientation_covariance[0], -1.0);
    let gw = io.f64(GYRO_NOISE_DENSITY) * 200f64.sqrt();
    assert!((m.angular_velocity_covariance[4] - gw * gw).abs() < 1e-20);
    assert_eq!(m.angular_velocity_covariance[1], 0.0);
    let (_, io) = start(|_| {});
    assert_eq!(msg(&io).orientation_covariance, [0.0; 9]);
}

fn run_bytes(seed: i32) -> Vec<Vec<u8>> {
    let (mut m, mut io) = start(|io| io.set_i32(SEED, seed));
    (0..100)
        .map(|k| {
            io.set_f64(VX, (k as f64 * 0.1).sin());
            io.set_f64(WZ, 0.2);
            m.do_step(&mut io, k as f64 * H, H, &mut Quiet).unwrap();
            io.binary(IMU).to_vec()
        })
        .collect()
}

#[test]
fn same_seed_same_bytes_other_seed_differs() {
    assert_eq!(run_bytes(7), run_bytes(7));
    assert_ne!(run_bytes(7), run_bytes(8));
}

#[test]
fn a_huge_step_stays_cheap_and_finite() {
    let (mut m, mut io) = start(|_| {});
    m.do_step(&mut io, 0.0, 1e6, &mut Quiet).unwrap();
    assert_eq!(msg(&io).header.stamp.to_nanos(), 1_000_000 * 1_000_000_000);
    assert!(accel(&io).iter().chain(gyro(&io).iter()).all(|v| v.is_finite()));
    assert!(m.do_step(&mut io, 1e6, 1e300, &mut Quiet).is_ok());
}

#[test]
fn through_the_fmi3_layer() {
    let token = std::ffi::CString::new(Imu::TOKEN).unwrap();
    unsafe {
        let p = fmi3::instantiate_co_simulation::<Imu>(
            c"imu".as_ptr(),
            token.as_ptr(),
            std::ptr::null(),
            0,
            0,
            0,
            0,
            std::ptr::null(),
            0,
            std::ptr::null_mut(),
            None,
            None,
        );
        assert!(!p.is_null());
        let vr = |i: usize| i as u32 + 1;
        assert_eq!(fmi3::set_float64::<Imu>(p, &vr(RATE), 1, &100.0, 1), Status::Ok);
        assert_eq!(fmi3::set_boolean::<Imu>(p, &vr(ENABLE_ORIENTATION), 1, &0u8, 1), Status::Ok);
        assert_eq!(fmi3::enter_initialization_mode::<Imu>(p, 0, 0.0, 0.0, 0, 0.0), Status::Ok);
        assert_eq!(fmi3::exit_initialization_mode::<Imu>(p), Status::Ok);
        assert_eq!(fmi3::set_float64::<Imu>(p, &vr(WZ), 1, &0.3, 1), Status::Ok);
        let (mut a, mut b, mut c, mut last) = (0u8, 0u8, 0u8, 0.0);
        for k in 0..5 {
            assert_eq!(fmi3::do_step::<Imu>(p, k as f64 * H, H, 0, &mut a, &mut b, &mut c, &mut last), Status::Ok);
        }
        let mut seq = 0i64;
        assert_eq!(fmi3::get_int64::<Imu>(p, &vr(IMU_SEQ), 1, &mut seq, 1), Status::Ok);
        assert_eq!(seq, 11, "100 Hz: two samples per step");
        let (mut size, mut data) = (0usize, std::ptr::null::<u8>());
        assert_eq!(fmi3::get_binary::<Imu>(p, &vr(IMU), 1, &mut size, &mut data, 1), Status::Ok);
        let frames = agrisim_frames::decode(std::slice::from_raw_parts(data, size)).unwrap();
        assert_eq!(
            frames.iter().map(|f| f.seq).collect::<Vec<_>>(),
            (2..=11).collect::<Vec<_>>(),
            "the samples of the last 0.1 s"
        );
        let m = sensor_msgs::Imu::from_cdr(frames.last().unwrap().payload).unwrap();
        assert_eq!(m.header.stamp.to_nanos(), 100_000_000);
        assert_eq!(m.orientation_covariance[0], -1.0);
        assert!((m.angular_velocity.z - 0.3).abs() < 0.05, "{}", m.angular_velocity.z);
        let mut gz = 0.0;
        assert_eq!(fmi3::get_float64::<Imu>(p, &vr(GYRO_Z), 1, &mut gz, 1), Status::Ok);
        assert_eq!(gz, m.angular_velocity.z);
        // A bad parameter is refused at initialization with the parameter's name.
        assert_eq!(fmi3::reset::<Imu>(p), Status::Ok);
        assert_eq!(fmi3::set_float64::<Imu>(p, &vr(GYRO_NOISE_DENSITY), 1, &-1.0, 1), Status::Ok);
        assert_eq!(fmi3::enter_initialization_mode::<Imu>(p, 0, 0.0, 0.0, 0, 0.0), Status::Ok);
        assert_eq!(fmi3::exit_initialization_mode::<Imu>(p), Status::Error);
        fmi3::free_instance::<Imu>(p);
    }
}
