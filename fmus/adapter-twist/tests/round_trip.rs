//! CDR Twist messages in, scalars out, through the generic FMI 3 layer: the port names are
//! the flattened .msg fields, commands in one step are applied in order, the newest wins, a
//! bad message is refused, and the watchdog zeroes the outputs like the chassis's.

mod common;

use agrisim_fmi::{Causality, Model, Start, Status};
use agrisim_fmu_adapter_twist::fields::FIELDS;
use agrisim_fmu_adapter_twist::ports::*;
use agrisim_fmu_adapter_twist::TwistToScalars;
use agrisim_msgs::geometry_msgs::{Twist, Vector3};
use agrisim_msgs::Message;
use common::{frames, Fmu};

const H: f64 = 0.02;

fn twist(v: [f64; 6]) -> Vec<u8> {
    Twist { linear: Vector3 { x: v[0], y: v[1], z: v[2] }, angular: Vector3 { x: v[3], y: v[4], z: v[5] } }.to_cdr()
}

/// Index of the output named `name`.
fn output(name: &str) -> usize {
    VARIABLES.iter().position(|v| v.name == name).unwrap_or_else(|| panic!("no variable {name}"))
}

/// The six outputs by their message field names.
fn outputs(f: &Fmu<TwistToScalars>) -> [f64; 6] {
    ["linear_x", "linear_y", "linear_z", "angular_x", "angular_y", "angular_z"].map(|n| f.f64(output(n)))
}

fn running() -> Fmu<TwistToScalars> {
    let f = Fmu::new();
    f.enter_init();
    f.exit_init();
    f
}

#[test]
fn the_float64_outputs_are_the_flattened_twist_fields_in_message_order() {
    let outs: Vec<(&str, &str)> = TwistToScalars::VARIABLES
        .iter()
        .filter(|v| v.causality == Causality::Output && matches!(v.start, Start::Float64(_)))
        .map(|v| (v.name, v.unit))
        .collect();
    assert_eq!(
        outs,
        [
            ("linear_x", "m/s"),
            ("linear_y", "m/s"),
            ("linear_z", "m/s"),
            ("angular_x", "rad/s"),
            ("angular_y", "rad/s"),
            ("angular_z", "rad/s")
        ]
    );
    assert_eq!(FIELDS.map(|f| f.path), ["linear.x", "linear.y", "linear.z", "angular.x", "angular.y", "angular.z"]);
    assert_eq!(VARIABLES[CMD_VEL].mime_type, "application/x-ros2-cdr-frames; version=1; type=geometry_msgs/msg/Twist");
}

#[test]
fn commands_in_one_step_are_taken_in_order_and_the_newest_is_output() {
    let f = running();
    assert_eq!(outputs(&f), [0.0; 6]);
    assert!(!f.bool(ACTIVE));
    let a = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6];
    let b = [-1.0, -2.0, -3.0, -4.0, -5.0, -6.0];
    let c = [1.5, -0.25, 0.0, 0.0, 0.0, 0.75];
    f.set_binary(CMD_VEL, &frames(1, 0, &[twist(a), twist(b), twist(c)]));
    f.set_i64(CMD_VEL_SEQ, 3);
    assert_eq!(f.step(0.0, H), Status::Ok);
    assert_eq!(outputs(&f), c, "each output carries its own field");
    assert_eq!(f.i32(COUNT), 3);
    assert!(f.bool(ACTIVE));

    // The same list seen again (exchanged more often than the window) adds nothing.
    assert_eq!(f.step(H, H), Status::Ok);
    assert_eq!(f.i32(COUNT), 3);

    // One bare CDR message, taken when the counter moves.
    f.set_binary(CMD_VEL, &twist(a));
    f.set_i64(CMD_VEL_SEQ, 4);
    assert_eq!(f.step(2.0 * H, H), Status::Ok);
    assert_eq!(outputs(&f), a);
    assert_eq!(f.i32(COUNT), 4);
    assert!(f.logged(Status::Warning).is_empty(), "{:?}", f.logs);
}

#[test]
fn a_bad_message_is_refused_with_a_warning_and_the_last_command_stays() {
    let f = running();
    let a = [0.5, 0.0, 0.0, 0.0, 0.0, 0.1];
    f.set_binary(CMD_VEL, &frames(1, 0, &[twist(a), vec![0, 1, 0, 0, 7], twist([f64::NAN; 6])]));
    f.set_i64(CMD_VEL_SEQ, 3);
    assert_eq!(f.step(0.0, H), Status::Ok);
    assert_eq!(outputs(&f), a);
    assert_eq!(f.i32(COUNT), 1);
    let w = f.logged(Status::Warning);
    assert_eq!(w.len(), 2, "{w:?}");
    assert!(w[0].contains("not a valid geometry_msgs/msg/Twist"), "{w:?}");
    assert!(w[1].contains("non-finite"), "{w:?}");
}

#[test]
fn the_watchdog_zeroes_the_outputs_when_commands_stop_like_the_chassis() {
    // Default timeout 0.5 s: a command taken at t = 0 is in force for the steps starting
    // before 0.5 s, as the chassis follows it; the step from 0.5 s outputs 0.
    let f = running();
    let a = [0.3, 0.0, 0.0, 0.0, 0.0, -0.2];
    f.set_binary(CMD_VEL, &twist(a));
    f.set_i64(CMD_VEL_SEQ, 1);
    for k in 0..25 {
        assert_eq!(f.step(k as f64 * H, H), Status::Ok);
        assert_eq!(outputs(&f), a, "step {k}");
    }
    assert_eq!(f.step(25.0 * H, H), Status::Ok);
    assert_eq!(outputs(&f), [0.0; 6]);
    assert!(!f.bool(ACTIVE));
    // A fresh command revives it.
    f.set_binary(CMD_VEL, &twist(a));
    f.set_i64(CMD_VEL_SEQ, 2);
    assert_eq!(f.step(26.0 * H, H), Status::Ok);
    assert_eq!(outputs(&f), a);
}

#[test]
fn a_timeout_of_zero_disables_the_watchdog() {
    let f = Fmu::<TwistToScalars>::new();
    f.set_f64(TIMEOUT, 0.0);
    f.enter_init();
    // A command present at initialization is taken then.
    let a = [0.0, 0.4, 0.0, 0.0, 0.0, 0.0];
    f.set_binary(CMD_VEL, &twist(a));
    f.set_i64(CMD_VEL_SEQ, 1);
    f.exit_init();
    assert_eq!(outputs(&f), a);
    for k in 0..200 {
        assert_eq!(f.step(k as f64 * H, H), Status::Ok);
    }
    assert_eq!(outputs(&f), a);
    assert_eq!(f.i32(COUNT), 1);
}
