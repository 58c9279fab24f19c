//! A number from the program around the engine (a scalar system input, always f64) reaching
//! an FMU's Int32 input is converted with checks, never cast: harvest.ssd's
//! `harvest_target_id` -> `world.target_fruit` with NaN or a fraction stops the run with an
//! error naming the variable and the value (a NaN target id must not become fruit 0).
//!
//! Needs the packed FMUs (target/fmu).

use agrisim_cosim::{LoadOptions, Master, System};
use agrisim_error::Result;
use std::path::{Path, PathBuf};

/// No messages; the target-id system input answers `x`, the other scalar inputs nothing.
struct Scalar(f64);

impl agrisim_cosim::Hooks for Scalar {
    fn scalar_input(&self, connector: &str) -> Option<f64> {
        connector.ends_with("target_id").then_some(self.0)
    }
}

fn first_step(x: f64) -> Result<()> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().unwrap();
    let fmu_dir: PathBuf = root.join("target/fmu");
    assert!(
        fmu_dir.join("Greenhouse.fmu").exists(),
        "{} has no packed FMUs: run `target/release/agrisim fmu pack`",
        fmu_dir.display()
    );
    let cache = tempfile::tempdir().unwrap();
    let mut system =
        System::load(&root.join("models/systems/harvest.ssd"), &LoadOptions::new(&fmu_dir, cache.path(), 0.02, 0.1))?;
    system.apply_parameters(&Default::default(), 1, &Default::default())?;
    let mut master = Master::new(system, 0.02, 0.1)?;
    master.initialize()?;
    master.advance(&mut Scalar(x))
}

#[test]
fn a_nan_or_fractional_target_id_is_refused() {
    first_step(3.0).unwrap();
    for (x, why) in [
        (f64::NAN, "value NaN is not a finite number"),
        (2.5, "value 2.5 is not an integer"),
        (1e12, "out of range for Int32"),
    ] {
        let e = first_step(x).unwrap_err().0;
        assert!(e.contains("target_fruit") && e.contains(why), "{x}: {e}");
    }
}
