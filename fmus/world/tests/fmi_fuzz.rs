//! Random FMI call sequences (illegal orders, NULLs, bad value references, wrong sizes, NaN,
//! odd step sizes, garbage scene strings) into the Greenhouse FMU's C API layer: no panic
//! escapes, statuses stay valid.

use agrisim_fmu_world::GreenhouseWorld;

agrisim_fmi::fmu_conformance_tests!(GreenhouseWorld, seeds = 4, cases = 300);
