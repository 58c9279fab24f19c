//! The scenario's greenhouse, generated the same way every FMU generates it (from the
//! `[greenhouse]` TOML text and its seed), for the orchestrator's own uses: the static map,
//! benchmark targets, glTF export, reports.

use crate::scenario::Scenario;
use agrisim_error::Result;
use agrisim_scene::{generate, Greenhouse, GreenhouseConfig, Layout};

fn config(s: &Scenario) -> Result<GreenhouseConfig> {
    GreenhouseConfig::from_toml_str(&s.scene_toml())
        .map_err(|e| agrisim_error::err!("scenario {}: [greenhouse]: {e}", s.path.display()))
}

pub fn generate_scene(s: &Scenario) -> Result<Greenhouse> {
    let cfg = config(s)?;
    Ok(generate(&cfg, cfg.seed))
}

/// Seed offset of the crop a mapping run saw (the same greenhouse, a week earlier).
const MAPPING_RUN_SEED: u64 = 0x0005_EED0_F0CA_11ED;

/// The scenario's greenhouse with its crop grown from another plant seed: what a mapping
/// run through the same house saw before the trial (see `[nav] prior_map`).
pub fn mapping_run_scene(s: &Scenario) -> Result<Greenhouse> {
    let cfg = config(s)?;
    Ok(generate(&cfg, cfg.seed ^ MAPPING_RUN_SEED))
}

/// The layout alone (rows, aisles, headland, start pose): cheap, no plants generated.
pub fn layout(s: &Scenario) -> Result<Layout> {
    Ok(Layout::from_config(&config(s)?))
}
