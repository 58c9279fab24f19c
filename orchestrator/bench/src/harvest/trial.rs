//! One harvest trial and its judge: the harvest system started afresh with the robot in an
//! aisle short of a seeded ripe target fruit (see [`super::targets`]); the harvest node
//! positions the base and the lift, plans and executes grasp, handover and placement.
//! Success is judged on ground truth from the world FMU: the target fruit was placed in the
//! box, no collision (robot against structure, arm against arm, base against anything),
//! within the time limit. Planning success means every motion the trial asked for was
//! planned.

use super::judge::{base_contact, Aims, DamageLog, PlantEffects, Reports, Touches, COLLISION_COUNTERS, SOFT_COUNTERS};
use super::session::harvest_session;
use super::setup::HarvestSetup;
use super::targets::{draw, HarvestTarget, HEIGHT_RANGE, RIPE_STAGE};
use crate::framework::report::decimate;
use crate::framework::Trial;
use agrisim_bus::{Node, Reader};
use agrisim_error::Result;
use agrisim_harvest::sight::Region;
use agrisim_harvest::{HarvestNode, Task};
use agrisim_math::Rng;
use agrisim_msgs::agrisim::CollisionState;
use agrisim_nodes::TaskPublisher;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

/// Whether a fruit bruised by its impact fails the trial (as grip bruises and broken stems
/// do): yes. The harvest node lowers the fruit into the box and lets go of it 3 cm above the
/// floor or the fruit already there (agrisim_harvest::geometry::PLACE_GAP), a fall of at most
/// about 5 cm, 1 m/s, well under the world's 2.0 m/s bruise speed; where it finds no way down
/// into the box it drops the fruit from over the rim, and such a drop may bruise it. (Dropped
/// from 0.13 m above the rim, 2.6 m/s, every fruit was impact-bruised.)
pub const IMPACT_BRUISE_FAILS: bool = true;

/// Simulated-time limit of one harvest [s].
pub const TRIAL_TIMEOUT: f64 = 120.0;
/// Length along the row of a harvest-by-sight task's region [m] ("a ripe fruit on your
/// left, within this 1 m of row").
pub const REGION_LENGTH: f64 = 1.0;
/// A grasp that failed on a target estimate farther than this from the fruit's true centre
/// failed on the estimate: mislocalized [m] (a picking attempt fails beyond about 15 mm).
pub const MISLOCALIZED: f64 = 0.015;

#[derive(Debug, Clone, Serialize, Deserialize)]
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
    /// Harvest by sight: the node was given `region` (x, y, z ranges in the map frame, around
    /// the drawn fruit above) and chose its fruit itself.
    #[serde(default)]
    pub sight: bool,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub region: Option<[[f64; 2]; 3]>,
    /// By sight: the fruit nearest the target the node last asked the mapper to allow
    /// (/harvest/allowed), its id and how far that estimate was from its true centre [mm].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub chosen_id: Option<u32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target_error_mm: Option<f64>,
    /// By sight: the radius the node gave its target, and that fruit's true radius [mm].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target_radius_mm: Option<[f64; 2]>,
    /// By sight: the true USDA stage of `chosen_id` (a stage below ripe is a wrong ripeness
    /// call by perception, not a grasp that took a neighbour).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub chosen_stage: Option<u8>,
    /// The fruit the world last placed in the box (its id and true stage), whichever it was.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub placed: Option<(u32, u8)>,
    /// What lies between the fruit and its aisle: free, partly_occluded, behind_stem.
    #[serde(default)]
    pub visibility: String,
    pub start: [f64; 3],
    pub outcome: String,
    /// Failure category: planning, grasp, handover, placement, timeout, collision, error; by
    /// sight also not_detected, too_wide (the region's ripe fruit all seen wider than the hand
    /// opens) and mislocalized; damage (a bruise or a broken stem).
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
    /// Fruit the node declined: pre-grasp plans that failed with another fruit of the region
    /// to take instead (by sight; optional plans of kind `pregrasp` on /harvest/plans).
    #[serde(default)]
    pub declined: usize,
    /// Wall time of each plan [s]: the harvest node's step that asked for it (IK + RRT-Connect
    /// + shortcut + time parameterization), shared among the plans of that step.
    pub planning_times: Vec<f64>,
    /// Simulated planning time the node charged, summed over its plans (`planning_time` of
    /// /harvest/plans) [s]: part of the time to harvest.
    #[serde(default)]
    pub thinking_time: f64,
    /// Simulated compute time the perception and mapping nodes charged over the trial (their
    /// cost models; 0 without sight) [s]: their outputs waited for it.
    #[serde(default)]
    pub perception_time: f64,
    #[serde(default)]
    pub mapping_time: f64,
    pub time_to_harvest: Option<f64>,
    pub placed_count: i64,
    pub contacts: BTreeMap<String, i64>,
    /// Scene objects the robot began to touch, by kind (stem, leaf, truss, fruit: fruit other
    /// than the target; post, gutter...), from every /collision message: what a grower would
    /// call damage risk. Counted, not failures (only base and structure contacts fail).
    #[serde(default)]
    pub touches: BTreeMap<String, u64>,
    /// Crop damage at the end of the trial, by kind (bruised_by_grip, bruised_by_impact,
    /// unripe_detached, stems_broken), from /plant_damage (world ground truth). A bruise
    /// or a broken stem fails the trial ("damage").
    #[serde(default)]
    pub damage: BTreeMap<String, u64>,
    /// How the last pedicel of the trial broke (pull, bend, twist); None when none broke.
    #[serde(default)]
    pub detach_mode: Option<String>,
    /// Largest pedicel force on the fruit at a break in the trial [N] (/plant_damage).
    #[serde(default)]
    pub detach_force: Option<f64>,
    /// Largest bending or twisting moment at the abscission zone at a break [N m].
    #[serde(default)]
    pub detach_moment: Option<f64>,
    /// Leaves the robot pressed aside from rest, the largest force it spent holding one [N],
    /// and the largest load it put on a main stem over its strength (/plant_damage).
    #[serde(flatten)]
    pub plant: PlantEffects,
    /// The pedicel's force on the hand while a grasped fruit hung on its plant, as (simulated
    /// time [s], force [N]) at every step (the world FMU's `*_load_f*` outputs, ground truth):
    /// the build-up to each break. Rounded to 1 ms and 1 mN.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub pedicel_force: Vec<(f64, f64)>,
    /// Pedicel force at each break as (simulated time [s], force [N]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub detach_events: Vec<(f64, f64)>,
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

/// The harvest node under test: the task (the fruit the paper hands over, or a region to
/// harvest by sight) and the trial's seed. Any node that speaks the harvest topics can take
/// its place.
pub type HarvestNodeFactory<'a> = &'a dyn Fn(Task, u64) -> Box<dyn Node>;

/// The built-in harvest node.
pub fn builtin_node(task: Task, seed: u64) -> Box<dyn Node> {
    Box::new(HarvestNode::with_task(task, seed))
}

/// The task of a harvest by sight around `target`: [`REGION_LENGTH`] of its row holding it at
/// a seeded place (never centred on it, never within 0.15 m of an end), from the row's plant
/// line to the aisle's centre line, at the harvestable heights.
pub fn region_of(target: &HarvestTarget, layout: &agrisim_scene::Layout, seed: u64) -> Region {
    let mut rng = Rng::new(seed ^ 0x0052_4547_494f_4e00); // "REGION"
    let x0 = target.center[0] - 0.15 - (REGION_LENGTH - 0.3) * rng.uniform();
    let aisle_y = target.start[1];
    let row_y = layout
        .rows
        .iter()
        .filter(|r| r.active)
        .map(|r| r.y)
        .min_by(|a, b| (a - target.center[1]).abs().total_cmp(&(b - target.center[1]).abs()))
        .unwrap_or(target.center[1]);
    Region {
        x: [x0, x0 + REGION_LENGTH],
        y: [row_y.min(aisle_y), row_y.max(aisle_y)],
        z: [HEIGHT_RANGE.0, HEIGHT_RANGE.1],
    }
}

/// Runs trial `t` into `mcap` with the built-in harvest node.
pub fn run(t: &Trial<HarvestSetup>, mcap: &Path) -> Result<HarvestTrial> {
    run_with(t, mcap, &builtin_node, TRIAL_TIMEOUT)
}

/// Runs trial `t` into `mcap` with the harvest node `node` makes, within `timeout` [s] of
/// simulated time. The judge reads the node's messages (/harvest/status, /harvest/plans),
/// the bus and the world FMU's ground truth; nothing else of the node.
pub fn run_with(t: &Trial<HarvestSetup>, mcap: &Path, node: HarvestNodeFactory, timeout: f64) -> Result<HarvestTrial> {
    let (s, setup, index, seed) = (t.scenario, t.setup, t.index, t.seed);
    let wall = Instant::now();
    let mut rng = Rng::new(seed);
    let target = draw(&setup.candidates, &setup.layout, &mut rng).expect("candidates checked non-empty");
    let region = s.harvest.sight.then(|| region_of(&target, &setup.layout, seed));
    let harvest = node(region.map_or(Task::Fruit(target.fruit_index), Task::Region), seed);
    let node_name = harvest.name().to_string();
    // An external node takes the harvest node's place: it is told the task the same way (by
    // sight the region on /harvest/task_region, never the fruit).
    let task = t.run.nodes.external.contains(&node_name).then(|| match region {
        Some(r) => TaskPublisher::region([r.x, r.y, r.z]),
        None => TaskPublisher::new(target.fruit_index),
    });
    let (mut m, charges) = harvest_session(t, target.start, mcap, harvest, task)?;
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
    let mut damage_reader = Reader::subscribe(&mut m.bus, "/plant_damage");
    let mut damage = DamageLog::default();
    let mut aims = Aims::subscribe(&mut m.bus);
    // By sight: the node's last target estimate, and the fruit nearest it (id, error [m]),
    // with the radius the node gave it and the true one [m].
    let mut chosen: Option<(u32, f64)> = None;
    let mut radii: Option<[f64; 2]> = None;
    let mut judged: Option<(Option<String>, String)> = None;
    let mut time_to_harvest = None;
    let mut touches = Touches::default();
    let mut pedicel_force: Vec<(f64, f64)> = Vec::new();
    let load_names =
        ["left_load_fx", "left_load_fy", "left_load_fz", "right_load_fx", "right_load_fy", "right_load_fz"];
    let result: Result<()> = (|| {
        for k in 1..=max_ticks {
            m.advance()?;
            let mut f = [0.0; 6];
            for (v, name) in f.iter_mut().zip(load_names) {
                *v = m.number(world, name)?;
            }
            let force = f64::max(f[0].hypot(f[1]).hypot(f[2]), f[3].hypot(f[4]).hypot(f[5]));
            // The loaded steps, and the first unloaded one after them (the break).
            if force > 0.0 || pedicel_force.last().is_some_and(|p| p.1 > 0.0) {
                let t = k as f64 * s.timing.step;
                pedicel_force.push(((t * 1e3).round() / 1e3, (force * 1e3).round() / 1e3));
            }
            path.push([m.number(chassis, "x")?, m.number(chassis, "y")?]);
            reports.read(&mut m, &node_name)?;
            damage.read(&mut damage_reader, &mut m.bus)?;
            if let Some(a) = aims.newest(&mut m.bus, &setup.fruit)? {
                chosen = Some((a.id, a.error));
                radii = Some([a.radius, setup.fruit[&a.id].radius]);
            }
            // The base must touch nothing; the arms may brush plants (counted, not failures).
            // Every collision state counts, however short the contact.
            for cs in collisions.take::<CollisionState>(&mut m.bus)? {
                let own = chosen.map_or(target.object_id, |c| c.0);
                touches.update(&cs, |id| id == own);
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
    let mut placed_fruit = None;
    let mut probe = || -> Result<()> {
        for c in COLLISION_COUNTERS.iter().chain(SOFT_COUNTERS.iter()) {
            contacts.insert(c.to_string(), m.number(world, c)? as i64);
        }
        placed = m.number(world, "placed_count")? as i64;
        let placed_id = m.number(world, "last_placed_id")? as i64;
        placed_fruit = u32::try_from(placed_id)
            .ok()
            .filter(|_| placed > 0)
            .and_then(|id| setup.fruit.get(&id).map(|f| (id, f.stage)));
        // The task's fruit: the one handed over, or by sight a ripe one of the region.
        let right = match region {
            None => placed_id == target.object_id as i64,
            Some(r) => u32::try_from(placed_id)
                .ok()
                .and_then(|id| setup.fruit.get(&id))
                .is_some_and(|f| f.stage >= RIPE_STAGE && r.contains(f.center)),
        };
        if placed > 0 && !right {
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
        detail = if region.is_some() {
            "the node reported success but the world has placed no ripe fruit of the region".into()
        } else {
            "the node reported success but the world has not placed the target fruit".into()
        };
    }
    // By sight, a grasp that missed a fruit the node had placed more than MISLOCALIZED away
    // failed on perception: mislocalized.
    if failure.as_deref() == Some("grasp") && chosen.is_some_and(|c| c.1 > MISLOCALIZED) {
        failure = Some("mislocalized".into());
    }
    if failure.is_none() {
        if let Some(why) = damage.failure(IMPACT_BRUISE_FAILS) {
            failure = Some("damage".into());
            detail = why;
        }
    }
    let planning = if failure.as_deref() == Some("planning") || reports.plans.iter().any(|p| !p.ok && !p.optional) {
        "failed"
    } else if failure.is_none() || matches!(failure.as_deref(), Some("placement" | "damage")) {
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
        declined: reports.plans.iter().filter(|p| p.kind == "pregrasp" && !p.ok && p.optional).count(),
        planning_times: reports.planning_times,
        thinking_time: reports.plans.iter().map(|p| p.planning_time).sum(),
        perception_time: charges.perception(),
        mapping_time: charges.mapping(),
        time_to_harvest,
        placed_count: placed,
        contacts,
        touches: touches.by_kind,
        damage: damage.by_kind(),
        detach_mode: damage.mode.clone(),
        detach_force: damage.force,
        detach_moment: damage.moment,
        detach_events: damage.events.clone(),
        pedicel_force,
        plant: damage.effects(),
        tracking_rms: tracking,
        sim_time,
        wall_time: wall.elapsed().as_secs_f64(),
        mcap: mcap.file_name().map(|f| format!("trials/{}", f.to_string_lossy())).unwrap_or_default(),
        path: decimate(&path, 10),
        scene: t.scene,
        sight: region.is_some(),
        region: region.map(|r| [r.x, r.y, r.z]),
        chosen_id: chosen.map(|c| c.0),
        target_error_mm: chosen.map(|c| c.1 * 1e3),
        target_radius_mm: radii.map(|r| r.map(|v| v * 1e3)),
        chosen_stage: chosen.and_then(|c| setup.fruit.get(&c.0)).map(|f| f.stage),
        placed: placed_fruit,
        ..HarvestTrial::of_target(index, seed, &target)
    })
}

/// The record of a trial whose process died: an error, with its target (drawn as the trial
/// draws it) and the reason.
pub fn failed(t: &Trial<HarvestSetup>, reason: String) -> HarvestTrial {
    let target =
        draw(&t.setup.candidates, &t.setup.layout, &mut Rng::new(t.seed)).expect("candidates checked non-empty");
    HarvestTrial {
        scene: t.scene,
        failure: Some("error".into()),
        detail: reason,
        ..HarvestTrial::of_target(t.index, t.seed, &target)
    }
}

impl HarvestTrial {
    /// Trial `index` on `target`, a failure until said otherwise, nothing measured yet.
    pub(crate) fn of_target(index: u64, seed: u64, target: &HarvestTarget) -> HarvestTrial {
        HarvestTrial {
            trial: index,
            scene: 0,
            seed,
            fruit_index: target.fruit_index,
            fruit_id: target.object_id,
            fruit_name: target.name.clone(),
            fruit: target.center,
            sight: false,
            region: None,
            chosen_id: None,
            target_error_mm: None,
            target_radius_mm: None,
            chosen_stage: None,
            placed: None,
            visibility: target.visibility.name().into(),
            start: target.start,
            outcome: "failure".into(),
            failure: None,
            failed_stage: None,
            detail: String::new(),
            planning: "not_reached".into(),
            planning_ok: false,
            plans: 0,
            declined: 0,
            planning_times: vec![],
            thinking_time: 0.0,
            perception_time: 0.0,
            mapping_time: 0.0,
            time_to_harvest: None,
            placed_count: 0,
            contacts: BTreeMap::new(),
            touches: BTreeMap::new(),
            damage: BTreeMap::new(),
            detach_mode: None,
            detach_force: None,
            detach_moment: None,
            detach_events: vec![],
            pedicel_force: vec![],
            plant: PlantEffects::default(),
            tracking_rms: [0.0; 2],
            sim_time: 0.0,
            wall_time: 0.0,
            mcap: format!("trials/{index:04}.mcap"),
            path: vec![],
        }
    }
}
