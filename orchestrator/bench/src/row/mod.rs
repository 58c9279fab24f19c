//! `agrisim bench row`: the whole-row harvest. Each trial is an aisle segment (both sides):
//! the robot starts at its beginning and harvests every ripe fruit it can reach there
//! ([`crate::harvest::targets::eligible`]: every visibility class), in order along the aisle,
//! moving the base between picks and returning each fruit to the box. Figures: fraction
//! harvested (by visibility class), fruit per hour, cycle time per fruit, plant touches per
//! fruit, dropped fruit (see [`trial`] for the judge).

pub mod report;
pub mod segment;
pub mod summary;
pub mod trial;

pub use segment::{draw_segment, Segment};
pub use summary::{summarize, ClassFraction, RowSummary};
pub use trial::{RowFruit, RowTrial, LENGTH};

use crate::framework::{OptionSpec, OptionValue, OptionValues, Trial, TrialBenchmark, Whole};
use crate::harvest::HarvestSetup;
use agrisim_error::{err, Result};
use agrisim_session::Scenario;
use std::path::Path;

/// The whole-row harvest benchmark.
pub struct Row;

const OPTIONS: [OptionSpec; 1] =
    [OptionSpec { name: LENGTH, help: "Segment length along the aisle [m]", default: OptionValue::F64(2.0) }];

impl TrialBenchmark for Row {
    type Setup = HarvestSetup;
    type Record = RowTrial;
    type Summary = RowSummary;

    fn name(&self) -> &'static str {
        "row"
    }
    fn about(&self) -> &'static str {
        "The whole-row harvest: N aisle segments (--trials), every reachable ripe fruit in them harvested in turn"
    }
    /// By sight, as the harvest; `harvest.toml` hands the node the segment's fruit.
    fn default_scenario(&self) -> &'static str {
        "harvest_sight"
    }
    fn options(&self) -> &'static [OptionSpec] {
        &OPTIONS
    }
    fn check(&self, options: &OptionValues) -> Result<()> {
        let length = options.f64(LENGTH);
        if length.is_finite() && length > 0.0 && length <= 200.0 {
            Ok(())
        } else {
            Err(err!("--length {length}: the segment length must be in (0, 200] m"))
        }
    }
    fn setup(&self, s: &Scenario, _: &OptionValues) -> Result<HarvestSetup> {
        HarvestSetup::new(s)
    }
    fn trial(&self, t: &Trial<HarvestSetup>, mcap: &Path) -> Result<RowTrial> {
        trial::run(t, mcap)
    }
    fn failed(&self, t: &Trial<HarvestSetup>, reason: String) -> RowTrial {
        trial::failed(t, reason)
    }
    /// trials.jsonl without the path (it is in trials/NNNN.json).
    fn line(&self, t: &RowTrial) -> String {
        serde_json::to_string(&RowTrial { path: vec![], ..t.clone() }).expect("plain struct")
    }
    fn summarize(&self, w: &Whole<HarvestSetup>, results: &[RowTrial]) -> RowSummary {
        summarize(w.scenario, w.plan, w.options.f64(LENGTH), results)
    }
    /// On the map of scene 0 (grown again: the set-up keeps no objects).
    fn report(&self, w: &Whole<HarvestSetup>, summary: &RowSummary, results: &[RowTrial]) -> Result<String> {
        let g = agrisim_session::scene::generate_scene(w.scenario)?;
        Ok(report::report_html(&g, summary, results))
    }
}
