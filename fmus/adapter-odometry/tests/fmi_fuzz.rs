//! Random FMI call sequences (illegal orders, NULLs, bad value references, wrong sizes, NaN,
//! odd step sizes) into the ScalarsToOdometry FMU's C API layer: no panic escapes, statuses
//! stay valid; plus the table, dependency and state round-trip checks.

agrisim_fmi_testing::fmu_conformance_tests!(agrisim_fmu_adapter_odometry::ScalarsToOdometry, seeds = 4, cases = 300);
