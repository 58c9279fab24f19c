//! `agrisim bench harvest`: the paper's dual-arm harvesting experiment, many trials, every
//! one recorded.
//!
//! Each trial starts the harvest system afresh with the robot in an aisle short of a seeded
//! ripe target fruit (see [`super::harvest_targets`]); the harvest node positions the base
//! and the lift, plans and executes grasp, handover and placement. Success is judged on
//! ground truth from the world FMU: the target fruit was placed in the box, no collision
//! (robot against structure, arm against arm, base against anything), within the time
//! limit. Planning success means every motion the trial asked for was planned.

use super::harvest_targets::{draw, eligible, HarvestTarget, Visibility};
use super::map::{grid_message, prior_map};
use super::nav::{decimate, trial_seed};
use super::report::{
    self, bar_chart, count_table, interval, opt, per_kind, rate_table, render_with, view_bounds, TrialTrace,
};
use super::stats::{percentile, wilson, Z95};
use crate::initial_pose::initial_estimate;
use crate::scenes::{by_scene, SceneResult, Scenes};
use crate::trials::{run_one, run_trials, write_summary, Exec, TrialPlan};
use agrisim_bus::{Node, Reader};
use agrisim_error::{err, Result};
use agrisim_greenhouse::occupancy::OccupancyMap;
use agrisim_harvest::{topics, HarvestNode};
use agrisim_math::Rng;
use agrisim_msgs::agrisim::{CollisionState, HarvestStatus, PlanResult};
use agrisim_nav::{Localizer, NavConfig};
use agrisim_nodes::{FaultInjector, MapServer, OdomTf, RobotStatePublisher};
use agrisim_session::{prepare, RunOptions, Scenario};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

/// Simulated-time limit of one harvest [s].
pub const TRIAL_TIMEOUT: f64 = 120.0;

#[derive(Debug, Clone, Serialize, serde::Deserialize)]
pub struct HarvestTrial {
    pub trial: u64,
    /// Scene index (`--scenes`): the greenhouse grown from the scenario's seed + scene.
    #[serde(default)]
    pub scene: u64,
    pub seed: u64,
    pub fruit_index: usize,
    pub fruit_id: u32,
    pub fruit_name: String,
    pub fruit: [f64; 3],
    /// What lies between the fruit and its aisle: free, partly_occluded, behind_stem.
    #[serde(default)]
    pub visibility: String,
    pub start: [f64; 3],
    pub outcome: String,
    /// Failure category: planning, grasp, handover, placement, timeout, collision, error.
    pub failure: Option<String>,
    pub failed_stage: Option<String>,
    pub detail: String,
    /// The planning verdict: "ok" (the harvest got to placing the fruit, so every plan it
    /// needed was made),
    /// "failed" (a plan without a fallback failed) or "not_reached" (no plan failed, but the
    /// trial ended for another reason before every plan was asked for: unknown).
    pub planning: String,
    /// `planning == "ok"`.
    pub planning_ok: bool,
    pub plans: usize,
    /// Wall time of each plan [s]: the harvest node's step that asked for it (IK + RRT-Connect
    /// + shortcut + time parameterization), shared among the plans of that step.
    pub planning_times: Vec<f64>,
    /// Simulated planning time the node charged, summed over its plans (`planning_time` of
    /// /harvest/plans) [s]: part of the time to harvest.
    #[serde(default)]
    pub thinking_time: f64,
    pub time_to_harvest: Option<f64>,
    pub placed_count: i64,
    pub contacts: BTreeMap<String, i64>,
    /// Scene objects the robot began to touch, by kind (stem, leaf, truss, fruit: fruit other
    /// than the target; post, gutter...), from every /collision message: what a grower would
    /// call damage risk. Counted, not failures (only base and structure contacts fail).
    #[serde(default)]
    pub touches: BTreeMap<String, u64>,
    /// RMS joint tracking error of the last trajectory of each arm [rad].
    pub tracking_rms: [f64; 2],
    pub sim_time: f64,
    pub wall_time: f64,
    pub mcap: String,
    /// Ground-truth base path (chassis x, y: every 10th exchange and the last); in
    /// trials/NNNN.json, not in trials.jsonl.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub path: Vec<[f64; 2]>,
}

#[derive(Debug, Clone, Serialize)]
pub struct HarvestSummary {
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
    /// Distinct (scene, fruit) targets among the trials.
    pub distinct_targets: u64,
    /// Trials and successes by the target's visibility class.
    pub per_visibility: BTreeMap<String, ClassResult>,
    pub planning_successes: u64,
    /// Trials whose planning verdict is "ok" or "failed" (the rate's denominator).
    pub planning_decided: u64,
    pub planning_success_rate: f64,
    pub planning_wilson95: [f64; 2],
    /// Harvest successes among the trials whose planning succeeded.
    pub conditional_success_rate: f64,
    pub conditional_wilson95: [f64; 2],
    pub failures: BTreeMap<String, u64>,
    pub plans: u64,
    pub planning_time_p50: Option<f64>,
    pub planning_time_p95: Option<f64>,
    pub planning_time_max: Option<f64>,
    /// Mean simulated planning time per trial [s] (the node's cost model).
    pub thinking_time_mean: f64,
    /// Simulated planning time over measured planning wall time, all timed plans: how well the
    /// node's cost model matches this machine (1 = exactly).
    pub thinking_over_wall: Option<f64>,
    pub tracking_rms_mean: f64,
    /// Mean per trial of the scene objects the robot began to touch, by kind.
    pub touches_per_trial: BTreeMap<String, f64>,
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

/// Onsets of contact with scene objects, by kind, from /collision messages.
#[derive(Default)]
pub(crate) struct Touches {
    /// Objects in contact in the last message.
    now: std::collections::BTreeSet<u32>,
    pub(crate) by_kind: BTreeMap<String, u64>,
}

impl Touches {
    /// Counts every object in `cs` not touched in the previous message, except the task's
    /// own fruit (`picked`).
    pub(crate) fn update(&mut self, cs: &CollisionState, picked: impl Fn(u32) -> bool) {
        let mut next = std::collections::BTreeSet::new();
        for c in &cs.contacts {
            // Arm-arm and carried-fruit contacts are failures, judged from the world's counters.
            if picked(c.object_id)
                || c.object_kind == "robot_arm"
                || c.robot_link == "carried_fruit"
                || !next.insert(c.object_id)
            {
                continue;
            }
            if !self.now.contains(&c.object_id) {
                *self.by_kind.entry(c.object_kind.clone()).or_insert(0) += 1;
            }
        }
        self.now = next;
    }
}

/// The failure a base contact in `cs` is, if any: the base must touch nothing.
pub(crate) fn base_contact(cs: &CollisionState) -> Option<String> {
    cs.contacts
        .iter()
        .find(|c| c.robot_link == "base_link")
        .map(|c| format!("the base touched {} ({})", c.object_name, c.object_kind))
}

/// Contact counters of the world FMU that end a trial as a collision (judged after every
/// exchange from counters the world updates every step): the robot or a fruit it carries
/// against the structure, arm against arm.
pub const COLLISION_COUNTERS: [&str; 3] = ["contact_robot_structure", "contact_arm_arm", "contact_carried_structure"];
/// Counted but expected: leaves and trusses brush the arm.
pub const SOFT_COUNTERS: [&str; 1] = ["contact_robot_plant"];

/// Everything a trial needs that does not change between trials.
pub struct HarvestSetup {
    pub layout: agrisim_greenhouse::Layout,
    pub map: OccupancyMap,
    pub candidates: Vec<HarvestTarget>,
}

impl HarvestSetup {
    pub fn new(s: &Scenario) -> Result<HarvestSetup> {
        let g = agrisim_session::scene::generate_scene(s)?;
        let map = prior_map(s, &g)?;
        let classes = &s.harvest.visibility;
        for c in classes {
            if ![Visibility::Free, Visibility::PartlyOccluded, Visibility::BehindStem].iter().any(|v| v.name() == c) {
                return Err(err!(
                    "scenario {}: [harvest] visibility: unknown class \"{c}\" (free, partly_occluded, behind_stem)",
                    s.path.display()
                ));
            }
        }
        let mut candidates = eligible(&g.objects, &g.layout);
        candidates.retain(|t| classes.iter().any(|c| c == t.visibility.name()));
        if candidates.is_empty() {
            return Err(err!("scenario {}: no ripe fruit of the visibility classes {classes:?} faces an aisle at a harvestable height", s.path.display()));
        }
        Ok(HarvestSetup { layout: g.layout, map, candidates })
    }
}

/// The harvest node under test: `fruit_index` is the task (the target the paper hands over),
/// `seed` the trial's seed. Any node that speaks the harvest topics can take its place.
pub type HarvestNodeFactory<'a> = &'a dyn Fn(usize, u64) -> Box<dyn Node>;

/// The built-in harvest node.
pub fn builtin_node(fruit_index: usize, seed: u64) -> Box<dyn Node> {
    Box::new(HarvestNode::new(fruit_index, seed))
}

/// The judge's view of the harvest node: only what it published.
struct Reports {
    plans_reader: Reader,
    status_reader: Reader,
    plans: Vec<PlanResult>,
    /// Wall time of each plan [s]: the node's step that asked for it, shared among the plans
    /// of that step.
    planning_times: Vec<f64>,
    /// The final status (outcome success or failure), once published.
    outcome: Option<HarvestStatus>,
}

impl Reports {
    fn subscribe(bus: &mut agrisim_bus::Bus) -> Reports {
        Reports {
            plans_reader: Reader::subscribe(bus, topics::PLANS),
            status_reader: Reader::subscribe(bus, topics::STATUS),
            plans: vec![],
            planning_times: vec![],
            outcome: None,
        }
    }

    /// Takes everything the node published since the last look.
    fn read(&mut self, m: &mut agrisim_session::Session, node: &str) -> Result<()> {
        let plans: Vec<PlanResult> = self.plans_reader.take(&mut m.bus)?;
        if !plans.is_empty() {
            // An external node (over ROS 2) is not timed here: no planning times for it.
            if let Some(wall) = m.node_wall(node) {
                self.planning_times.extend(std::iter::repeat_n(wall / plans.len() as f64, plans.len()));
            }
            self.plans.extend(plans);
        }
        for st in self.status_reader.take::<HarvestStatus>(&mut m.bus)? {
            if self.outcome.is_none() && (st.outcome == "success" || st.outcome == "failure") {
                self.outcome = Some(st);
            }
        }
        Ok(())
    }
}

/// Runs one trial into `mcap` with the built-in harvest node.
pub fn run_trial(
    s: &Scenario,
    o: &RunOptions,
    setup: &HarvestSetup,
    index: u64,
    seed: u64,
    mcap: &Path,
) -> Result<HarvestTrial> {
    run_trial_with(s, o, setup, index, seed, mcap, &builtin_node, TRIAL_TIMEOUT)
}

/// Runs one trial into `mcap` with the harvest node `node` makes, within `timeout` [s] of
/// simulated time. The judge reads the node's messages (/harvest/status, /harvest/plans),
/// the bus and the world FMU's ground truth; nothing else of the node.
#[allow(clippy::too_many_arguments)]
pub fn run_trial_with(
    s: &Scenario,
    o: &RunOptions,
    setup: &HarvestSetup,
    index: u64,
    seed: u64,
    mcap: &Path,
    node: HarvestNodeFactory,
    timeout: f64,
) -> Result<HarvestTrial> {
    let wall = Instant::now();
    let mut rng = Rng::new(seed);
    let target = draw(&setup.candidates, &setup.layout, &mut rng).expect("candidates checked non-empty");
    let harvest = node(target.fruit_index, seed);
    let node_name = harvest.name().to_string();
    // An external node takes the harvest node's place: it is told the task the same way.
    let task =
        o.nodes.external.contains(&node_name).then(|| crate::task_publisher::TaskPublisher::new(target.fruit_index));
    let mut m = harvest_session(s, o, setup, target.start, seed, mcap, harvest, task)?;
    let (world, arm_l, arm_r) = (
        m.component("world", "harvest benchmark")?,
        m.component("arm_left", "harvest benchmark")?,
        m.component("arm_right", "harvest benchmark")?,
    );
    let chassis = m.component("chassis", "harvest benchmark")?;
    let max_ticks = (timeout / s.timing.step).round() as u64;
    let mut path = vec![[m.number(chassis, "x")?, m.number(chassis, "y")?]];
    let mut reports = Reports::subscribe(&mut m.bus);
    let mut collisions = Reader::subscribe(&mut m.bus, "/collision");
    let mut judged: Option<(Option<String>, String)> = None;
    let mut time_to_harvest = None;
    let mut touches = Touches::default();
    let result: Result<()> = (|| {
        for k in 1..=max_ticks {
            m.advance()?;
            path.push([m.number(chassis, "x")?, m.number(chassis, "y")?]);
            reports.read(&mut m, &node_name)?;
            // The base must touch nothing; the arms may brush plants (counted, not failures).
            // Every collision state counts, however short the contact.
            for cs in collisions.take::<CollisionState>(&mut m.bus)? {
                touches.update(&cs, |id| id == target.object_id);
                if let Some(why) = base_contact(&cs) {
                    judged = Some((Some("collision".into()), why));
                    return Ok(());
                }
            }
            for c in COLLISION_COUNTERS {
                if m.number(world, c)? > 0.0 {
                    judged = Some((Some("collision".into()), c.to_string()));
                    return Ok(());
                }
            }
            if let Some(st) = &reports.outcome {
                let success = st.outcome == "success";
                if success {
                    time_to_harvest = Some(k as f64 * s.timing.step);
                }
                judged = Some((
                    (!success).then(|| st.failure_category.clone()),
                    if success { String::new() } else { st.detail.clone() },
                ));
                return Ok(());
            }
        }
        judged = Some((Some("timeout".into()), format!("no outcome within {timeout} s")));
        Ok(())
    })();
    let sim_time = m.time();
    let failed_stage = reports.outcome.as_ref().filter(|o| o.outcome != "success").map(|o| o.stage.clone());
    let mut contacts = BTreeMap::new();
    let mut placed = 0;
    let mut tracking = [0.0; 2];
    let mut probe = || -> Result<()> {
        for c in COLLISION_COUNTERS.iter().chain(SOFT_COUNTERS.iter()) {
            contacts.insert(c.to_string(), m.number(world, c)? as i64);
        }
        placed = m.number(world, "placed_count")? as i64;
        let placed_id = m.number(world, "last_placed_id")? as i64;
        if placed > 0 && placed_id != target.object_id as i64 {
            placed = 0;
        }
        tracking = [m.number(arm_l, "tracking_error_rms")?, m.number(arm_r, "tracking_error_rms")?];
        Ok(())
    };
    let probed = probe();
    let (mut failure, mut detail) = match (result, probed) {
        (Ok(()), Ok(())) => {
            m.finish_point()?;
            judged.expect("set on every exit")
        }
        (Err(e), _) | (Ok(()), Err(e)) => {
            m.record_failure(&e);
            (Some("error".to_string()), e.to_string())
        }
    };
    m.recorder_finish()?;
    // Ground truth has the last word: the node believing in success is not enough.
    if failure.is_none() && placed == 0 {
        failure = Some("placement".into());
        detail = "the node reported success but the world has not placed the target fruit".into();
    }
    let planning = if failure.as_deref() == Some("planning") || reports.plans.iter().any(|p| !p.ok && !p.optional) {
        "failed"
    } else if failure.is_none() || failure.as_deref() == Some("placement") {
        // Placement is judged after the node's last motion: every plan was made.
        "ok"
    } else {
        "not_reached"
    };
    Ok(HarvestTrial {
        outcome: if failure.is_none() { "success" } else { "failure" }.to_string(),
        failed_stage: failure.as_ref().and(failed_stage),
        failure,
        detail,
        planning: planning.into(),
        planning_ok: planning == "ok",
        plans: reports.plans.len(),
        planning_times: reports.planning_times,
        thinking_time: reports.plans.iter().map(|p| p.planning_time).sum(),
        time_to_harvest,
        placed_count: placed,
        contacts,
        touches: touches.by_kind,
        tracking_rms: tracking,
        sim_time,
        wall_time: wall.elapsed().as_secs_f64(),
        mcap: mcap.file_name().map(|f| format!("trials/{}", f.to_string_lossy())).unwrap_or_default(),
        path: decimate(&path, 10),
        ..HarvestTrial::of_target(index, seed, &target)
    })
}

/// A harvest system ready to run from `start` (x, y, yaw of base_link): the map server,
/// odometry TF, the localizer started from a seeded estimate of the start pose (never the
/// true one), the robot state publisher, `harvest` (the node under test), the fault
/// injector, and `task` (what tells an external node its task), recording into `mcap`.
#[allow(clippy::too_many_arguments)]
pub fn harvest_session(
    s: &Scenario,
    o: &RunOptions,
    setup: &HarvestSetup,
    start: [f64; 3],
    seed: u64,
    mcap: &Path,
    harvest: Box<dyn Node>,
    task: Option<crate::task_publisher::TaskPublisher>,
) -> Result<agrisim_session::Session> {
    let mut s = s.clone();
    let chassis = s.parameters.entry("chassis".into()).or_default();
    for (k, v) in ["x0", "y0", "yaw0"].iter().zip(start) {
        chassis.insert(k.to_string(), toml::Value::Float(v));
    }
    let (estimate, _) = initial_estimate(start, s.nav.initial_pose_std, seed);
    let mut nav_cfg = NavConfig::for_estimate(estimate, s.nav.initial_pose_std);
    nav_cfg.embedded_localizer = false;
    let mut nodes: Vec<Box<dyn Node>> = vec![
        Box::new(MapServer::new(grid_message(&setup.map, 0))),
        Box::new(OdomTf::default()),
        Box::new(Localizer::new(&nav_cfg)),
        Box::new(RobotStatePublisher::agrisim()),
        harvest,
        Box::new(FaultInjector::new(&s.inject)),
    ];
    if let Some(t) = task {
        nodes.push(Box::new(t));
    }
    prepare(&s, &RunOptions { seed: Some(seed), ..o.clone() }, mcap, nodes)
}

/// Runs `trials` trials and writes trials.jsonl, summary.json, report.html and trials/*.mcap.
pub fn bench_harvest(
    s: &Scenario,
    o: &RunOptions,
    plan: TrialPlan,
    out: &Path,
    resume: bool,
    exec: Exec,
    progress: impl FnMut(u64, u64),
) -> Result<HarvestSummary> {
    let o = o.record_default(s, agrisim_session::Profile::Standard);
    let seed = plan.seed;
    let scenes = Scenes::all(s, plan.scenes, HarvestSetup::new)?;
    let done = run_trials(
        out,
        plan.trials,
        resume,
        exec,
        progress,
        |i, mcap| {
            let (k, s, setup) = scenes.of(i);
            run_trial(s, &o, setup, i, trial_seed(seed, i), mcap).map(|t| HarvestTrial { scene: k, ..t })
        },
        |i, reason| {
            let (k, _, setup) = scenes.of(i);
            HarvestTrial { scene: k, ..failed_trial(setup, i, trial_seed(seed, i), reason) }
        },
        // trials.jsonl without the path (it is in trials/NNNN.json).
        |t| serde_json::to_string(&HarvestTrial { path: vec![], ..t.clone() }).expect("plain struct"),
    )?;
    let summary = summarize(s, plan, &done.results);
    write_summary(out, &summary, done.interrupted)?;
    write_report(s, &summary, &done.results, out)?;
    Ok(summary)
}

/// A worker process's job: harvest trial `i` of the benchmark `bench_harvest` runs.
pub fn harvest_worker(s: &Scenario, o: &RunOptions, plan: TrialPlan, out: &Path, i: u64) -> Result<()> {
    let o = o.record_default(s, agrisim_session::Profile::Standard);
    let scenes = Scenes::for_trial(s, plan.scenes, i, HarvestSetup::new)?;
    let (k, s, setup) = scenes.of(i);
    run_one(out, i, |i, mcap| {
        run_trial(s, &o, setup, i, trial_seed(plan.seed, i), mcap).map(|t| HarvestTrial { scene: k, ..t })
    })
}

/// The record of a trial whose process died: an error, with its target (drawn as the trial
/// draws it) and the reason.
fn failed_trial(setup: &HarvestSetup, index: u64, seed: u64, reason: String) -> HarvestTrial {
    let target = draw(&setup.candidates, &setup.layout, &mut Rng::new(seed)).expect("candidates checked non-empty");
    HarvestTrial { failure: Some("error".into()), detail: reason, ..HarvestTrial::of_target(index, seed, &target) }
}

impl HarvestTrial {
    /// Trial `index` on `target`, a failure until said otherwise, nothing measured yet.
    fn of_target(index: u64, seed: u64, target: &HarvestTarget) -> HarvestTrial {
        HarvestTrial {
            trial: index,
            scene: 0,
            seed,
            fruit_index: target.fruit_index,
            fruit_id: target.object_id,
            fruit_name: target.name.clone(),
            fruit: target.center,
            visibility: target.visibility.name().into(),
            start: target.start,
            outcome: "failure".into(),
            failure: None,
            failed_stage: None,
            detail: String::new(),
            planning: "not_reached".into(),
            planning_ok: false,
            plans: 0,
            planning_times: vec![],
            thinking_time: 0.0,
            time_to_harvest: None,
            placed_count: 0,
            contacts: BTreeMap::new(),
            touches: BTreeMap::new(),
            tracking_rms: [0.0; 2],
            sim_time: 0.0,
            wall_time: 0.0,
            mcap: format!("trials/{index:04}.mcap"),
            path: vec![],
        }
    }
}

pub fn summarize(s: &Scenario, plan: TrialPlan, results: &[HarvestTrial]) -> HarvestSummary {
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
    HarvestSummary {
        scenario: s.name.clone(),
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
        planning_successes: planned,
        planning_decided: decided,
        planning_success_rate: rate(planned, decided),
        planning_wilson95: wilson(planned, decided, Z95),
        conditional_success_rate: rate(ok_given_planned, planned),
        conditional_wilson95: wilson(ok_given_planned, planned, Z95),
        failures,
        plans: times.len() as u64,
        planning_time_p50: percentile(&times, 0.5),
        planning_time_p95: percentile(&times, 0.95),
        planning_time_max: times.last().copied(),
        thinking_time_mean: results.iter().map(|t| t.thinking_time).sum::<f64>() / n.max(1) as f64,
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

/// report.html: the rates (harvest, planning, conditional) with their intervals, results per
/// scene and per visibility class, the failure taxonomy, a histogram of the time to harvest,
/// and the map of scene 0 with every trial's ground-truth base path and target fruit (green
/// harvested, red not). Only figures the seed determines: the same seed gives the same page
/// (the wall-clock figures are in summary.json).
fn write_report(s: &Scenario, sum: &HarvestSummary, results: &[HarvestTrial], out: &Path) -> Result<()> {
    let g = agrisim_session::scene::generate_scene(s)?;
    report::write(out, &report_html(&g, sum, results))
}

/// The page [`write_report`] writes, on the map of `g`.
fn report_html(g: &agrisim_greenhouse::Greenhouse, sum: &HarvestSummary, results: &[HarvestTrial]) -> String {
    let rows = vec![
        ("scenario".to_string(), sum.scenario.clone()),
        ("seed".to_string(), sum.seed.to_string()),
        (
            "trials x scenes".to_string(),
            format!("{} in {} scene(s), {} distinct targets", sum.trials, sum.scenes, sum.distinct_targets),
        ),
        ("harvested".to_string(), format!("{} / {} = {:.3}", sum.successes, sum.trials, sum.success_rate)),
        ("harvest Wilson 95 %".to_string(), interval(sum.wilson95)),
        ("harvest cluster bootstrap 95 % (over scenes)".to_string(), interval(sum.cluster_bootstrap95)),
        (
            "planning (of decided trials)".to_string(),
            format!("{} / {} = {:.3}", sum.planning_successes, sum.planning_decided, sum.planning_success_rate),
        ),
        ("planning Wilson 95 %".to_string(), interval(sum.planning_wilson95)),
        (
            "harvested given planning".to_string(),
            format!("{:.3}, Wilson 95 % {}", sum.conditional_success_rate, interval(sum.conditional_wilson95)),
        ),
        ("mean time to harvest [s]".to_string(), opt(sum.time_to_harvest_mean)),
        (
            "plans; planning time charged per trial [s]".to_string(),
            format!("{}; {:.3}", sum.plans, sum.thinking_time_mean),
        ),
        ("plant touches per trial".to_string(), per_kind(&sum.touches_per_trial)),
        ("joint tracking RMS mean [rad]".to_string(), format!("{:.2e}", sum.tracking_rms_mean)),
        (
            "wall-clock figures".to_string(),
            "in summary.json (rtf, planning_time_p50/p95/max, thinking_over_wall)".to_string(),
        ),
    ];
    let classes = sum.per_visibility.iter().map(|(k, c)| (k.clone(), c.trials, c.successes, c.wilson95));
    let times: Vec<f64> = results.iter().filter_map(|t| t.time_to_harvest).collect();
    let mut sections = vec![];
    if sum.scenes > 1 {
        let scenes = sum.per_scene.iter().map(|r| {
            (
                format!("{} (greenhouse seed {})", r.scene, r.scene_seed),
                r.trials,
                r.successes,
                wilson(r.successes, r.trials, Z95),
            )
        });
        let note = "<p>The map above is scene 0's; the trials of the other scenes are drawn on it.</p>";
        sections.push(("Harvested per scene".to_string(), rate_table(["scene", "trials", "harvested"], scenes) + note));
    }
    sections.extend([
        ("Harvested by visibility class".to_string(), rate_table(["class", "trials", "harvested"], classes)),
        ("Failure taxonomy (trials not harvested)".to_string(), count_table(["category", "trials"], &sum.failures)),
        ("Time to harvest (successful trials, simulated)".to_string(), bar_chart(&times, 5.0, "time to harvest [s]")),
    ]);
    let traces: Vec<TrialTrace> = results
        .iter()
        .map(|t| TrialTrace {
            index: t.trial,
            success: t.outcome == "success",
            reason: match &t.failure {
                None => format!("harvested in {} s", opt(t.time_to_harvest)),
                Some(f) => {
                    format!("{f} (stage {}, {}): {}", t.failed_stage.as_deref().unwrap_or("-"), t.visibility, t.detail)
                }
            },
            target: t.fruit,
            path: t.path.clone(),
        })
        .collect();
    render_with(
        &format!("agrisim harvest benchmark: {}", sum.scenario),
        &rows,
        &g.objects,
        view_bounds(&g.layout, &traces),
        &traces,
        &sections,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use agrisim_msgs::agrisim::Contact;

    fn state(contacts: &[(u32, &str, &str)]) -> CollisionState {
        CollisionState {
            contacts: contacts
                .iter()
                .map(|&(id, kind, link)| Contact {
                    object_id: id,
                    object_kind: kind.into(),
                    robot_link: link.into(),
                    ..Contact::default()
                })
                .collect(),
            ..CollisionState::default()
        }
    }

    /// An object counts once per onset, however many links touch it and however long; the
    /// target fruit, arm-arm and carried-fruit contacts (failures, not touches) do not
    /// count; letting go and touching again does.
    #[test]
    fn touches_count_onsets_by_kind() {
        let mut t = Touches::default();
        t.update(&state(&[(5, "leaf", "left_link5"), (5, "leaf", "left_link6"), (9, "fruit", "left_hand")]), |id| {
            id == 9
        });
        t.update(
            &state(&[
                (5, "leaf", "left_link5"),
                (7, "stem", "left_link4"),
                (0, "robot_arm", "left_link7"),
                (13, "post", "carried_fruit"),
            ]),
            |id| id == 9,
        );
        t.update(&state(&[]), |id| id == 9);
        t.update(&state(&[(5, "leaf", "left_link5"), (11, "fruit", "right_hand")]), |id| id == 9);
        assert_eq!(
            t.by_kind,
            BTreeMap::from([("leaf".to_string(), 2), ("stem".to_string(), 1), ("fruit".to_string(), 1)])
        );
    }

    /// report.html holds only what the seed determines: trials that differ in their
    /// wall-clock figures alone give the same page. One path per trial, a row per visibility
    /// class and per failure category, the time to harvest in the histogram.
    #[test]
    fn report_is_the_same_whatever_the_wall_clock() {
        let s =
            Scenario::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models/scenarios/harvest.toml")).unwrap();
        let g = agrisim_session::scene::generate_scene(&s).unwrap();
        let targets = eligible(&g.objects, &g.layout);
        let trials = |wall: f64| -> Vec<HarvestTrial> {
            let picked = targets.iter().step_by(97).take(3).enumerate();
            picked
                .map(|(i, t)| {
                    let mut r = HarvestTrial {
                        sim_time: 30.0,
                        wall_time: wall * (i + 1) as f64,
                        plans: 2,
                        planning_times: vec![wall * 1e-3; 2],
                        ..HarvestTrial::of_target(i as u64, 1, t)
                    };
                    r.path = vec![[t.start[0], t.start[1]], [t.start[0] + 0.5, t.start[1]]];
                    let (failure, stage, planning) = [
                        (None, None, "ok"),
                        (Some("grasp"), Some("grasp"), "not_reached"),
                        (Some("planning"), Some("pre_grasp"), "failed"),
                    ][i];
                    (r.failure, r.failed_stage, r.planning, r.planning_ok) =
                        (failure.map(String::from), stage.map(String::from), planning.into(), planning == "ok");
                    if failure.is_none() {
                        (r.outcome, r.time_to_harvest) = ("success".into(), Some(27.3));
                    }
                    r
                })
                .collect()
        };
        let plan = TrialPlan { trials: 3, seed: 1, scenes: 1 };
        let (a, b) = (trials(5.0), trials(9.0));
        let (sa, sb) = (summarize(&s, plan, &a), summarize(&s, plan, &b));
        assert_ne!(sa.rtf, sb.rtf);
        let html = report_html(&g, &sa, &a);
        assert_eq!(html, report_html(&g, &sb, &b));
        assert!(!html.contains("real-time"));
        assert_eq!(html.matches("<polyline").count(), 3);
        assert!(
            html.contains("<tr><td>grasp</td><td>1</td></tr>") && html.contains("<tr><td>planning</td><td>1</td></tr>")
        );
        assert!(html.contains("<th>planning (of decided trials)</th><td>1 / 2 = 0.500</td>"));
        for (k, c) in &sa.per_visibility {
            assert!(html.contains(&format!("<tr><td>{k}</td><td>{}</td><td>{}</td>", c.trials, c.successes)), "{k}");
        }
        assert!(html.contains("<title>25-30: 1</title>"), "the one time to harvest in the histogram");
    }
}
