//! The Arm model driven directly (no FMI layer): an invalid-trajectory corpus (all rejected,
//! the arm does not move by a single bit, every reason distinct and reported), tracking of a
//! valid trajectory with a realistic, small, non-zero error, the gripper stalling on an
//! object, message publication, and determinism.

use agrisim_fmi::{Log, Model, Store, Value};
use agrisim_fmu_arm::arm::READY_POSE;
use agrisim_fmu_arm::dynamics::{COULOMB, DEFAULT_KP};
use agrisim_fmu_arm::ports::*;
use agrisim_fmu_arm::Arm;
use agrisim_msgs::agrisim::{GripperState, TrajectoryStatus};
use agrisim_msgs::builtin_interfaces::Duration;
use agrisim_msgs::control_msgs::GripperCommand;
use agrisim_msgs::sensor_msgs::JointState;
use agrisim_msgs::trajectory_msgs::{JointTrajectory, JointTrajectoryPoint};
use agrisim_msgs::Message;

#[derive(Default)]
struct Record(Vec<String>);
impl Log for Record {
    fn info(&mut self, m: std::fmt::Arguments<'_>) {
        self.0.push(format!("info: {m}"));
    }
    fn warning(&mut self, m: std::fmt::Arguments<'_>) {
        self.0.push(format!("warning: {m}"));
    }
}

const H: f64 = 0.02;

struct Sim {
    arm: Arm,
    io: Store,
    t: f64,
    log: Record,
    traj_seq: i64,
    grip_seq: i64,
}

impl Sim {
    fn new(setup: impl FnOnce(&mut Store)) -> Sim {
        let mut io = Store::new(Arm::VARIABLES);
        setup(&mut io);
        let mut arm = Arm::new();
        let mut log = Record::default();
        arm.initialize(&mut io, 0.0, &mut log).unwrap();
        Sim { arm, io, t: 0.0, log, traj_seq: 0, grip_seq: 0 }
    }

    fn step(&mut self, n: usize) {
        for _ in 0..n {
            self.arm.do_step(&mut self.io, self.t, H, &mut self.log).unwrap();
            self.t += H;
        }
    }

    fn send(&mut self, bytes: &[u8]) {
        self.traj_seq += 1;
        self.io.set_binary(TRAJECTORY, bytes);
        self.io.set_i64(TRAJECTORY_SEQ, self.traj_seq);
    }

    fn grip(&mut self, position: f64, max_effort: f64) {
        self.grip_seq += 1;
        self.io.set_binary(GRIPPER_COMMAND, &GripperCommand { position, max_effort }.to_cdr());
        self.io.set_i64(GRIPPER_COMMAND_SEQ, self.grip_seq);
    }

    fn q(&self) -> [f64; 7] {
        Q.map(|i| self.io.f64(i))
    }

    fn q_bits(&self) -> [u64; 7] {
        self.q().map(f64::to_bits)
    }

    fn status(&self) -> TrajectoryStatus {
        TrajectoryStatus::from_cdr(agrisim_fmi::port::latest(&self.io, TRAJECTORY_STATUS)).unwrap()
    }
}

fn names(side: &str) -> Vec<String> {
    (1..=7).map(|i| format!("{side}_joint{i}")).collect()
}

fn point(q: [f64; 7], qd: Option<[f64; 7]>, t: f64) -> JointTrajectoryPoint {
    JointTrajectoryPoint {
        positions: q.to_vec(),
        velocities: qd.map_or(vec![], |v| v.to_vec()),
        accelerations: vec![],
        effort: vec![],
        time_from_start: Duration::from_secs_f64(t).unwrap(),
    }
}

fn traj(points: Vec<JointTrajectoryPoint>) -> JointTrajectory {
    JointTrajectory { joint_names: names("left"), points, ..Default::default() }
}

fn add(q: [f64; 7], d: [f64; 7]) -> [f64; 7] {
    std::array::from_fn(|i| q[i] + d[i])
}

/// A pick-like motion from the ready pose: out, via point with velocity, back (cubic).
fn sample_trajectory() -> JointTrajectory {
    let a = add(READY_POSE, [0.4, 0.3, -0.2, 0.5, 0.3, -0.4, 0.6]);
    let b = add(READY_POSE, [0.8, 0.5, -0.3, 0.9, 0.5, -0.6, 1.0]);
    let v = [0.3, 0.15, -0.05, 0.3, 0.15, -0.15, 0.3];
    traj(vec![point(a, Some(v), 1.5), point(b, Some([0.0; 7]), 3.0), point(READY_POSE, Some([0.0; 7]), 5.0)])
}

/// Invalid trajectories with what makes them invalid. Built from a valid 2-point trajectory.
fn corpus() -> Vec<(&'static str, Vec<u8>)> {
    corpus_with_reasons().into_iter().map(|(l, _, b)| (l, b)).collect()
}

/// Invalid trajectories with what makes them invalid and a fragment of the expected reason.
fn corpus_with_reasons() -> Vec<(&'static str, &'static str, Vec<u8>)> {
    let good = traj(vec![point(add(READY_POSE, [0.1; 7]), None, 1.0), point(add(READY_POSE, [0.2; 7]), None, 2.0)]);
    let m = |f: &dyn Fn(&mut JointTrajectory)| {
        let mut t = good.clone();
        f(&mut t);
        t.to_cdr()
    };
    let nan = f64::NAN;
    vec![
        ("garbage bytes", "unsupported CDR encapsulation", vec![0xde, 0xad, 0xbe, 0xef, 1, 2, 3]),
        ("empty bytes", "too short", vec![]),
        ("truncated CDR", "CDR sequence count", good.to_cdr()[..40].to_vec()),
        ("unknown joint name", "unknown joint name \"left_joint8\"", m(&|t| t.joint_names[6] = "left_joint8".into())),
        ("other arm's names", "unknown joint name \"right_joint1\"", m(&|t| t.joint_names = names("right"))),
        (
            "missing joint",
            "left_joint7 missing",
            m(&|t| {
                t.joint_names.pop();
                for p in &mut t.points {
                    p.positions.pop();
                }
            }),
        ),
        ("duplicate joint", "duplicate joint name", m(&|t| t.joint_names[1] = "left_joint1".into())),
        ("no joint names", "(0 of 7 given)", m(&|t| t.joint_names.clear())),
        ("no points", "no points", m(&|t| t.points.clear())),
        (
            "6 positions",
            "point 1: 6 positions",
            m(&|t| {
                t.points[1].positions.pop();
            }),
        ),
        ("8 positions", "point 0: 8 positions", m(&|t| t.points[0].positions.push(0.0))),
        ("3 velocities", "3 velocities", m(&|t| t.points[0].velocities = vec![0.0; 3])),
        (
            "accelerations without velocities",
            "accelerations given without velocities",
            m(&|t| t.points[0].accelerations = vec![0.0; 7]),
        ),
        ("effort given", "effort", m(&|t| t.points[1].effort = vec![1.0; 7])),
        ("NaN position", "positions[2] (left_joint3) is NaN", m(&|t| t.points[1].positions[2] = nan)),
        ("+inf position", "positions[0] (left_joint1) is inf", m(&|t| t.points[0].positions[0] = f64::INFINITY)),
        (
            "NaN velocity",
            "velocities[3] (left_joint4) is NaN",
            m(&|t| t.points[0].velocities = vec![0.0, 0.0, 0.0, nan, 0.0, 0.0, 0.0]),
        ),
        (
            "-inf acceleration",
            "accelerations[4] (left_joint5) is -inf",
            m(&|t| {
                t.points[0].velocities = vec![0.0; 7];
                t.points[0].accelerations = vec![0.0, 0.0, 0.0, 0.0, f64::NEG_INFINITY, 0.0, 0.0];
            }),
        ),
        ("nanosec >= 1e9", "nanosec 1000000000", m(&|t| t.points[1].time_from_start = Duration::new(1, 1_000_000_000))),
        (
            "negative time",
            "negative time_from_start",
            m(&|t| t.points[0].time_from_start = Duration::new(-1, 500_000_000)),
        ),
        ("equal times", "not after point 0", m(&|t| t.points[1].time_from_start = Duration::new(1, 0))),
        (
            "decreasing times",
            "0.5 s not after point 0",
            m(&|t| t.points[1].time_from_start = Duration::new(0, 500_000_000)),
        ),
        ("above upper limit", "left_joint4 position 0 rad outside limits", m(&|t| t.points[1].positions[3] = 0.0)),
        ("below lower limit", "left_joint1 position -3 rad outside limits", m(&|t| t.points[1].positions[0] = -3.0)),
        (
            "velocity beyond limit",
            "left_joint2 velocity 3 rad/s beyond limit",
            m(&|t| t.points[0].velocities = vec![0.0, 3.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
        ),
        (
            "implied velocity beyond limit",
            "point 1: left_joint1 moves",
            m(&|t| t.points[1].positions[0] = READY_POSE[0] + 2.5),
        ),
        (
            "too fast from current state",
            "from current position",
            m(&|t| t.points[0].time_from_start = Duration::new(0, 10_000_000)),
        ),
        ("jump at time 0", "a jump", m(&|t| t.points[0].time_from_start = Duration::new(0, 0))),
        (
            "reordered names, positions not",
            "left_joint4 position 0.1 rad outside limits",
            m(&|t| t.joint_names.swap(0, 3)),
        ),
    ]
}

#[test]
fn invalid_corpus_is_rejected_and_the_arm_does_not_move() {
    let mut sim = Sim::new(|_| {});
    let q0 = sim.q_bits();
    assert_eq!(sim.q(), READY_POSE);
    let corpus = corpus_with_reasons();
    let mut reasons = std::collections::BTreeSet::new();
    for (k, (label, expected, bytes)) in corpus.iter().enumerate() {
        sim.send(bytes);
        sim.step(5);
        let st = sim.status();
        assert_eq!(st.state, TrajectoryStatus::REJECTED, "{label}");
        assert_eq!(st.rejected_count, k as u64 + 1, "{label}");
        assert_eq!(st.trajectory_count, 0, "{label}: accepted");
        assert_eq!(sim.io.i32(STATUS), 2, "{label}");
        assert_eq!(sim.q_bits(), q0, "{label}: the arm moved");
        assert!(st.reason.contains(expected), "{label}: reason {:?} lacks {expected:?}", st.reason);
        let logged = sim.log.0.iter().filter(|l| l.starts_with("warning") && l.contains(&st.reason)).count();
        assert_eq!(logged, 1, "{label}: reason not logged once: {}", st.reason);
        assert!(reasons.insert(st.reason.clone()), "{label}: reason not distinct: {}", st.reason);
        println!("{label:35} -> {}", st.reason);
    }
    assert_eq!(reasons.len(), corpus.len());
    // A valid one is still accepted afterwards.
    sim.send(&sample_trajectory().to_cdr());
    sim.step(1);
    assert_eq!(sim.status().state, TrajectoryStatus::EXECUTING);
    assert_eq!(sim.io.i32(STATUS), 1);
}

/// While a valid trajectory executes, invalid ones change nothing: the arm matches, bit for
/// bit, a twin that never received them.
#[test]
fn invalid_trajectories_do_not_disturb_a_running_one() {
    let mut a = Sim::new(|_| {});
    let mut b = Sim::new(|_| {});
    let good = sample_trajectory().to_cdr();
    a.send(&good);
    b.send(&good);
    let corpus = corpus();
    for k in 0..300 {
        if k % 10 == 5 {
            a.send(&corpus[(k / 10) % corpus.len()].1);
        }
        a.step(1);
        b.step(1);
        assert_eq!(a.q_bits(), b.q_bits(), "step {k}");
        assert_eq!(a.io.f64(TRACKING_ERROR_RMS).to_bits(), b.io.f64(TRACKING_ERROR_RMS).to_bits());
    }
    assert_eq!(a.arm.rejected, 30);
    assert_eq!(a.arm.accepted, 1);
    assert_eq!(b.status().state, TrajectoryStatus::SUCCEEDED);
}

/// At rest, PD control leaves a static error up to Coulomb friction / stiffness per joint
/// (0.46 mrad at joint 1 up to 5.6 mrad at joint 7 with the default gains).
fn assert_in_stiction_band(q: [f64; 7], goal: [f64; 7]) {
    for i in 0..7 {
        let band = COULOMB[i] / DEFAULT_KP[i] + 1e-5;
        assert!((q[i] - goal[i]).abs() <= band, "joint {i}: {} vs {} (band {band})", q[i], goal[i]);
    }
}

#[test]
fn valid_trajectory_is_tracked_with_small_nonzero_error() {
    let mut sim = Sim::new(|_| {});
    let t = sample_trajectory();
    sim.send(&t.to_cdr());
    let mut max_dev = 0.0f64;
    for _ in 0..250 {
        sim.step(1);
        max_dev = max_dev.max((0..7).map(|i| (sim.q()[i] - READY_POSE[i]).abs()).fold(0.0, f64::max));
    }
    // Let it settle on the final point.
    sim.step(50);
    let st = sim.status();
    assert_eq!(st.state, TrajectoryStatus::SUCCEEDED);
    assert_eq!(st.trajectory_count, 1);
    assert_eq!(sim.io.i32(STATUS), 0);
    let rms = sim.io.f64(TRACKING_ERROR_RMS);
    println!(
        "sample trajectory (5 s, cubic, 3 points): RMS tracking error {rms:.6} rad, max {:.6} rad",
        st.max_tracking_error
    );
    assert_eq!(rms, st.rms_tracking_error);
    assert!(rms > 1e-5, "tracking error unrealistically small: {rms}");
    assert!(rms < 5e-3, "tracking error too large: {rms}");
    assert!(st.max_tracking_error >= rms && st.max_tracking_error < 0.02);
    assert!(max_dev > 0.8, "the arm did not follow the motion: {max_dev}");
    assert_in_stiction_band(sim.q(), READY_POSE);
}

/// With the controller's model equal to the plant and the friction it expects, the error
/// shrinks: the default error comes from the documented mismatch, not from a broken loop.
#[test]
fn model_mismatch_is_what_causes_most_error() {
    let run = |scale: f64| {
        let mut sim = Sim::new(|io| {
            io.set_f64(INERTIA_SCALE, scale);
            io.set_f64(COULOMB_SCALE, scale);
            io.set_f64(VISCOUS_SCALE, scale);
        });
        sim.send(&sample_trajectory().to_cdr());
        sim.step(260);
        sim.io.f64(TRACKING_ERROR_RMS)
    };
    let (exact, mismatched, no_ff) = (run(1.0), run(0.9), run(0.0));
    println!("RMS: exact model {exact:.2e}, 10 % mismatch {mismatched:.2e}, no feedforward {no_ff:.2e}");
    assert!(exact < mismatched && mismatched < no_ff);
    assert!(exact > 0.0);
}

#[test]
fn positions_only_trajectory_interpolates_linearly_and_converges() {
    let mut sim = Sim::new(|_| {});
    let goal = add(READY_POSE, [0.5, -0.3, 0.2, 0.4, -0.5, 0.3, -0.6]);
    sim.send(&traj(vec![point(goal, None, 2.0)]).to_cdr());
    sim.step(150);
    assert_eq!(sim.status().state, TrajectoryStatus::SUCCEEDED);
    assert_in_stiction_band(sim.q(), goal);
}

#[test]
fn gripper_closes_on_object_and_stalls() {
    let mut sim = Sim::new(|_| {});
    assert_eq!(sim.io.f64(FINGER_WIDTH), 0.08);
    sim.io.set_f64(GRASP_WIDTH, 0.05);
    sim.grip(0.0, 30.0);
    sim.step(10); // 0.2 s at 0.1 m/s: 0.02 m closed
    assert!((sim.io.f64(FINGER_WIDTH) - 0.06).abs() < 1e-9, "{}", sim.io.f64(FINGER_WIDTH));
    sim.step(40);
    assert_eq!(sim.io.f64(FINGER_WIDTH), 0.05);
    let gs = GripperState::from_cdr(agrisim_fmi::port::latest(&sim.io, GRIPPER_STATE)).unwrap();
    assert!(gs.stalled && !gs.reached_goal);
    assert_eq!((gs.position, gs.effort), (0.05, 30.0));
    let js = JointState::from_cdr(agrisim_fmi::port::latest(&sim.io, JOINT_STATES)).unwrap();
    assert_eq!(&js.name[7..], ["left_finger_joint1", "left_finger_joint2"]);
    assert_eq!(&js.position[7..], [0.025, 0.025]);
    assert_eq!(&js.effort[7..], [30.0, 30.0]);
    // Open again: reaches the goal, no force.
    sim.grip(0.08, 30.0);
    sim.step(30);
    let gs = GripperState::from_cdr(agrisim_fmi::port::latest(&sim.io, GRIPPER_STATE)).unwrap();
    assert!(!gs.stalled && gs.reached_goal && gs.effort == 0.0);
    // A command out of range is refused and logged; the target stays.
    sim.grip(0.2, 10.0);
    sim.step(5);
    assert!(sim.log.0.iter().any(|l| l.contains("gripper: command refused")));
    assert_eq!(sim.io.f64(FINGER_WIDTH), 0.08);
}

#[test]
fn joint_states_at_rate_with_stamps_and_right_side_names() {
    let mut sim = Sim::new(|io| {
        *io.value_mut(SIDE) = Value::String("right".into());
        io.set_f64(JOINT_STATE_RATE, 10.0);
    });
    assert_eq!(sim.io.i64(JOINT_STATES_SEQ), 1);
    let mut stamps = vec![];
    let mut last = 1;
    for _ in 0..25 {
        sim.step(1);
        if sim.io.i64(JOINT_STATES_SEQ) != last {
            last = sim.io.i64(JOINT_STATES_SEQ);
            let js = JointState::from_cdr(agrisim_fmi::port::latest(&sim.io, JOINT_STATES)).unwrap();
            assert_eq!(js.name[0], "right_joint1");
            assert_eq!(js.position.len(), 9);
            assert_eq!(js.velocity.len(), 9);
            assert_eq!(js.effort.len(), 9);
            stamps.push(js.header.stamp.to_nanos());
        }
    }
    assert_eq!(stamps, [100_000_000, 200_000_000, 300_000_000, 400_000_000, 500_000_000]);
    // Trajectory for the left arm's names is rejected by the right arm.
    sim.send(&traj(vec![point(READY_POSE, None, 1.0)]).to_cdr());
    sim.step(1);
    assert!(sim.status().reason.contains("unknown joint name \"left_joint1\""));
}

#[test]
fn deterministic_and_seeded() {
    let run = |seed: i32| {
        let mut sim = Sim::new(|io| {
            io.set_f64(POSITION_NOISE, 1e-4);
            io.set_i32(SEED, seed);
        });
        sim.send(&sample_trajectory().to_cdr());
        sim.io.set_f64(GRASP_WIDTH, 0.04);
        sim.grip(0.0, 50.0);
        let mut out = vec![];
        for _ in 0..100 {
            sim.step(1);
            out.extend_from_slice(sim.io.binary(JOINT_STATES));
            out.extend_from_slice(sim.io.binary(TRAJECTORY_STATUS));
            out.extend_from_slice(sim.io.binary(GRIPPER_STATE));
            out.extend(sim.q_bits().iter().flat_map(|b| b.to_le_bytes()));
        }
        out
    };
    assert_eq!(run(7), run(7));
    assert_ne!(run(7), run(8));
}

#[test]
fn status_published_on_change_and_periodically() {
    let mut sim = Sim::new(|io| io.set_f64(STATUS_RATE, 1.0));
    let s0 = sim.io.i64(TRAJECTORY_STATUS_SEQ);
    sim.step(10);
    assert_eq!(sim.io.i64(TRAJECTORY_STATUS_SEQ), s0, "no change, no period yet");
    sim.send(&[1, 2, 3]);
    sim.step(1);
    assert_eq!(sim.io.i64(TRAJECTORY_STATUS_SEQ), s0 + 1, "rejection publishes");
    sim.step(40); // passes t = 1 s
    assert_eq!(sim.io.i64(TRAJECTORY_STATUS_SEQ), s0 + 2, "periodic");
}

#[test]
fn bad_parameters_fail_initialization() {
    for setup in [
        (|io: &mut Store| *io.value_mut(SIDE) = Value::String("up".into())) as fn(&mut Store),
        |io| *io.value_mut(Q_INIT) = Value::String("0,0,0,0,0,0,0".into()), // joint 4 limit
        |io| *io.value_mut(Q_INIT) = Value::String("0,1".into()),
        |io| *io.value_mut(KP) = Value::String("1,2,3,4,5,6,x".into()),
        |io| io.set_f64(JOINT_STATE_RATE, f64::NAN),
    ] {
        let mut io = Store::new(Arm::VARIABLES);
        setup(&mut io);
        assert!(Arm::new().initialize(&mut io, 0.0, &mut Record::default()).is_err());
    }
}

#[test]
fn a_rejection_quoting_a_huge_joint_name_fits_the_status_port() {
    let mut a = Sim::new(|_| {});
    let mut t = sample_trajectory();
    t.joint_names[0] = "x".repeat(100_000);
    a.send(&t.to_cdr());
    a.step(1);
    let reason = a.status().reason;
    assert!(
        reason.starts_with("unknown joint name \"xxx") && reason.ends_with("...") && reason.len() <= 1024,
        "{}",
        reason.len()
    );
    assert!(a.io.binary(TRAJECTORY_STATUS).len() <= Arm::VARIABLES[TRAJECTORY_STATUS].max_size);
}
