//! Random FMI call sequences (illegal orders, NULLs, bad value references, wrong sizes, NaN,
//! odd step sizes) into the Camera FMU's C API layer: no panic escapes, statuses stay valid.
//! Few cases: each published frame renders 1280x720 rays.

agrisim_fmi::fmu_conformance_tests!(agrisim_fmu_camera::Camera, seeds = 4, cases = 150);
