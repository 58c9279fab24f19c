//! Random FMI call sequences (illegal orders, NULLs, bad value references, wrong sizes, NaN,
//! odd step sizes, garbage message bytes) into the Arm FMU's C API layer: no panic escapes,
//! statuses stay valid.

agrisim_fmi::fmu_conformance_tests!(agrisim_fmu_arm::Arm, seeds = 4, cases = 300);
