//! Paths shared by the session crate's integration tests.

use std::path::{Path, PathBuf};

/// The workspace root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().unwrap()
}

/// The packed FMUs (target/fmu), checked to hold `fmu`.
pub fn fmu_dir(fmu: &str) -> PathBuf {
    let d = root().join("target/fmu");
    assert!(d.join(fmu).exists(), "{} has no packed FMUs: run `target/release/agrisim fmu pack`", d.display());
    d
}
