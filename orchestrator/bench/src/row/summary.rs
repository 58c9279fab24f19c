//! summary.json of the row benchmark: fraction harvested (by visibility class, with the
//! cluster bootstrap over segments), fruit per hour, cycle times, touches, dropped fruit.

use super::trial::RowTrial;
use crate::framework::stats::{cluster_bootstrap95, percentile, wilson, Z95};
use crate::framework::TrialPlan;
use crate::harvest::judge::PlantEffects;
use agrisim_session::Scenario;
use serde::Serialize;
use std::collections::BTreeMap;

#[derive(Debug, Clone, Serialize)]
pub struct RowSummary {
    pub scenario: String,
    pub seed: u64,
    pub segments: u64,
    pub segment_length: f64,
    pub targets: u64,
    pub harvested: u64,
    pub harvested_fraction: f64,
    /// Counts every fruit as independent (they are not: fruit of one segment share its run).
    pub wilson95: [f64; 2],
    /// Resamples whole segments: the interval to quote.
    pub cluster_bootstrap95: [f64; 2],
    pub per_class: BTreeMap<String, ClassFraction>,
    pub failures: BTreeMap<String, u64>,
    pub segments_ended: BTreeMap<String, u64>,
    pub fruit_per_hour: f64,
    pub cycle_time_mean: Option<f64>,
    pub cycle_time_p50: Option<f64>,
    pub cycle_time_p95: Option<f64>,
    pub touches_per_fruit: BTreeMap<String, f64>,
    pub dropped: i64,
    /// By sight (`[harvest] sight`): the node found the fruit itself in stretches of the
    /// segment; otherwise it was handed the reachable ripe fruit (ground truth).
    pub perception_in_loop: bool,
    /// By sight: the picks the node tried, and the failed ones by class
    /// ([`super::trial::RowAttempt::failure_class`]: a grasp aimed over 15 mm from any fruit
    /// is mislocalized).
    pub attempts: u64,
    pub attempt_failures: BTreeMap<String, u64>,
    /// Fruit taken off their plants, of them unripe (damage), and their share.
    pub detached: u64,
    pub unripe_detached: u64,
    pub unripe_share: f64,
    /// Unripe fruit in the box, and ripe ones outside the reachable targets.
    pub unripe_placed: u64,
    pub other_ripe_placed: u64,
    pub thinking_time_per_fruit: f64,
    /// Perception and mapping compute charged per reachable ripe fruit [s] (0 without sight).
    pub perception_time_per_fruit: f64,
    pub mapping_time_per_fruit: f64,
    /// Crop damage over all segments, by kind; leaves pressed aside per fruit; the largest
    /// force spent holding a leaf [N] and the largest main-stem load over its strength.
    pub damage: BTreeMap<String, u64>,
    pub leaf_pushes_per_fruit: f64,
    pub peak_leaf_force: f64,
    pub peak_stem_load: f64,
    pub rtf: f64,
    pub sim_time: f64,
    pub wall_time: f64,
}

#[derive(Debug, Clone, Default, Serialize)]
pub struct ClassFraction {
    pub targets: u64,
    pub harvested: u64,
    pub wilson95: [f64; 2],
}

pub fn summarize(s: &Scenario, plan: TrialPlan, length: f64, results: &[RowTrial]) -> RowSummary {
    let targets: u64 = results.iter().map(|t| t.targets).sum();
    let harvested: u64 = results.iter().map(|t| t.harvested).sum();
    let mut per_class: BTreeMap<String, ClassFraction> = BTreeMap::new();
    let mut failures: BTreeMap<String, u64> = BTreeMap::new();
    let mut ended: BTreeMap<String, u64> = BTreeMap::new();
    let mut touches: BTreeMap<String, f64> = BTreeMap::new();
    for t in results {
        for (k, [n, h]) in &t.per_class {
            let c = per_class.entry(k.clone()).or_default();
            c.targets += n;
            c.harvested += h;
        }
        for (k, v) in &t.failures {
            *failures.entry(k.clone()).or_insert(0) += v;
        }
        *ended.entry(t.ended.split(':').next().unwrap_or("").to_string()).or_insert(0) += 1;
        for (k, v) in &t.touches {
            *touches.entry(k.clone()).or_insert(0.0) += *v as f64 / targets.max(1) as f64;
        }
    }
    for c in per_class.values_mut() {
        c.wilson95 = wilson(c.harvested, c.targets, Z95);
    }
    let mut cycles: Vec<f64> = results.iter().flat_map(|t| t.cycle_times.iter().copied()).collect();
    cycles.sort_by(f64::total_cmp);
    let sim: f64 = results.iter().map(|t| t.sim_time).sum();
    let wall: f64 = results.iter().map(|t| t.wall_time).sum();
    let detached: u64 = results.iter().map(|t| t.detached).sum();
    let unripe_detached: u64 = results.iter().map(|t| t.unripe_detached).sum();
    let clusters: Vec<(u64, u64)> =
        results.iter().filter(|t| t.targets > 0).map(|t| (t.harvested, t.targets)).collect();
    let plant = PlantEffects::total(results.iter().map(|t| &t.plant));
    let mut attempt_failures: BTreeMap<String, u64> = BTreeMap::new();
    for f in results.iter().flat_map(|t| &t.attempts).filter_map(|a| a.failure_class()) {
        *attempt_failures.entry(f).or_insert(0) += 1;
    }
    RowSummary {
        scenario: s.name.clone(),
        seed: plan.seed,
        segments: results.len() as u64,
        segment_length: length,
        targets,
        harvested,
        harvested_fraction: if targets == 0 { 0.0 } else { harvested as f64 / targets as f64 },
        wilson95: wilson(harvested, targets, Z95),
        cluster_bootstrap95: cluster_bootstrap95(&clusters, 4000, plan.seed ^ 0x0520_0B00),
        per_class,
        failures,
        segments_ended: ended,
        fruit_per_hour: if sim > 0.0 { harvested as f64 * 3600.0 / sim } else { 0.0 },
        cycle_time_mean: (!cycles.is_empty()).then(|| cycles.iter().sum::<f64>() / cycles.len() as f64),
        cycle_time_p50: percentile(&cycles, 0.5),
        cycle_time_p95: percentile(&cycles, 0.95),
        touches_per_fruit: touches,
        dropped: results.iter().map(|t| t.dropped).sum(),
        perception_in_loop: s.harvest.sight,
        attempts: results.iter().map(|t| t.attempts.len() as u64).sum(),
        attempt_failures,
        detached,
        unripe_detached,
        unripe_share: if detached == 0 { 0.0 } else { unripe_detached as f64 / detached as f64 },
        unripe_placed: results.iter().map(|t| t.unripe_placed).sum(),
        other_ripe_placed: results.iter().map(|t| t.other_ripe_placed).sum(),
        thinking_time_per_fruit: results.iter().map(|t| t.thinking_time).sum::<f64>() / targets.max(1) as f64,
        perception_time_per_fruit: results.iter().map(|t| t.perception_time).sum::<f64>() / targets.max(1) as f64,
        mapping_time_per_fruit: results.iter().map(|t| t.mapping_time).sum::<f64>() / targets.max(1) as f64,
        damage: {
            let mut m: BTreeMap<String, u64> = BTreeMap::new();
            for (k, v) in results.iter().flat_map(|t| t.damage.iter()) {
                *m.entry(k.clone()).or_insert(0) += v;
            }
            m
        },
        leaf_pushes_per_fruit: plant.leaf_pushes as f64 / targets.max(1) as f64,
        peak_leaf_force: plant.peak_leaf_force,
        peak_stem_load: plant.peak_stem_load,
        rtf: if wall > 0.0 { sim / wall } else { 0.0 },
        sim_time: sim,
        wall_time: wall,
    }
}
