//! `agrisim bench perception`: the perception node on camera frames from seeded robot poses
//! in the aisles, judged against the world's ground truth (fruit poses, the camera's label
//! image, ripeness from the scene): recall per ripeness stage and visibility class,
//! precision, 3-D centre error by distance, overlay pictures.

pub mod judge;
pub mod png;
pub mod report;
pub mod setup;
pub mod summary;
pub mod trial;

pub use setup::PerceptionSetup;
pub use summary::PerceptionSummary;
pub use trial::PerceptionRecord;

use crate::framework::{OptionSpec, OptionValue, OptionValues, Trial, TrialBenchmark, Whole};
use agrisim_error::{err, Result};
use agrisim_session::Scenario;
use std::path::Path;

/// The environments `--environment` chooses (0 keeps the scenario's).
pub const ENVIRONMENTS: [&str; 5] = ["scenario", "noon", "dusk", "overcast", "fog"];

const OPTIONS: [OptionSpec; 3] = [
    OptionSpec {
        name: "environment",
        help: "Light and weather: 0 the scenario's, 1 clear noon, 2 clear dusk, 3 overcast, 4 fog (15 m visibility)",
        default: OptionValue::U64(0),
    },
    OptionSpec {
        name: "frames",
        help: "Frames judged per trial (10 Hz, robot standing)",
        default: OptionValue::U64(2),
    },
    OptionSpec {
        name: "overlays",
        help: "Trials (the first N) that write an overlay picture trials/NNNN.png",
        default: OptionValue::U64(12),
    },
];

pub struct PerceptionBench;

impl TrialBenchmark for PerceptionBench {
    type Setup = PerceptionSetup;
    type Record = PerceptionRecord;
    type Summary = PerceptionSummary;

    fn name(&self) -> &'static str {
        "perception"
    }
    fn about(&self) -> &'static str {
        "Tomato perception from RGB-D frames at seeded poses: recall, precision, ripeness, 3-D centre error"
    }
    fn default_scenario(&self) -> &'static str {
        "sensors"
    }
    fn options(&self) -> &'static [OptionSpec] {
        &OPTIONS
    }
    fn check(&self, o: &OptionValues) -> Result<()> {
        if o.u64("environment") as usize >= ENVIRONMENTS.len() {
            return Err(err!("--environment {}: 0-4 ({})", o.u64("environment"), ENVIRONMENTS.join(", ")));
        }
        if !(1..=50).contains(&o.u64("frames")) {
            return Err(err!("--frames {}: 1-50", o.u64("frames")));
        }
        Ok(())
    }
    fn setup(&self, s: &Scenario, _: &OptionValues) -> Result<PerceptionSetup> {
        PerceptionSetup::new(s)
    }
    fn trial(&self, t: &Trial<PerceptionSetup>, mcap: &Path) -> Result<PerceptionRecord> {
        trial::run(t, mcap)
    }
    fn failed(&self, t: &Trial<PerceptionSetup>, reason: String) -> PerceptionRecord {
        trial::failed(t, reason)
    }
    fn line(&self, r: &PerceptionRecord) -> String {
        serde_json::to_string(&r.line()).expect("plain struct")
    }
    fn summarize(&self, w: &Whole<PerceptionSetup>, results: &[PerceptionRecord]) -> PerceptionSummary {
        summary::summarize(w, results)
    }
    fn report(
        &self,
        _: &Whole<PerceptionSetup>,
        s: &PerceptionSummary,
        results: &[PerceptionRecord],
    ) -> Result<String> {
        Ok(report::report_html(s, results))
    }
}
