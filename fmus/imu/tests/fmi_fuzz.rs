//! Random FMI call sequences (illegal orders, NULLs, bad value references, wrong sizes, NaN,
//! odd step sizes) into the Imu FMU's C API layer: no panic escapes, statuses stay valid.

#[test]
fn variable_table_makes_a_valid_fmu() {
    agrisim_fmi::testing::assert_valid_table::<agrisim_fmu_imu::Imu>();
}

#[test]
fn random_fmi3_call_sequences() {
    for seed in 0..4 {
        agrisim_fmi::testing::fuzz_fmi3::<agrisim_fmu_imu::Imu>(seed, 300);
    }
}

#[test]
fn random_fmi2_call_sequences() {
    for seed in 0..4 {
        agrisim_fmi::testing::fuzz_fmi2::<agrisim_fmu_imu::Imu>(seed, 300);
    }
}
