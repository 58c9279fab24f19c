//! `agrisim bench nav`: the paper's navigation experiment, many trials, every one recorded
//! (see [`trial`] for what a trial is and how it is judged).

pub mod report;
pub mod setup;
pub mod summary;
pub mod targets;
pub mod trial;

pub use setup::NavSetup;
pub use summary::{summarize, NavSummary};
pub use targets::draw_target;
pub use trial::{NavRecord, NavTrial};

use crate::framework::{Trial, TrialBenchmark, Whole};
use agrisim_error::Result;
use agrisim_session::Scenario;
use std::path::Path;

/// The navigation benchmark.
pub struct Nav;

impl TrialBenchmark for Nav {
    type Setup = NavSetup;
    type Record = NavRecord;
    type Summary = NavSummary;

    fn name(&self) -> &'static str {
        "nav"
    }
    fn about(&self) -> &'static str {
        "The navigation experiment: N trials to seeded targets in the aisles and the headland"
    }
    fn default_scenario(&self) -> &'static str {
        "default"
    }
    fn setup(&self, s: &Scenario, _: &crate::framework::OptionValues) -> Result<NavSetup> {
        NavSetup::new(s)
    }
    fn trial(&self, t: &Trial<NavSetup>, mcap: &Path) -> Result<NavRecord> {
        trial::run(t, mcap)
    }
    fn failed(&self, t: &Trial<NavSetup>, reason: String) -> NavRecord {
        trial::failed(t, reason)
    }
    /// trials.jsonl without the path (it is in trials/NNNN.json).
    fn line(&self, r: &NavRecord) -> String {
        serde_json::to_string(&r.trial).expect("plain struct")
    }
    fn summarize(&self, w: &Whole<NavSetup>, results: &[NavRecord]) -> NavSummary {
        let trials: Vec<NavTrial> = results.iter().map(|r| r.trial.clone()).collect();
        summarize(w.scenario, w.plan, &trials)
    }
    fn report(&self, w: &Whole<NavSetup>, summary: &NavSummary, results: &[NavRecord]) -> Result<String> {
        Ok(report::report_html(w.scenes.first(), summary, results))
    }
}
