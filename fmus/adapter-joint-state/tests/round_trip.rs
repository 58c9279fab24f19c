//! Joint scalars in, JointState out, through the generic FMI 3 layer: names, positions,
//! optional velocities and stamps on the publication grid.

#[path = "../../adapter-twist/tests/common/mod.rs"]
mod common;

use agrisim_fmi::Status;
use agrisim_fmu_adapter_joint_state::ports::*;
use agrisim_fmu_adapter_joint_state::JointStateFromScalars;
use agrisim_msgs::sensor_msgs::JointState;
use agrisim_msgs::Message;
use common::{payloads, Fmu};

const H: f64 = 0.02;

#[test]
fn positions_and_velocities_are_published_under_the_joint_names_at_the_rate() {
    let f = Fmu::<JointStateFromScalars>::new();
    f.set_string(JOINTS, "a,b,c");
    f.set_f64(RATE, 25.0);
    f.set_bool(WITH_VELOCITY, true);
    f.enter_init();
    f.exit_init();
    for k in 0..10 {
        let t = k as f64 * H;
        for j in 0..7 {
            f.set_f64(Q[j], t + j as f64);
            f.set_f64(QD[j], -(j as f64));
        }
        assert_eq!(f.step(t, H), Status::Ok);
    }
    // 25 Hz from t = 0 over 0.2 s: 6 messages; the 0.1 s window holds those stamped after 0.1 s.
    assert_eq!(f.i64(JOINT_STATES_SEQ), 6);
    let msgs = payloads(&f.binary(JOINT_STATES));
    let (seq, stamp, bytes) = msgs.last().unwrap();
    assert_eq!((*seq, *stamp), (6, 200_000_000));
    let m = JointState::from_cdr(bytes).unwrap();
    assert_eq!(m.name, ["a", "b", "c"]);
    // The inputs present at the step that reached the instant (set at t = 0.18 s).
    assert_eq!(m.position, [0.18, 1.18, 2.18]);
    assert_eq!(m.velocity, [-0.0, -1.0, -2.0]);
    assert!(m.effort.is_empty());
    assert_eq!(m.header.stamp.to_nanos(), 200_000_000);
}

#[test]
fn velocity_is_left_empty_by_default() {
    let f = Fmu::<JointStateFromScalars>::new();
    f.enter_init();
    f.set_f64(Q[6], 0.5);
    f.exit_init();
    let m = JointState::from_cdr(&payloads(&f.binary(JOINT_STATES)).pop().unwrap().2).unwrap();
    assert_eq!(m.name.len(), 7);
    assert_eq!(m.name[6], "left_joint7");
    assert_eq!(m.position[6], 0.5);
    assert!(m.velocity.is_empty());
}
