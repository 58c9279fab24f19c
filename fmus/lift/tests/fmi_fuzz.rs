//! Random FMI call sequences (illegal orders, NULLs, bad value references, wrong sizes, NaN,
//! odd step sizes) into the Lift FMU's C API layer: no panic escapes, statuses stay valid.

agrisim_fmi_testing::fmu_conformance_tests!(agrisim_fmu_lift::Lift, seeds = 4, cases = 300);
