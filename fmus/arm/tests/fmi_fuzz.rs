//! Random FMI call sequences (illegal orders, NULLs, bad value references, wrong sizes, NaN,
//! odd step sizes, garbage message bytes) into the Arm FMU's C API layer: no panic escapes,
//! statuses stay valid.

agrisim_fmi_testing::fmu_conformance_tests!(agrisim_fmu_arm::Arm, seeds = 4, cases = 300);

/// String parameters the generic dependency check cannot vary on its own.
#[test]
fn initial_dependencies_hold_for_the_right_arm_and_other_gains() {
    use agrisim_fmi::Value;
    use agrisim_fmu_arm::ports::{KD, KP, Q_INIT, SIDE};
    let text = |s: &str| Value::String(s.into());
    agrisim_fmi_testing::assert_initial_dependencies::<agrisim_fmu_arm::Arm>(&[
        (SIDE, text("right")),
        (Q_INIT, text("0.1,-0.7,0.1,-2.3,0.1,1.6,0.8")),
        (KP, text("500,500,500,500,200,100,40")),
        (KD, text("40,40,40,40,20,20,10")),
    ]);
}
