//! Random FMI call sequences (illegal orders, NULLs, bad value references, wrong sizes, NaN,
//! odd step sizes) into the Camera FMU's C API layer: no panic escapes, statuses stay valid.
//! Few cases: each published frame renders 1280x720 rays.

agrisim_fmi_testing::fmu_conformance_tests!(agrisim_fmu_camera::Camera, seeds = 4, cases = 150);

/// Weather (the generic dependency check cannot vary the environment text on its own).
#[test]
fn initial_dependencies_hold_in_fog() {
    let fog = agrisim_fmi::Value::String("weather = \"fog\"\nvisibility = 30.0".into());
    agrisim_fmi_testing::assert_initial_dependencies::<agrisim_fmu_camera::Camera>(&[(
        agrisim_fmu_camera::ports::ENVIRONMENT,
        fog,
    )]);
}
