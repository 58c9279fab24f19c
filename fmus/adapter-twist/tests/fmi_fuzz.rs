//! The conformance tests of `agrisim_fmi_testing::fmu_conformance_tests!`, spelled out: the
//! macro's state round trip drives only Float64 inputs and scalar counters, and this model has
//! none (its one input is a message port), so nothing would change after the saved point.
//! Here the round trip is driven with Twist messages instead; the other checks are the
//! macro's: a valid table, complete initial dependencies, no direct feedthrough, and random
//! FMI 3 / FMI 2 call sequences that never let a panic escape nor return an invalid status.

use agrisim_fmi::{Model, Store};
use agrisim_fmi_testing as t;
use agrisim_fmu_adapter_twist::ports::{CMD_VEL, CMD_VEL_SEQ};
use agrisim_fmu_adapter_twist::TwistToScalars as M;
use agrisim_msgs::geometry_msgs::{Twist, Vector3};
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

/// A new command before every third step (so the watchdog also expires between them).
fn drive(io: &mut Store, k: usize) {
    if k.is_multiple_of(3) {
        let x = (0.37 * k as f64).sin();
        let m = Twist { linear: Vector3 { x, y: -x, z: 0.0 }, angular: Vector3 { x: 0.0, y: 0.0, z: 2.0 * x } };
        io.set_binary(CMD_VEL, &m.to_cdr());
        io.set_i64(CMD_VEL_SEQ, k as i64 + 1);
    }
}

#[test]
fn serialized_states_restore_exactly() {
    t::assert_state_round_trip::<M>(&[], M::STEP_SIZE, 13, 12, &drive);
}
