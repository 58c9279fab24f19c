//! One nav trial and its judge: the system started afresh at the predefined initial state,
//! one seeded target (an aisle or the headland, so row switches are included), success when
//! the ground-truth base centre is within the goal tolerance as the navigator reports
//! success, with no collision, within the time limit; otherwise a failure with its reason
//! (collision, timeout, no_path, stuck, goal_missed, error). Ground truth is read only to
//! judge; the navigation stack never sees it.

use super::setup::NavSetup;
use super::targets::draw_target;
use crate::framework::report::decimate;
use crate::framework::Trial;
use crate::initial_pose::initial_estimate;
use crate::map::grid_message;
use agrisim_bus::Node;
use agrisim_error::Result;
use agrisim_math::Rng;
use agrisim_msgs::agrisim::NavigationStatus;
use agrisim_msgs::geometry_msgs::PoseStamped;
use agrisim_msgs::Message;
use agrisim_nodes::{FaultInjector, GoalPublisher, MapServer, OdomTf};
use agrisim_session::{prepare, RunOptions, Scenario};
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::time::Instant;

/// A trial's line of trials.jsonl.
#[derive(Debug, Clone, Serialize, Deserialize)]
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

/// A nav trial as kept in trials/NNNN.json: the result and its path (every 10th point).
#[derive(Serialize, Deserialize)]
pub struct NavRecord {
    pub trial: NavTrial,
    pub path: Vec<[f64; 2]>,
}

/// The trial's target: drawn from its seed, clear of everything the full map holds.
fn target(s: &Scenario, setup: &NavSetup, seed: u64) -> Option<[f64; 3]> {
    let nav = &s.nav;
    draw_target(&setup.layout, &setup.truth, &mut Rng::new(seed), nav.targets_in_headland, nav.aisle_margin, 0.7)
}

/// The record of a trial whose process died: an error, with its target (drawn as the trial
/// draws it) and the reason.
pub fn failed(t: &Trial<NavSetup>, reason: String) -> NavRecord {
    let trial = NavTrial {
        trial: t.index,
        scene: t.scene,
        seed: t.seed,
        target: target(t.scenario, t.setup, t.seed).unwrap_or([0.0; 3]),
        outcome: "failure".into(),
        reason: Some(format!("error: {reason}")),
        time_to_goal: None,
        path_length: 0.0,
        min_clearance: 0.0,
        final_localization_error: None,
        initial_pose_error: initial_estimate(t.setup.layout.start_pose, t.scenario.nav.initial_pose_std, t.seed).1,
        sim_time: 0.0,
        wall_time: 0.0,
        mcap: format!("trials/{:04}.mcap", t.index),
    };
    NavRecord { trial, path: vec![] }
}

/// Runs trial `t` into `mcap` and judges it.
pub fn run(t: &Trial<NavSetup>, mcap: &Path) -> Result<NavRecord> {
    let (s, setup, seed) = (t.scenario, t.setup, t.seed);
    let wall = Instant::now();
    let nav = &s.nav;
    let target = target(s, setup, seed).ok_or_else(|| {
        agrisim_error::err!("scenario {}: no free navigation target could be drawn", s.path.display())
    })?;
    // The localizer starts from an operator's estimate of the start pose, never the true one.
    let (estimate, initial_pose_error) = initial_estimate(setup.layout.start_pose, nav.initial_pose_std, seed);
    let config = agrisim_nav::NavConfig::for_estimate(estimate, nav.initial_pose_std);
    let navigator = agrisim_nav::Navigator::new(agrisim_nav::NavConfig { plugins: setup.plugins, ..config });
    let nodes: Vec<Box<dyn Node>> = vec![
        Box::new(MapServer::new(grid_message(&setup.map, 0))),
        Box::new(OdomTf::default()),
        Box::new(GoalPublisher::new(0, target)),
        Box::new(navigator),
        Box::new(FaultInjector::new(&s.inject)),
    ];
    let opts = RunOptions { seed: Some(seed), ..t.run.clone() };
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
        trial: t.index,
        scene: t.scene,
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
    Ok(NavRecord { trial, path: decimate(&path, 10) })
}
