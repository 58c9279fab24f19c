//! summary.json of the harvest benchmark: harvest, planning and conditional rates with their
//! intervals, per scene and per visibility class, failure taxonomy, planning times, touches.

use super::judge::PlantEffects;
use super::trial::HarvestTrial;
use crate::framework::scenes::{by_scene, SceneResult};
use crate::framework::stats::{percentile, wilson, Z95};
use crate::framework::TrialPlan;
use agrisim_session::Scenario;
use serde::Serialize;
use std::collections::BTreeMap;

#[derive(Debug, Clone, Serialize)]
pub struct HarvestSummary {
    pub scenario: String,
    /// Perception in the loop (`[harvest] sight`): the node found its fruit with the
    /// perception node and planned in the mapping node's sensed scene. Off: it was handed the
    /// world's target and planning scene (ground truth).
    pub perception_in_loop: bool,
    /// By sight: distance from the node's target estimate to the nearest fruit's true centre
    /// [mm], median and 95th percentile over the trials that chose a fruit.
    pub target_error_mm_p50: Option<f64>,
    pub target_error_mm_p95: Option<f64>,
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
    /// Distinct (scene, fruit) targets among the trials.
    pub distinct_targets: u64,
    /// Trials and successes by the target's visibility class.
    pub per_visibility: BTreeMap<String, ClassResult>,
    /// The trials whose task the hand could do at all (a ripe fruit of the task no wider than
    /// the hand opens: [`super::feasible`]) and their successes. The rest are beyond this
    /// gripper whatever the method; `success_rate` counts them, this does not.
    pub within_hand: ClassResult,
    pub planning_successes: u64,
    /// Trials whose planning verdict is "ok" or "failed" (the rate's denominator).
    pub planning_decided: u64,
    pub planning_success_rate: f64,
    pub planning_wilson95: [f64; 2],
    /// Harvest successes among the trials whose planning succeeded.
    pub conditional_success_rate: f64,
    pub conditional_wilson95: [f64; 2],
    pub failures: BTreeMap<String, u64>,
    /// Fruit declined for want of a pre-grasp (by sight: the node took another), and the
    /// trials that declined any: a first choice without a plan, beside the planning verdict.
    #[serde(default)]
    pub declined: u64,
    #[serde(default)]
    pub trials_declining: u64,
    pub plans: u64,
    pub planning_time_p50: Option<f64>,
    pub planning_time_p95: Option<f64>,
    pub planning_time_max: Option<f64>,
    /// Mean simulated planning time per trial [s] (the node's cost model).
    pub thinking_time_mean: f64,
    /// Mean simulated compute time per trial of the perception and mapping nodes [s] (their
    /// cost models; 0 without sight).
    pub perception_time_mean: f64,
    pub mapping_time_mean: f64,
    /// Simulated planning time over measured planning wall time, all timed plans: how well the
    /// node's cost model matches this machine (1 = exactly).
    pub thinking_over_wall: Option<f64>,
    pub tracking_rms_mean: f64,
    /// Mean per trial of the scene objects the robot began to touch, by kind.
    pub touches_per_trial: BTreeMap<String, f64>,
    /// Crop damage over all trials, by kind (bruised_by_grip, bruised_by_impact,
    /// unripe_detached, stems_broken).
    pub damage: BTreeMap<String, u64>,
    /// Trials whose last pedicel broke by each mode (pull, bend, twist).
    pub detach_modes: BTreeMap<String, u64>,
    /// Mean over trials with a break of the largest pedicel force at a break [N].
    pub detach_force_mean: Option<f64>,
    /// Mean per trial of the leaves pressed aside; the largest force spent holding one [N]
    /// and the largest main-stem load over its strength, over all trials.
    #[serde(default)]
    pub leaf_pushes_per_trial: f64,
    #[serde(default)]
    pub peak_leaf_force: f64,
    #[serde(default)]
    pub peak_stem_load: f64,
    pub time_to_harvest_mean: Option<f64>,
    pub rtf: f64,
    pub sim_time: f64,
    pub wall_time: f64,
}

/// One class of trials (e.g. a visibility class).
#[derive(Debug, Clone, Default, Serialize)]
pub struct ClassResult {
    pub trials: u64,
    pub successes: u64,
    pub wilson95: [f64; 2],
}

/// `hand[i]`: whether trial `i`'s task was within the hand ([`super::feasible::hand_can_do`]).
pub fn summarize(s: &Scenario, plan: TrialPlan, results: &[HarvestTrial], hand: &[bool]) -> HarvestSummary {
    let seed = plan.seed;
    let n = results.len() as u64;
    let outcomes: Vec<(u64, bool)> = results.iter().map(|t| (t.scene, t.outcome == "success")).collect();
    let (per_scene, cluster_bootstrap95) = by_scene(s, plan.scenes, seed, &outcomes);
    let distinct_targets =
        results.iter().map(|t| (t.scene, t.fruit_id)).collect::<std::collections::BTreeSet<_>>().len() as u64;
    let ok = results.iter().filter(|t| t.outcome == "success").count() as u64;
    let planned = results.iter().filter(|t| t.planning_ok).count() as u64;
    // Planning is judged only where it was decided: a trial that failed before asking for
    // every plan says nothing of the plans it never asked for.
    let decided = results.iter().filter(|t| t.planning != "not_reached").count() as u64;
    let ok_given_planned = results.iter().filter(|t| t.planning_ok && t.outcome == "success").count() as u64;
    let mut failures = BTreeMap::new();
    for t in results.iter().filter_map(|t| t.failure.as_ref()) {
        *failures.entry(t.clone()).or_insert(0) += 1;
    }
    let mut times: Vec<f64> = results.iter().flat_map(|t| t.planning_times.iter().copied()).collect();
    times.sort_by(f64::total_cmp);
    let sim: f64 = results.iter().map(|t| t.sim_time).sum();
    let wall: f64 = results.iter().map(|t| t.wall_time).sum();
    let tth: Vec<f64> = results.iter().filter_map(|t| t.time_to_harvest).collect();
    let rate = |a: u64, b: u64| if b == 0 { 0.0 } else { a as f64 / b as f64 };
    let mut target_errors: Vec<f64> = results.iter().filter_map(|t| t.target_error_mm).collect();
    target_errors.sort_by(f64::total_cmp);
    let plant = PlantEffects::total(results.iter().map(|t| &t.plant));
    HarvestSummary {
        scenario: s.name.clone(),
        perception_in_loop: s.harvest.sight,
        target_error_mm_p50: percentile(&target_errors, 0.5),
        target_error_mm_p95: percentile(&target_errors, 0.95),
        seed,
        trials: n,
        successes: ok,
        success_rate: rate(ok, n),
        wilson95: wilson(ok, n, Z95),
        scenes: plan.scenes.max(1),
        per_scene,
        cluster_bootstrap95,
        distinct_targets,
        per_visibility: {
            let mut m: BTreeMap<String, ClassResult> = BTreeMap::new();
            for t in results {
                let c = m.entry(t.visibility.clone()).or_default();
                c.trials += 1;
                c.successes += (t.outcome == "success") as u64;
            }
            for c in m.values_mut() {
                c.wilson95 = wilson(c.successes, c.trials, Z95);
            }
            m
        },
        within_hand: {
            let within = results.iter().zip(hand).filter(|(_, h)| **h);
            let (trials, successes) =
                within.fold((0, 0), |(n, k), (t, _)| (n + 1, k + (t.outcome == "success") as u64));
            ClassResult { trials, successes, wilson95: wilson(successes, trials, Z95) }
        },
        planning_successes: planned,
        planning_decided: decided,
        planning_success_rate: rate(planned, decided),
        planning_wilson95: wilson(planned, decided, Z95),
        conditional_success_rate: rate(ok_given_planned, planned),
        conditional_wilson95: wilson(ok_given_planned, planned, Z95),
        failures,
        declined: results.iter().map(|t| t.declined as u64).sum(),
        trials_declining: results.iter().filter(|t| t.declined > 0).count() as u64,
        plans: times.len() as u64,
        planning_time_p50: percentile(&times, 0.5),
        planning_time_p95: percentile(&times, 0.95),
        planning_time_max: times.last().copied(),
        thinking_time_mean: results.iter().map(|t| t.thinking_time).sum::<f64>() / n.max(1) as f64,
        perception_time_mean: results.iter().map(|t| t.perception_time).sum::<f64>() / n.max(1) as f64,
        mapping_time_mean: results.iter().map(|t| t.mapping_time).sum::<f64>() / n.max(1) as f64,
        thinking_over_wall: {
            let timed: Vec<&HarvestTrial> = results.iter().filter(|t| !t.planning_times.is_empty()).collect();
            let wall: f64 = timed.iter().flat_map(|t| t.planning_times.iter()).sum();
            (wall > 0.0).then(|| timed.iter().map(|t| t.thinking_time).sum::<f64>() / wall)
        },
        touches_per_trial: {
            let mut m: BTreeMap<String, f64> = BTreeMap::new();
            for (k, v) in results.iter().flat_map(|t| t.touches.iter()) {
                *m.entry(k.clone()).or_insert(0.0) += *v as f64 / n.max(1) as f64;
            }
            m
        },
        damage: {
            let mut m: BTreeMap<String, u64> = BTreeMap::new();
            for (k, v) in results.iter().flat_map(|t| t.damage.iter()) {
                *m.entry(k.clone()).or_insert(0) += v;
            }
            m
        },
        detach_modes: {
            let mut m: BTreeMap<String, u64> = BTreeMap::new();
            for mode in results.iter().filter_map(|t| t.detach_mode.as_ref()) {
                *m.entry(mode.clone()).or_insert(0) += 1;
            }
            m
        },
        detach_force_mean: {
            let f: Vec<f64> = results.iter().filter_map(|t| t.detach_force).collect();
            (!f.is_empty()).then(|| f.iter().sum::<f64>() / f.len() as f64)
        },
        leaf_pushes_per_trial: plant.leaf_pushes as f64 / n.max(1) as f64,
        peak_leaf_force: plant.peak_leaf_force,
        peak_stem_load: plant.peak_stem_load,
        tracking_rms_mean: if n == 0 {
            0.0
        } else {
            results.iter().map(|t| 0.5 * (t.tracking_rms[0] + t.tracking_rms[1])).sum::<f64>() / n as f64
        },
        time_to_harvest_mean: if tth.is_empty() { None } else { Some(tth.iter().sum::<f64>() / tth.len() as f64) },
        rtf: if wall > 0.0 { sim / wall } else { 0.0 },
        sim_time: sim,
        wall_time: wall,
    }
}
