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
        agrisim_fmi::testing::fuzz_fmi3::<TestModel>(seed, 300);
    }
}

#[test]
fn fuzz_fmi2() {
    quiet_injected_panics();
    for seed in 0..4 {
        agrisim_fmi::testing::fuzz_fmi2::<TestModel>(seed, 300);
    }
}

#[test]
fn model_structure_dependencies_hold() {
    agrisim_fmi::testing::assert_valid_table::<TestModel>();
    agrisim_fmi::testing::assert_initial_dependencies::<TestModel>(&[]);
    agrisim_fmi::testing::assert_no_direct_feedthrough::<TestModel>();
}
