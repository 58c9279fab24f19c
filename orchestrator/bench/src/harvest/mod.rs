//! `agrisim bench harvest`: the paper's dual-arm harvesting experiment, many trials, every
//! one recorded (see [`trial`] for what a trial is and how it is judged). By default by
//! sight (`models/scenarios/harvest_sight.toml`); `harvest.toml` hands the node the
//! ground-truth target and collision scene, to isolate manipulation.

pub mod feasible;
pub mod judge;
pub mod report;
pub mod session;
pub mod setup;
pub mod summary;
pub mod targets;
pub mod trial;

pub use setup::HarvestSetup;
pub use summary::{summarize, ClassResult, HarvestSummary};
pub use trial::{builtin_node, run_with, HarvestNodeFactory, HarvestTrial, TRIAL_TIMEOUT};

use crate::framework::{OptionValues, Trial, TrialBenchmark, Whole};
use agrisim_error::Result;
use agrisim_session::Scenario;
use std::path::Path;

/// The dual-arm harvest benchmark.
pub struct Harvest;

impl TrialBenchmark for Harvest {
    type Setup = HarvestSetup;
    type Record = HarvestTrial;
    type Summary = HarvestSummary;

    fn name(&self) -> &'static str {
        "harvest"
    }
    fn about(&self) -> &'static str {
        "The dual-arm harvesting experiment: N trials on seeded ripe fruit"
    }
    /// By sight: perception and a sensed collision scene in the loop. Ground truth
    /// (`harvest.toml`) isolates manipulation.
    fn default_scenario(&self) -> &'static str {
        "harvest_sight"
    }
    fn setup(&self, s: &Scenario, _: &OptionValues) -> Result<HarvestSetup> {
        HarvestSetup::new(s)
    }
    fn trial(&self, t: &Trial<HarvestSetup>, mcap: &Path) -> Result<HarvestTrial> {
        trial::run(t, mcap)
    }
    fn failed(&self, t: &Trial<HarvestSetup>, reason: String) -> HarvestTrial {
        trial::failed(t, reason)
    }
    /// trials.jsonl without the path (it is in trials/NNNN.json).
    fn line(&self, t: &HarvestTrial) -> String {
        serde_json::to_string(&HarvestTrial { path: vec![], ..t.clone() }).expect("plain struct")
    }
    fn summarize(&self, w: &Whole<HarvestSetup>, results: &[HarvestTrial]) -> HarvestSummary {
        // The tasks within the hand, from each trial's scene (ground truth, judge side).
        let hand: Vec<bool> = results.iter().map(|t| feasible::hand_can_do(&w.scenes.of(t.trial).2.fruit, t)).collect();
        summarize(w.scenario, w.plan, results, &hand)
    }
    /// On the map of scene 0 (grown again: the set-up keeps no objects).
    fn report(&self, w: &Whole<HarvestSetup>, summary: &HarvestSummary, results: &[HarvestTrial]) -> Result<String> {
        let g = agrisim_session::scene::generate_scene(w.scenario)?;
        Ok(report::report_html(&g, summary, results))
    }
}
