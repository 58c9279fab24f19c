//! The scenario's greenhouse, generated the same way every FMU generates it (from the
//! `[greenhouse]` TOML text and its seed), for the orchestrator's own uses: the static map,
//! benchmark targets, glTF export, reports.

use crate::error::Result;
use crate::scenario::Scenario;
use agrisim_greenhouse::{generate, Greenhouse, GreenhouseConfig};

pub fn generate_scene(s: &Scenario) -> Result<Greenhouse> {
    let cfg = GreenhouseConfig::from_toml_str(&s.scene_toml()).map_err(|e| crate::err!("scenario {}: [greenhouse]: {e}", s.path.display()))?;
    Ok(generate(&cfg, cfg.seed))
}
