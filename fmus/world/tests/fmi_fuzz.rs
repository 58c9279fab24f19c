//! Random FMI call sequences (illegal orders, NULLs, bad value references, wrong sizes, NaN,
//! odd step sizes, garbage scene strings) into the Greenhouse FMU's C API layer: no panic
//! escapes, statuses stay valid.

use agrisim_fmu_world::GreenhouseWorld;

#[test]
fn variable_table_makes_a_valid_fmu() {
    agrisim_fmi::testing::assert_valid_table::<GreenhouseWorld>();
}

#[test]
fn random_fmi3_call_sequences() {
    for seed in 0..4 {
        agrisim_fmi::testing::fuzz_fmi3::<GreenhouseWorld>(seed, 300);
    }
}

#[test]
fn random_fmi2_call_sequences() {
    for seed in 0..4 {
        agrisim_fmi::testing::fuzz_fmi2::<GreenhouseWorld>(seed, 300);
    }
}
