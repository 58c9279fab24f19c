//! Chassis models against analytic answers and their own contracts, through the Model trait.

use agrisim_chassis::ports::*;
use agrisim_chassis::{ChassisDynamic, ChassisKinematic};
use agrisim_fmi::{Model, Quiet, Store};
use agrisim_msgs::geometry_msgs::{Twist, Vector3};
use agrisim_msgs::nav_msgs::Odometry;
use agrisim_msgs::Message;

const H: f64 = 0.02;

fn start<M: Model>(setup: impl FnOnce(&mut Store)) -> (M, Store) {
    let mut io = Store::new(M::VARIABLES);
    setup(&mut io);
    let mut m = M::new();
    m.initialize(&mut io, 0.0, &mut Quiet).unwrap();
    (m, io)
}

fn run<M: Model>(m: &mut M, io: &mut Store, from_step: usize, steps: usize) {
    for k in from_step..from_step + steps {
        m.do_step(io, k as f64 * H, H, &mut Quiet).unwrap();
    }
}

/// Ideal actuators: every limit out of the way, watchdog off.
fn ideal(io: &mut Store) {
    io.set_f64(STEER_RATE_MAX, 1e12);
    io.set_f64(WHEEL_SPEED_MAX, 1e12);
    io.set_f64(WHEEL_ACCEL_MAX, 1e15);
    io.set_f64(CMD_TIMEOUT, 0.0);
}

#[test]
fn straight_line_with_acceleration_limit_matches_trapezoid() {
    // 1 m/s forward; wheel accel 10 rad/s^2 x 0.1 m = 1 m/s^2: ramp 1 s, then constant.
    let (mut m, mut io) = start::<ChassisKinematic>(|io| {
        io.set_f64(CMD_TIMEOUT, 0.0);
        io.set_f64(CMD_VX, 1.0);
    });
    run(&mut m, &mut io, 0, 250); // 5 s
    let x_analytic = 0.5 * 1.0 * 1.0 + 1.0 * 4.0;
    assert!((io.f64(X) - x_analytic).abs() < 1e-6, "x {} vs {}", io.f64(X), x_analytic);
    assert!(io.f64(Y).abs() < 1e-12 && io.f64(YAW).abs() < 1e-12);
    assert!((io.f64(VX) - 1.0).abs() < 1e-12);
}

#[test]
fn circle_matches_analytic_pose() {
    let (v, w, vy) = (0.6, 0.3, 0.2);
    let (mut m, mut io) = start::<ChassisKinematic>(|io| {
        ideal(io);
        io.set_f64(CMD_VX, v);
        io.set_f64(CMD_VY, vy);
        io.set_f64(CMD_WZ, w);
        io.set_f64(X0, 1.0);
        io.set_f64(YAW0, 0.5);
    });
    for k in 0..1500 {
        m.do_step(&mut io, k as f64 * H, H, &mut Quiet).unwrap();
        let t = (k + 1) as f64 * H;
        // p(t) = p0 + R(yaw0) [ (sin wt v - (1-cos wt) vy)/w, ((1-cos wt) v + sin wt vy)/w ]
        let (s, c) = (w * t).sin_cos();
        let (bx, by) = ((s * v - (1.0 - c) * vy) / w, ((1.0 - c) * v + s * vy) / w);
        let (s0, c0) = 0.5f64.sin_cos();
        let (xa, ya) = (1.0 + c0 * bx - s0 * by, s0 * bx + c0 * by);
        assert!(
            (io.f64(X) - xa).abs() < 1e-6 && (io.f64(Y) - ya).abs() < 1e-6,
            "t={t}: ({}, {}) vs ({xa}, {ya})",
            io.f64(X),
            io.f64(Y)
        );
        // Without noise, odometry equals ground truth (in its own frame, which starts at the initial pose).
        assert!((io.f64(ODOM_X) - io.f64(X)).abs() < 1e-9);
    }
}

fn drift_after(seed: i32) -> f64 {
    let (mut m, mut io) = start::<ChassisKinematic>(|io| {
        io.set_f64(CMD_TIMEOUT, 0.0);
        io.set_f64(CMD_VX, 0.8);
        io.set_f64(CMD_WZ, 0.1);
        io.set_f64(ENC_NOISE, 0.2);
        io.set_f64(STEER_NOISE, 0.01);
        io.set_f64(SLIP_MEAN, 0.02);
        io.set_f64(SLIP_STD, 0.05);
        io.set_i32(SEED, seed);
    });
    run(&mut m, &mut io, 0, 1000);
    (io.f64(ODOM_X) - io.f64(X)).hypot(io.f64(ODOM_Y) - io.f64(Y))
}

#[test]
fn odometry_drifts_with_noise_and_depends_on_seed() {
    let (a, a2, b) = (drift_after(1), drift_after(1), drift_after(2));
    assert!(a > 0.05, "drift {a} m after 20 s should be visible");
    assert_eq!(a.to_bits(), a2.to_bits(), "same seed, same drift");
    assert_ne!(a.to_bits(), b.to_bits(), "other seed, other drift");
}

#[test]
fn watchdog_stops_the_base_without_fresh_commands() {
    let (mut m, mut io) = start::<ChassisKinematic>(|io| io.set_f64(CMD_VX, 0.5));
    run(&mut m, &mut io, 0, 10);
    assert!(io.f64(VX) > 0.0 && io.bool(CMD_ACTIVE));
    run(&mut m, &mut io, 10, 40); // t = 1.0 s > 0.5 s timeout, decel 1 m/s^2
    assert!(!io.bool(CMD_ACTIVE));
    assert_eq!(io.f64(VX), 0.0);
    // A fresh scalar command (counter change) restarts it.
    io.set_i32(CMD_SEQ, 1);
    run(&mut m, &mut io, 50, 5);
    assert!(io.bool(CMD_ACTIVE) && io.f64(VX) > 0.0);
}

#[test]
fn twist_message_is_followed_and_latest_wins() {
    let (mut m, mut io) = start::<ChassisKinematic>(ideal);
    let msg = Twist { linear: Vector3 { x: 0.0, y: 0.4, z: 0.0 }, angular: Vector3::default() };
    io.set_binary(CMD_VEL, &msg.to_cdr());
    io.set_i64(CMD_VEL_SEQ, 1);
    run(&mut m, &mut io, 0, 50);
    assert!((io.f64(Y) - 0.4).abs() < 1e-9 && io.f64(X).abs() < 1e-12, "y {}", io.f64(Y));
    io.set_f64(CMD_VX, 0.1);
    io.set_i32(CMD_SEQ, 7);
    run(&mut m, &mut io, 50, 50);
    assert!((io.f64(X) - 0.1).abs() < 1e-9 && (io.f64(Y) - 0.4).abs() < 1e-9);
}

/// Collects warnings.
#[derive(Default)]
struct Warnings(Vec<String>);

impl agrisim_fmi::Log for Warnings {
    fn info(&mut self, _: std::fmt::Arguments<'_>) {}
    fn warning(&mut self, m: std::fmt::Arguments<'_>) {
        self.0.push(m.to_string());
    }
}

#[test]
fn garbage_twist_is_refused_with_a_warning_and_the_last_valid_command_stays() {
    let (mut m, mut io) = start::<ChassisKinematic>(|io| {
        ideal(io);
        io.set_f64(CMD_TIMEOUT, 0.5);
    });
    let good = Twist { linear: Vector3 { x: 0.3, y: 0.0, z: 0.0 }, angular: Vector3::default() };
    io.set_binary(CMD_VEL, &good.to_cdr());
    io.set_i64(CMD_VEL_SEQ, 1);
    let mut log = Warnings::default();
    m.do_step(&mut io, 0.0, H, &mut log).unwrap();
    io.set_binary(CMD_VEL, &[0xde, 0xad, 0xbe]);
    io.set_i64(CMD_VEL_SEQ, 2);
    m.do_step(&mut io, H, H, &mut log).unwrap();
    assert_eq!(log.0.len(), 1, "{:?}", log.0);
    assert!(
        log.0[0].contains("cmd_vel") && log.0[0].contains("refused") && log.0[0].contains("t=0.02"),
        "{}",
        log.0[0]
    );
    assert!(io.bool(CMD_ACTIVE) && (io.f64(VX) - 0.3).abs() < 1e-9, "the last valid command stays in force");
    // ... until the watchdog: the refused message does not count as a command.
    for k in 2..30 {
        m.do_step(&mut io, k as f64 * H, H, &mut log).unwrap();
    }
    assert!(!io.bool(CMD_ACTIVE) && io.f64(VX).abs() < 1e-9, "the watchdog stopped the base");
}

#[test]
fn odom_message_published_at_ten_hertz_with_sim_time_stamps() {
    let (mut m, mut io) = start::<ChassisKinematic>(|io| io.set_f64(CMD_VX, 0.2));
    assert_eq!(io.i64(ODOM_SEQ), 1);
    let mut stamps = vec![];
    let mut seq = 1;
    for k in 0..50 {
        m.do_step(&mut io, k as f64 * H, H, &mut Quiet).unwrap();
        if io.i64(ODOM_SEQ) != seq {
            seq = io.i64(ODOM_SEQ);
            let o = Odometry::from_cdr(agrisim_fmi::port::latest(&io, ODOM)).unwrap();
            assert_eq!(o.header.frame_id, "odom");
            assert_eq!(o.child_frame_id, "base_link");
            stamps.push(o.header.stamp.sec as i64 * 1_000_000_000 + o.header.stamp.nanosec as i64);
        }
    }
    assert_eq!(stamps, (1..=10).map(|i| i * 100_000_000).collect::<Vec<i64>>());
}

#[test]
fn dynamic_model_slips_under_hard_acceleration_and_tracks_slow_commands() {
    let cmd = |io: &mut Store| {
        io.set_f64(CMD_TIMEOUT, 0.0);
        io.set_f64(CMD_VX, 1.0);
    };
    let (mut k, mut ik) = start::<ChassisKinematic>(cmd);
    let (mut d, mut id) = start::<ChassisDynamic>(cmd);
    run(&mut k, &mut ik, 0, 250);
    run(&mut d, &mut id, 0, 250);
    // Same ports, different physics: close in steady state, not equal.
    assert!((id.f64(VX) - 1.0).abs() < 0.02, "dynamic vx {}", id.f64(VX));
    assert!(id.f64(X) != ik.f64(X));
    assert!((id.f64(X) - ik.f64(X)).abs() < 0.3, "{} vs {}", id.f64(X), ik.f64(X));
    // Low friction + aggressive profile: the wheels spin faster than the ground moves.
    let (mut d2, mut io2) = start::<ChassisDynamic>(|io| {
        cmd(io);
        io.set_f64(MU, 0.05);
        io.set_f64(WHEEL_ACCEL_MAX, 100.0);
    });
    run(&mut d2, &mut io2, 0, 25);
    let wheel_speed = io2.f64(SPIN_FL) * 0.1;
    assert!(wheel_speed - io2.f64(VX) > 0.1, "wheel {wheel_speed} vs ground {}", io2.f64(VX));
    assert!((io2.f64(ODOM_X) - io2.f64(X)).abs() > 0.01, "odometry must over-estimate when the wheels slip");
}

#[test]
fn heavier_payload_slows_the_dynamic_chassis() {
    let go = |mass: f64| {
        let (mut d, mut io) = start::<ChassisDynamic>(|io| {
            io.set_f64(CMD_TIMEOUT, 0.0);
            io.set_f64(CMD_VX, 1.0);
            io.set_f64(WHEEL_ACCEL_MAX, 100.0);
            io.set_f64(PAYLOAD_MASS, mass);
        });
        run(&mut d, &mut io, 0, 10);
        io.f64(VX)
    };
    assert!(go(0.0) > go(300.0));
}

#[test]
fn invalid_parameters_are_refused_with_their_name() {
    let mut io = Store::new(VARIABLES);
    io.set_f64(WHEEL_RADIUS, -1.0);
    let err = ChassisKinematic::new().initialize(&mut io, 0.0, &mut Quiet).unwrap_err();
    assert!(err.contains("wheel_radius"), "{err}");
    let mut io = Store::new(VARIABLES);
    io.set_f64(MASS, f64::NAN);
    let err = ChassisDynamic::new().initialize(&mut io, 0.0, &mut Quiet).unwrap_err();
    assert!(err.contains("mass"), "{err}");
}
