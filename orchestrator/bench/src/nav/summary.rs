//! summary.json of the nav benchmark: the success rate with its intervals (Wilson's, and the
//! cluster bootstrap over scenes), per-scene results, failure taxonomy, means.

use super::trial::NavTrial;
use crate::framework::scenes::{by_scene, SceneResult};
use crate::framework::stats::{wilson, Z95};
use crate::framework::TrialPlan;
use agrisim_session::Scenario;
use serde::Serialize;
use std::collections::BTreeMap;

#[derive(Debug, Clone, Serialize)]
pub struct NavSummary {
    pub scenario: String,
    pub seed: u64,
    pub trials: u64,
    pub successes: u64,
    pub success_rate: f64,
    /// Counts every trial as independent (right for one scene's trials only).
    pub wilson95: [f64; 2],
    pub scenes: u64,
    pub per_scene: Vec<SceneResult>,
    /// Resamples whole scenes: the interval to quote when trials share scenes.
    pub cluster_bootstrap95: [f64; 2],
    pub failures: BTreeMap<String, u64>,
    /// Simulated time / wall time over all trials.
    pub rtf: f64,
    pub sim_time: f64,
    pub wall_time: f64,
    pub time_to_goal_mean: Option<f64>,
    pub path_length_mean: f64,
    pub min_clearance_min: f64,
}

pub fn summarize(s: &Scenario, plan: TrialPlan, results: &[NavTrial]) -> NavSummary {
    let seed = plan.seed;
    let n = results.len() as u64;
    let outcomes: Vec<(u64, bool)> = results.iter().map(|t| (t.scene, t.outcome == "success")).collect();
    let (per_scene, cluster_bootstrap95) = by_scene(s, plan.scenes, seed, &outcomes);
    let ok: Vec<&NavTrial> = results.iter().filter(|t| t.outcome == "success").collect();
    let mut failures = BTreeMap::new();
    for t in results.iter().filter(|t| t.outcome != "success") {
        let reason = t.reason.clone().unwrap_or_default();
        let key = reason.split(':').next().unwrap_or("").to_string();
        *failures.entry(key).or_insert(0) += 1;
    }
    let sim: f64 = results.iter().map(|t| t.sim_time).sum();
    let wall: f64 = results.iter().map(|t| t.wall_time).sum();
    let ttg: Vec<f64> = ok.iter().filter_map(|t| t.time_to_goal).collect();
    NavSummary {
        scenario: s.name.clone(),
        seed,
        trials: n,
        successes: ok.len() as u64,
        success_rate: if n == 0 { 0.0 } else { ok.len() as f64 / n as f64 },
        wilson95: wilson(ok.len() as u64, n, Z95),
        scenes: plan.scenes.max(1),
        per_scene,
        cluster_bootstrap95,
        failures,
        rtf: if wall > 0.0 { sim / wall } else { 0.0 },
        sim_time: sim,
        wall_time: wall,
        time_to_goal_mean: if ttg.is_empty() { None } else { Some(ttg.iter().sum::<f64>() / ttg.len() as f64) },
        path_length_mean: if n == 0 { 0.0 } else { results.iter().map(|t| t.path_length).sum::<f64>() / n as f64 },
        // Over the trials that drove (a trial whose process died has no clearance).
        min_clearance_min: results
            .iter()
            .filter(|t| t.sim_time > 0.0)
            .map(|t| t.min_clearance)
            .fold(f64::INFINITY, f64::min),
    }
}
