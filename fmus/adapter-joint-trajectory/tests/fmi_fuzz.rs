//! The conformance tests of `agrisim_fmi_testing::fmu_conformance_tests!`, spelled out: the
//! macro's state round trip drives only Float64 inputs and scalar counters, and this model's
//! one input is a message port, so it is driven with trajectories here; the other checks are
//! the macro's (valid table, initial dependencies, no direct feedthrough, random FMI 3 and
//! FMI 2 call sequences).

use agrisim_fmi::{Model, Store};
use agrisim_fmi_testing as t;
use agrisim_fmu_adapter_joint_trajectory::ports::{TRAJECTORY, TRAJECTORY_SEQ};
use agrisim_fmu_adapter_joint_trajectory::JointTrajectoryToScalars as M;
use agrisim_msgs::builtin_interfaces::Duration;
use agrisim_msgs::trajectory_msgs::{JointTrajectory, JointTrajectoryPoint};
use agrisim_msgs::Message;

#[test]
fn variable_table_makes_a_valid_fmu() {
    t::assert_valid_table::<M>();
}

#[test]
fn initial_dependencies_are_complete() {
    t::assert_initial_dependencies::<M>(&[]);
}

#[test]
fn no_output_changes_when_inputs_are_set() {
    t::assert_no_direct_feedthrough::<M>();
}

#[test]
fn random_fmi3_call_sequences() {
    for seed in 0..4 {
        t::fuzz_fmi3::<M>(seed, 300);
    }
}

#[test]
fn random_fmi2_call_sequences() {
    for seed in 0..4 {
        t::fuzz_fmi2::<M>(seed, 300);
    }
}

/// A new two-point trajectory every fifth step, each replacing the one before mid-way.
fn drive(io: &mut Store, k: usize) {
    if k.is_multiple_of(5) {
        let x = (0.37 * k as f64).sin();
        let pt = |q: f64, ms: i64, v: Vec<f64>| JointTrajectoryPoint {
            positions: vec![q; 7],
            velocities: v,
            time_from_start: Duration::from_nanos(ms * 1_000_000),
            ..Default::default()
        };
        let m = JointTrajectory {
            joint_names: (1..=7).map(|j| format!("left_joint{j}")).collect(),
            points: vec![pt(x, 60, vec![]), pt(-x, 200, vec![0.1; 7])],
            ..Default::default()
        };
        io.set_binary(TRAJECTORY, &m.to_cdr());
        io.set_i64(TRAJECTORY_SEQ, k as i64 + 1);
    }
}

#[test]
fn serialized_states_restore_exactly() {
    t::assert_state_round_trip::<M>(&[], M::STEP_SIZE, 13, 12, &drive);
}
