//! The shared randomized call-sequence harness on the test model.

use agrisim_fmu_testmodel::TestModel;

/// Injected panics (fault = 2) are expected; keep them out of the test output.
fn quiet_injected_panics() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        if !info.to_string().contains("testmodel: injected panic") {
            default(info);
        }
    }));
}

#[test]
fn fuzz_fmi3() {
    quiet_injected_panics();
    for seed in 0..4 {
        agrisim_fmi_testing::fuzz_fmi3::<TestModel>(seed, 300);
    }
}

#[test]
fn fuzz_fmi2() {
    quiet_injected_panics();
    for seed in 0..4 {
        agrisim_fmi_testing::fuzz_fmi2::<TestModel>(seed, 300);
    }
}

#[test]
fn model_structure_dependencies_hold() {
    agrisim_fmi_testing::assert_valid_table::<TestModel>();
    agrisim_fmi_testing::assert_initial_dependencies::<TestModel>(&[]);
    agrisim_fmi_testing::assert_no_direct_feedthrough::<TestModel>();
}

#[test]
fn serialized_states_restore_exactly() {
    use agrisim_fmi::Value;
    use agrisim_fmu_testmodel::*;
    let params = [(X0, Value::Float64(2.5)), (LABEL, Value::String("saved".into()))];
    let n = agrisim_fmi_testing::assert_state_round_trip::<TestModel>(&params, 0.02, 7, 9, &|io, k| {
        io.set_f64(U, (k as f64 * 0.3).sin());
        io.set_binary(MSG_IN, &[k as u8; 3]);
    });
    assert!(n > 50, "{n} bytes");
}
