//! The scenario's greenhouse, generated the same way every FMU generates it (from the
//! `[greenhouse]` TOML text and its seed), for the orchestrator's own uses: the static map,
//! benchmark targets, glTF export, reports.

use crate::scenario::Scenario;
use agrisim_error::Result;
use agrisim_greenhouse::{generate, Greenhouse, GreenhouseConfig, Layout};

fn config(s: &Scenario) -> Result<GreenhouseConfig> {
    GreenhouseConfig::from_toml_str(&s.scene_toml()).map_err(|e| agrisim_error::err!("scenario {}: [greenhouse]: {e}", s.path.display()))
}

pub fn generate_scene(s: &Scenario) -> Result<Greenhouse> {
    let cfg = config(s)?;
    Ok(generate(&cfg, cfg.seed))
}

/// The layout alone (rows, aisles, headland, start pose): cheap, no plants generated.
pub fn layout(s: &Scenario) -> Result<Layout> {
    Ok(Layout::from_config(&config(s)?))
}
