//! Random FMI call sequences (illegal orders, NULLs, bad value references, wrong sizes, NaN,
//! odd step sizes, garbage scene strings) into the Greenhouse FMU's C API layer: no panic
//! escapes, statuses stay valid.

use agrisim_fmu_greenhouse::GreenhouseWorld;

agrisim_fmi_testing::fmu_conformance_tests!(GreenhouseWorld, seeds = 4, cases = 300);

/// Another scene (the generic dependency check cannot vary the scene text on its own).
#[test]
fn initial_dependencies_hold_for_another_scene() {
    let scene = "rows = 2\nactive_rows = 2\nwidth = 12.0\nlength = 20.0\nrow_length = 8.0";
    agrisim_fmi_testing::assert_initial_dependencies::<GreenhouseWorld>(&[(
        agrisim_fmu_greenhouse::ports::SCENE,
        agrisim_fmi::Value::String(scene.into()),
    )]);
}
