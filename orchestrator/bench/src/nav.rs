//! `agrisim bench nav`: the paper's navigation experiment, many trials, every one recorded.
//!
//! Each trial starts the system afresh at the predefined initial state, sends one seeded
//! target (an aisle or the headland, so row switches are included), and ends in success
//! (ground-truth base centre within the goal tolerance, no collision, within the time limit)
//! or in failure with a reason: collision, timeout, no_path, stuck, goal_missed, error.
//! Ground truth is read here only to judge; the navigation stack never sees it.

use super::report::{self, bar_chart, count_table, interval, opt, rate_table, render_with, view_bounds, TrialTrace};
use super::stats::{wilson, Z95};
use super::targets::draw_target;
use crate::initial_pose::initial_estimate;
use crate::map::{grid_message, prior_map, MAP_BAND, MAP_RESOLUTION};
use crate::scenes::{by_scene, SceneResult, Scenes};
use crate::trials::{run_one, run_trials, write_summary, Exec, TrialPlan};
use agrisim_bus::Node;
use agrisim_error::Result;
use agrisim_greenhouse::occupancy::OccupancyMap;
use agrisim_math::Rng;
use agrisim_msgs::agrisim::NavigationStatus;
use agrisim_msgs::geometry_msgs::PoseStamped;
use agrisim_msgs::Message;
use agrisim_nodes::{FaultInjector, GoalPublisher, MapServer, OdomTf};
use agrisim_session::{prepare, RunOptions, Scenario};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

#[derive(Debug, Clone, Serialize, serde::Deserialize)]
pub struct NavTrial {
    pub trial: u64,
    /// Scene index (`--scenes`): the greenhouse grown from the scenario's seed + scene.
    #[serde(default)]
    pub scene: u64,
    pub seed: u64,
    pub target: [f64; 3],
    pub outcome: String,
    pub reason: Option<String>,
    pub time_to_goal: Option<f64>,
    pub path_length: f64,
    pub min_clearance: f64,
    pub final_localization_error: Option<f64>,
    /// Error of the localizer's initial estimate (x, y, yaw) [m, m, rad], seeded.
    pub initial_pose_error: [f64; 3],
    pub sim_time: f64,
    pub wall_time: f64,
    pub mcap: String,
}

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

/// The seed of trial `i`: independent streams per trial from one master seed.
pub fn trial_seed(master: u64, i: u64) -> u64 {
    let mut r = Rng::new(master ^ i.wrapping_mul(0x9E37_79B9_7F4A_7C15));
    r.next_u64()
}

/// Everything a trial needs that does not change between trials.
pub struct NavSetup {
    pub layout: agrisim_greenhouse::Layout,
    pub objects: Vec<agrisim_greenhouse::Object>,
    /// The static map the robot is given: the building plan, without obstacles (those it
    /// must find with its LiDAR and plan around).
    pub map: OccupancyMap,
    /// Everything, obstacles included: only to keep targets out of obstacles.
    pub truth: OccupancyMap,
}

impl NavSetup {
    pub fn new(s: &Scenario) -> Result<NavSetup> {
        let g = agrisim_session::scene::generate_scene(s)?;
        let map = prior_map(s, &g)?;
        let truth = OccupancyMap::from_objects(&g.objects, MAP_RESOLUTION, MAP_BAND, g.layout.bounds);
        Ok(NavSetup { layout: g.layout, objects: g.objects, map, truth })
    }
}

/// A worker process's job: nav trial `i` of the benchmark `bench_nav` runs.
pub fn nav_worker(s: &Scenario, o: &RunOptions, plan: TrialPlan, out: &Path, i: u64) -> Result<()> {
    let o = o.record_default(s, agrisim_session::Profile::Standard);
    let scenes = Scenes::for_trial(s, plan.scenes, i, NavSetup::new)?;
    let (k, s, setup) = scenes.of(i);
    run_one(out, i, |i, mcap| nav_record(s, &o, setup, plan.seed, k, i, mcap))
}

/// The record of a trial whose process died: an error, with its target (drawn as the trial
/// draws it) and the reason.
fn failed_trial(s: &Scenario, setup: &NavSetup, index: u64, seed: u64, reason: String) -> NavRecord {
    let nav = &s.nav;
    let target =
        draw_target(&setup.layout, &setup.truth, &mut Rng::new(seed), nav.targets_in_headland, nav.aisle_margin, 0.7)
            .unwrap_or([0.0; 3]);
    let trial = NavTrial {
        trial: index,
        scene: 0,
        seed,
        target,
        outcome: "failure".into(),
        reason: Some(format!("error: {reason}")),
        time_to_goal: None,
        path_length: 0.0,
        min_clearance: 0.0,
        final_localization_error: None,
        initial_pose_error: initial_estimate(setup.layout.start_pose, nav.initial_pose_std, seed).1,
        sim_time: 0.0,
        wall_time: 0.0,
        mcap: format!("trials/{index:04}.mcap"),
    };
    NavRecord { trial, path: vec![] }
}

/// Runs one trial into `mcap`.
pub fn run_trial(
    s: &Scenario,
    o: &RunOptions,
    setup: &NavSetup,
    index: u64,
    seed: u64,
    mcap: &Path,
) -> Result<(NavTrial, Vec<[f64; 2]>)> {
    let wall = Instant::now();
    let mut rng = Rng::new(seed);
    let nav = &s.nav;
    let target = draw_target(&setup.layout, &setup.truth, &mut rng, nav.targets_in_headland, nav.aisle_margin, 0.7)
        .ok_or_else(|| {
            agrisim_error::err!("scenario {}: no free navigation target could be drawn", s.path.display())
        })?;
    // The localizer starts from an operator's estimate of the start pose, never the true one.
    let (estimate, initial_pose_error) = initial_estimate(setup.layout.start_pose, nav.initial_pose_std, seed);
    let navigator = agrisim_nav::Navigator::new(agrisim_nav::NavConfig::for_estimate(estimate, nav.initial_pose_std));
    let nodes: Vec<Box<dyn Node>> = vec![
        Box::new(MapServer::new(grid_message(&setup.map, 0))),
        Box::new(OdomTf::default()),
        Box::new(GoalPublisher::new(0, target)),
        Box::new(navigator),
        Box::new(FaultInjector::new(&s.inject)),
    ];
    let opts = RunOptions { seed: Some(seed), ..o.clone() };
    let mut m = prepare(s, &opts, mcap, nodes)?;
    let chassis = m.component("chassis", "nav benchmark")?;
    let world = m.component("world", "nav benchmark")?;
    let step = s.timing.step;
    let max_ticks = (nav.trial_timeout / step).round() as u64;
    let mut path = vec![[m.number(chassis, "x")?, m.number(chassis, "y")?]];
    let (mut length, mut clearance) = (0.0, f64::INFINITY);
    // Every status message (a node may publish more than one per exchange).
    let mut statuses = agrisim_bus::Reader::subscribe(&mut m.bus, "/navigate/status");
    let mut outcome: Option<(bool, Option<String>)> = None;
    let mut time_to_goal = None;
    let result: Result<()> = (|| {
        for k in 1..=max_ticks {
            m.advance()?;
            let (x, y) = (m.number(chassis, "x")?, m.number(chassis, "y")?);
            let last = *path.last().expect("non-empty");
            length += (x - last[0]).hypot(y - last[1]);
            path.push([x, y]);
            clearance = clearance.min(m.number(world, "min_clearance")?);
            if m.number(world, "collision")? != 0.0 {
                outcome = Some((false, Some("collision".into())));
                return Ok(());
            }
            for st in statuses.take::<NavigationStatus>(&mut m.bus)? {
                match st.state.as_str() {
                    "succeeded" => {
                        let d = (x - target[0]).hypot(y - target[1]);
                        outcome = Some(if d <= nav.goal_tolerance {
                            (true, None)
                        } else {
                            (false, Some("goal_missed".into()))
                        });
                        time_to_goal = Some(k as f64 * step);
                        return Ok(());
                    }
                    "failed" => {
                        outcome =
                            Some((false, Some(if st.detail.is_empty() { "failed".into() } else { st.detail.clone() })));
                        return Ok(());
                    }
                    _ => {}
                }
            }
        }
        outcome = Some((false, Some("timeout".into())));
        Ok(())
    })();
    let sim_time = m.time();
    let loc_err = match m.bus.latest("/localization/pose") {
        Some(sample) => PoseStamped::from_cdr(&sample.cdr).ok().map(|p| {
            let [x, y] = *path.last().expect("non-empty");
            (p.pose.position.x - x).hypot(p.pose.position.y - y)
        }),
        None => None,
    };
    let (success, reason) = match result {
        Ok(()) => {
            m.finish_point()?;
            outcome.expect("set on every exit")
        }
        Err(e) => {
            m.record_failure(&e);
            (false, Some(format!("error: {e}")))
        }
    };
    m.recorder_finish()?;
    let trial = NavTrial {
        trial: index,
        scene: 0,
        seed,
        target,
        outcome: if success { "success" } else { "failure" }.to_string(),
        reason,
        time_to_goal: if success { time_to_goal } else { None },
        path_length: length,
        min_clearance: clearance,
        final_localization_error: loc_err,
        initial_pose_error,
        sim_time,
        wall_time: wall.elapsed().as_secs_f64(),
        mcap: mcap.file_name().map(|f| format!("trials/{}", f.to_string_lossy())).unwrap_or_default(),
    };
    Ok((trial, path))
}

/// Runs `trials` trials and writes trials.jsonl, summary.json, report.html and trials/*.mcap.
/// A nav trial as kept in trials/NNNN.json: the result and its path (every 10th point).
#[derive(Serialize, serde::Deserialize)]
struct NavRecord {
    trial: NavTrial,
    path: Vec<[f64; 2]>,
}

fn nav_record(
    s: &Scenario,
    o: &RunOptions,
    setup: &NavSetup,
    seed: u64,
    scene: u64,
    i: u64,
    mcap: &Path,
) -> Result<NavRecord> {
    let (trial, path) = run_trial(s, o, setup, i, trial_seed(seed, i), mcap)?;
    Ok(NavRecord { trial: NavTrial { scene, ..trial }, path: decimate(&path, 10) })
}

pub fn bench_nav(
    s: &Scenario,
    o: &RunOptions,
    plan: TrialPlan,
    out: &Path,
    resume: bool,
    exec: Exec,
    progress: impl FnMut(u64, u64),
) -> Result<NavSummary> {
    let o = o.record_default(s, agrisim_session::Profile::Standard);
    let seed = plan.seed;
    let scenes = Scenes::all(s, plan.scenes, NavSetup::new)?;
    let done = run_trials(
        out,
        plan.trials,
        resume,
        exec,
        progress,
        |i, mcap| {
            let (k, s, setup) = scenes.of(i);
            nav_record(s, &o, setup, seed, k, i, mcap)
        },
        |i, reason| {
            let (k, s, setup) = scenes.of(i);
            NavRecord {
                trial: NavTrial { scene: k, ..failed_trial(s, setup, i, trial_seed(seed, i), reason).trial },
                path: vec![],
            }
        },
        |r| serde_json::to_string(&r.trial).expect("plain struct"),
    )?;
    let setup = scenes.first();
    let traces: Vec<TrialTrace> = done
        .results
        .iter()
        .map(|r| TrialTrace {
            index: r.trial.trial,
            success: r.trial.outcome == "success",
            reason: r.trial.reason.clone().unwrap_or_else(|| "success".into()),
            target: r.trial.target,
            path: r.path.clone(),
        })
        .collect();
    let results: Vec<NavTrial> = done.results.into_iter().map(|r| r.trial).collect();
    let summary = summarize(s, plan, &results);
    write_summary(out, &summary, done.interrupted)?;
    let html = report_html(&setup.objects, &setup.layout, &summary, &results, &traces);
    report::write(out, &html)?;
    Ok(summary)
}

/// The report page: figures the seed determines only (the wall-clock ones are in
/// summary.json), so the same seed gives the same page.
fn report_html(
    objects: &[agrisim_greenhouse::Object],
    layout: &agrisim_greenhouse::Layout,
    sum: &NavSummary,
    results: &[NavTrial],
    traces: &[TrialTrace],
) -> String {
    let rows = vec![
        ("scenario".to_string(), sum.scenario.clone()),
        ("seed".to_string(), sum.seed.to_string()),
        ("trials x scenes".to_string(), format!("{} in {} scene(s)", sum.trials, sum.scenes)),
        ("reached".to_string(), format!("{} / {} = {:.3}", sum.successes, sum.trials, sum.success_rate)),
        ("Wilson 95 %".to_string(), interval(sum.wilson95)),
        ("cluster bootstrap 95 % (over scenes)".to_string(), interval(sum.cluster_bootstrap95)),
        ("mean time to goal [s]".to_string(), opt(sum.time_to_goal_mean)),
        ("mean path length [m]".to_string(), format!("{:.2}", sum.path_length_mean)),
        ("min clearance [m]".to_string(), format!("{:.3}", sum.min_clearance_min)),
        ("wall-clock figures".to_string(), "in summary.json (rtf, wall_time)".to_string()),
    ];
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
        sections.push(("Reached per scene".to_string(), rate_table(["scene", "trials", "reached"], scenes) + note));
    }
    let times: Vec<f64> = results.iter().filter_map(|t| t.time_to_goal).collect();
    sections.extend([
        ("Failure taxonomy (trials not reached)".to_string(), count_table(["reason", "trials"], &sum.failures)),
        ("Time to goal (successful trials, simulated)".to_string(), bar_chart(&times, 5.0, "time to goal [s]")),
    ]);
    render_with(
        &format!("agrisim nav benchmark: {}", sum.scenario),
        &rows,
        objects,
        view_bounds(layout, traces),
        traces,
        &sections,
    )
}

/// Every `every`-th point of `path`, and its last.
pub(crate) fn decimate(path: &[[f64; 2]], every: usize) -> Vec<[f64; 2]> {
    let mut v: Vec<[f64; 2]> = path.iter().step_by(every).copied().collect();
    if let Some(last) = path.last() {
        v.push(*last);
    }
    v
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
