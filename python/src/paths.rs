//! Where the checkout's models, scenarios and packed FMUs are: `AGRISIM_ROOT`, else the
//! checkout this module was built from (the package is built from a checkout: `pip install
//! ./python`), so scenarios may be named (`"default"`) as well as given as paths.

use pyo3::prelude::*;
use std::path::{Path, PathBuf};

/// The agrisim checkout: `AGRISIM_ROOT` or the one this module was built from.
#[pyfunction]
pub fn root() -> PathBuf {
    std::env::var_os("AGRISIM_ROOT")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("python/ has a parent").to_path_buf())
}

/// A scenario file: an existing path as given, else `models/scenarios/NAME.toml` of the root.
#[pyfunction]
pub fn scenario_path(scenario: PathBuf) -> PathBuf {
    if scenario.exists() || scenario.extension().is_some() || scenario.components().count() > 1 {
        return scenario;
    }
    root().join("models/scenarios").join(scenario).with_extension("toml")
}

/// The packed FMUs (`agrisim fmu pack`) and their unpack cache.
pub fn fmu_dirs() -> (PathBuf, PathBuf) {
    let target = std::env::var_os("AGRISIM_TARGET").map(PathBuf::from).unwrap_or_else(|| root().join("target"));
    (target.join("fmu"), target.join("fmu-cache"))
}

/// The `agrisim` command of the checkout (benchmark worker processes run it).
pub fn agrisim_bin() -> PathBuf {
    std::env::var_os("AGRISIM_BIN").map(PathBuf::from).unwrap_or_else(|| root().join("target/release/agrisim"))
}
