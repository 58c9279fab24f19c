//! One row trial and its judge: a segment harvested by the built-in row node
//! ([`agrisim_harvest::RowNode`]), judged from ground truth and messages only. A fruit is
//! harvested when the world has placed it in the box (`placed_count`, `last_placed_id` after
//! every exchange); the node's `/harvest/status` gives each fruit's failure category;
//! contacts come from the world's counters (structure, arm-arm, carried fruit: they end the
//! segment) and `/collision` (plant touches, counted).

use super::segment::{draw_segment, regions_of};
use crate::framework::Trial;
use crate::harvest::judge::{base_contact, Aims, DamageLog, PlantEffects, Touches, COLLISION_COUNTERS};
use crate::harvest::session::harvest_session;
use crate::harvest::targets::RIPE_STAGE;
use crate::harvest::trial::MISLOCALIZED;
use crate::harvest::HarvestSetup;
use agrisim_bus::Node;
use agrisim_bus::Reader;
use agrisim_error::{err, Result};
use agrisim_harvest::{row, topics, RowNode};
use agrisim_math::Rng;
use agrisim_msgs::agrisim::{CollisionState, HarvestStatus, PlanResult};
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use std::time::Instant;

/// Simulated time a segment may take per fruit, and on top [s].
pub const TIME_PER_FRUIT: f64 = 90.0;
pub const TIME_EXTRA: f64 = 60.0;
/// By sight, simulated time a segment may take per region on top (driving there, the scan
/// and the scan that finds nothing left) [s].
pub const TIME_PER_REGION: f64 = 20.0;
/// How long the judge waits after the last outcome for released fruit to come to rest [s]
/// (the world settles a fruit still moving after 10 s).
const SETTLE_LIMIT: f64 = 11.0;

/// One fruit of a segment and what became of it.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RowFruit {
    pub fruit_index: usize,
    pub fruit_id: u32,
    pub fruit: [f64; 3],
    pub visibility: String,
    pub harvested: bool,
    /// Failure category from the node's status (or "not_reached" when the segment ended first).
    pub failure: Option<String>,
    pub failed_stage: Option<String>,
    pub detail: String,
    /// When the world placed it in the box [s].
    pub placed_at: Option<f64>,
}

/// By sight: one pick the node tried, and the fruit nearest its target then.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RowAttempt {
    /// When the node reported its outcome [s].
    pub at: f64,
    /// The fruit nearest the target it asked the mapper to allow, its true USDA stage and
    /// how far the estimate was from its centre [mm]; none when it chose nothing.
    pub chosen: Option<(u32, u8, f64)>,
    pub outcome: String,
    pub failure: Option<String>,
}

impl RowAttempt {
    /// The pick's failure class, as the harvest judge classes a trial's: a grasp that
    /// missed, aimed more than [`MISLOCALIZED`] from the nearest fruit, failed on
    /// perception (mislocalized); otherwise the node's own category.
    pub fn failure_class(&self) -> Option<String> {
        let far = self.chosen.is_some_and(|c| c.2 > MISLOCALIZED * 1e3);
        match self.failure.as_deref() {
            Some("grasp") if far => Some("mislocalized".into()),
            f => f.map(str::to_string),
        }
    }
}

#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct RowTrial {
    pub trial: u64,
    pub scene: u64,
    pub seed: u64,
    /// The aisle's centre line and the segment's extent along it [m].
    pub aisle_y: f64,
    pub x_range: [f64; 2],
    pub start: [f64; 3],
    pub targets: u64,
    pub harvested: u64,
    /// (targets, harvested) by visibility class.
    pub per_class: BTreeMap<String, [u64; 2]>,
    pub failures: BTreeMap<String, u64>,
    /// Why the segment ended: "done" (every fruit has its outcome), "timeout", "collision: ...",
    /// "error: ...".
    pub ended: String,
    /// Time between successive placements (the first from the start) [s].
    pub cycle_times: Vec<f64>,
    /// Harvested fruit per hour of the segment's simulated time.
    pub fruit_per_hour: f64,
    /// Plant objects the robot began to touch, by kind.
    pub touches: BTreeMap<String, u64>,
    pub dropped: i64,
    /// Fruit whose pedicel broke (every pick that took a fruit off its plant).
    #[serde(default)]
    pub detached: u64,
    /// Unripe fruit detached (world ground truth; damage), and unripe fruit in the box.
    #[serde(default)]
    pub unripe_detached: u64,
    #[serde(default)]
    pub unripe_placed: u64,
    /// Ripe fruit in the box that were not among the segment's reachable targets.
    #[serde(default)]
    pub other_ripe_placed: u64,
    /// By sight: the node found the fruit itself in regions of the segment.
    #[serde(default)]
    pub sight: bool,
    /// By sight: every pick the node tried.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub attempts: Vec<RowAttempt>,
    /// Simulated planning time the node charged [s].
    pub thinking_time: f64,
    /// Simulated compute the perception and mapping nodes charged over the segment (their
    /// cost models; 0 without sight) [s].
    #[serde(default)]
    pub perception_time: f64,
    #[serde(default)]
    pub mapping_time: f64,
    /// Crop damage at the end, by kind (bruised_by_grip, bruised_by_impact, unripe_detached,
    /// stems_broken), leaves pressed aside from rest, the largest force spent holding one [N]
    /// and the largest main-stem load over its strength (/plant_damage, world ground truth).
    #[serde(default)]
    pub damage: BTreeMap<String, u64>,
    #[serde(flatten)]
    pub plant: PlantEffects,
    pub fruit: Vec<RowFruit>,
    /// Ground-truth base path (every 10th exchange); in trials/NNNN.json, not in
    /// trials.jsonl.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub path: Vec<[f64; 2]>,
    pub sim_time: f64,
    pub wall_time: f64,
    pub mcap: String,
}

/// The segment length option [m].
pub const LENGTH: &str = "length";

/// Runs trial `t`'s segment into `mcap` with the built-in row node.
pub fn run(t: &Trial<HarvestSetup>, mcap: &Path) -> Result<RowTrial> {
    let (s, setup, index, seed, length) = (t.scenario, t.setup, t.index, t.seed, t.options.f64(LENGTH));
    let wall = Instant::now();
    let seg = draw_segment(setup, length, &mut Rng::new(seed))
        .ok_or_else(|| err!("scenario {}: no aisle with reachable ripe fruit", s.path.display()))?;
    // By sight the node is given the segment's stretches of row, not its fruit.
    let regions = s.harvest.sight.then(|| regions_of(&seg, &setup.layout));
    let node: Box<dyn Node> = match &regions {
        Some(r) => Box::new(RowNode::by_sight(r.clone(), seed)),
        None => Box::new(RowNode::new(seg.targets.iter().map(|t| t.fruit_index).collect(), seed)),
    };
    let (mut m, charges) = harvest_session(t, seg.start, mcap, node, None)?;
    let (world, chassis) = (m.component("world", "row benchmark")?, m.component("chassis", "row benchmark")?);
    let step = s.timing.step;
    let timeout = TIME_PER_FRUIT * seg.targets.len() as f64
        + TIME_PER_REGION * regions.as_ref().map_or(0, |r| r.len()) as f64
        + TIME_EXTRA;
    let max_ticks = (timeout / step).round() as u64;
    let mut statuses = Reader::subscribe(&mut m.bus, topics::STATUS);
    let mut plans = Reader::subscribe(&mut m.bus, topics::PLANS);
    let mut collisions = Reader::subscribe(&mut m.bus, "/collision");
    let mut damage_reader = Reader::subscribe(&mut m.bus, "/plant_damage");
    let mut aims = Aims::subscribe(&mut m.bus);
    let mut damage = DamageLog::default();
    // By sight: the fruit nearest the node's current target (id, error [m]), its tries, and
    // whether it has reported the row done.
    let mut chosen: Option<(u32, f64)> = None;
    let mut attempts: Vec<RowAttempt> = vec![];
    let mut finished = false;
    let ids: BTreeSet<u32> = seg.targets.iter().map(|t| t.object_id).collect();
    let mut outcomes: BTreeMap<i32, HarvestStatus> = BTreeMap::new();
    let mut placed: BTreeMap<u32, f64> = BTreeMap::new();
    let mut placed_count = 0.0;
    let mut touches = Touches::default();
    let mut thinking = 0.0;
    let mut path = vec![];
    let mut ended = String::from("timeout");
    let mut all_done: Option<u64> = None;
    let result: Result<()> = (|| {
        for k in 1..=max_ticks {
            m.advance()?;
            if k % 10 == 1 {
                path.push([m.number(chassis, "x")?, m.number(chassis, "y")?]);
            }
            damage.read(&mut damage_reader, &mut m.bus)?;
            // The target stays the pick's until its outcome is recorded.
            if let Some(a) = aims.newest(&mut m.bus, &setup.fruit)? {
                chosen = Some((a.id, a.error));
            }
            for st in statuses.take::<HarvestStatus>(&mut m.bus)? {
                let pick_ended = st.outcome == "success" || st.outcome == "failure";
                match (regions.is_some(), pick_ended) {
                    (true, true) => {
                        let mut a = RowAttempt {
                            at: k as f64 * step,
                            chosen: chosen.take().map(|(id, e)| (id, setup.fruit[&id].stage, e * 1e3)),
                            failure: (st.outcome == "failure").then(|| st.failure_category.clone()),
                            outcome: st.outcome,
                        };
                        a.failure = a.failure_class();
                        attempts.push(a);
                    }
                    (false, true) => {
                        outcomes.entry(st.target_id).or_insert(st);
                    }
                    (true, false) => finished |= st.outcome == row::FINISHED,
                    (false, false) => {}
                }
            }
            thinking += plans.take::<PlanResult>(&mut m.bus)?.iter().map(|p| p.planning_time).sum::<f64>();
            // Plant touches (onsets, the segment's own fruit left out); the base touches nothing.
            for cs in collisions.take::<CollisionState>(&mut m.bus)? {
                touches.update(&cs, |id| ids.contains(&id));
                if let Some(why) = base_contact(&cs) {
                    ended = format!("collision: {why}");
                    return Ok(());
                }
            }
            for c in COLLISION_COUNTERS {
                if m.number(world, c)? > 0.0 {
                    ended = format!("collision: {c}");
                    return Ok(());
                }
            }
            let n = m.number(world, "placed_count")?;
            if n > placed_count {
                placed_count = n;
                let id = m.number(world, "last_placed_id")?;
                if id >= 0.0 {
                    placed.entry(id as u32).or_insert(k as f64 * step);
                }
            }
            // Done when every fruit has its outcome and every picked fruit has come to rest
            // (placed or dropped), or SETTLE_LIMIT after the last outcome.
            let all_told = match regions {
                Some(_) => finished,
                None => seg.targets.iter().all(|t| outcomes.contains_key(&(t.fruit_index as i32))),
            };
            if all_told {
                let done_at = *all_done.get_or_insert(k);
                let resting = m.number(world, "picked_count")? <= n + m.number(world, "dropped_count")?;
                if resting || (k - done_at) as f64 * step >= SETTLE_LIMIT {
                    ended = "done".into();
                    return Ok(());
                }
            }
        }
        Ok(())
    })();
    let sim_time = m.time();
    let dropped = m.number(world, "dropped_count").map(|v| v as i64);
    match (&result, &dropped) {
        (Ok(()), Ok(_)) => m.finish_point()?,
        (Err(e), _) | (Ok(()), Err(e)) => {
            m.record_failure(e);
            ended = format!("error: {e}");
        }
    }
    m.recorder_finish()?;
    let fruit: Vec<RowFruit> = seg
        .targets
        .iter()
        .map(|t| {
            let placed_at = placed.get(&t.object_id).copied();
            let st = outcomes.get(&(t.fruit_index as i32));
            // By sight: the last pick tried at this fruit.
            let tried = attempts.iter().rev().find(|a| a.chosen.is_some_and(|c| c.0 == t.object_id));
            let failure = match (placed_at, st, tried) {
                (Some(_), _, _) => None,
                (None, Some(st), _) if st.outcome == "failure" => Some(st.failure_category.clone()),
                (None, _, Some(a)) => Some(a.failure.clone().unwrap_or_else(|| "placement".into())),
                // The node believed in success, but the world has not placed it.
                (None, Some(_), None) => Some("placement".into()),
                // By sight, a fruit the node never chose in a segment it finished.
                (None, None, None) if finished => Some("not_detected".into()),
                (None, None, None) => Some("not_reached".into()),
            };
            RowFruit {
                fruit_index: t.fruit_index,
                fruit_id: t.object_id,
                fruit: t.center,
                visibility: t.visibility.name().into(),
                harvested: placed_at.is_some(),
                failed_stage: failure.as_ref().and(st.map(|s| s.stage.clone())),
                detail: if failure.is_some() {
                    st.map(|s| s.detail.clone()).unwrap_or_default()
                } else {
                    String::new()
                },
                failure,
                placed_at,
            }
        })
        .collect();
    let mut per_class: BTreeMap<String, [u64; 2]> = BTreeMap::new();
    let mut failures: BTreeMap<String, u64> = BTreeMap::new();
    for f in &fruit {
        let c = per_class.entry(f.visibility.clone()).or_default();
        c[0] += 1;
        c[1] += f.harvested as u64;
        if let Some(why) = &f.failure {
            *failures.entry(why.clone()).or_insert(0) += 1;
        }
    }
    let mut times: Vec<f64> = fruit.iter().filter_map(|f| f.placed_at).collect();
    times.sort_by(f64::total_cmp);
    let cycle_times: Vec<f64> = times.iter().scan(0.0, |prev, &t| Some(t - std::mem::replace(prev, t))).collect();
    let harvested = times.len() as u64;
    let targets_ids: BTreeSet<u32> = seg.targets.iter().map(|t| t.object_id).collect();
    let stage_of = |id: &u32| setup.fruit.get(id).map_or(0, |f| f.stage);
    let unripe_placed = placed.keys().filter(|id| stage_of(id) < RIPE_STAGE).count() as u64;
    let other_ripe_placed =
        placed.keys().filter(|id| stage_of(id) >= RIPE_STAGE && !targets_ids.contains(id)).count() as u64;
    Ok(RowTrial {
        trial: index,
        scene: t.scene,
        seed,
        aisle_y: seg.aisle_y,
        x_range: seg.x_range,
        start: seg.start,
        targets: seg.targets.len() as u64,
        harvested,
        per_class,
        failures,
        ended,
        cycle_times,
        fruit_per_hour: if sim_time > 0.0 { harvested as f64 * 3600.0 / sim_time } else { 0.0 },
        touches: touches.by_kind,
        dropped: dropped.unwrap_or(0),
        detached: damage.events.len() as u64,
        unripe_detached: damage.last.unripe_detached as u64,
        unripe_placed,
        other_ripe_placed,
        sight: regions.is_some(),
        attempts,
        thinking_time: thinking,
        perception_time: charges.perception(),
        mapping_time: charges.mapping(),
        damage: damage.by_kind(),
        plant: damage.effects(),
        fruit,
        path,
        sim_time,
        wall_time: wall.elapsed().as_secs_f64(),
        mcap: format!("trials/{index:04}.mcap"),
    })
}

/// The record of a segment whose process died.
pub fn failed(t: &Trial<HarvestSetup>, reason: String) -> RowTrial {
    let (index, seed) = (t.index, t.seed);
    let seg = draw_segment(t.setup, t.options.f64(LENGTH), &mut Rng::new(seed));
    let targets = seg.as_ref().map_or(0, |s| s.targets.len() as u64);
    RowTrial {
        trial: index,
        scene: t.scene,
        seed,
        aisle_y: seg.as_ref().map_or(0.0, |s| s.aisle_y),
        x_range: seg.as_ref().map_or([0.0; 2], |s| s.x_range),
        start: seg.as_ref().map_or([0.0; 3], |s| s.start),
        targets,
        failures: BTreeMap::from([("error".to_string(), targets)]),
        ended: format!("error: {reason}"),
        mcap: format!("trials/{index:04}.mcap"),
        ..RowTrial::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The harvest judge's rule: a grasp that closed on nothing, aimed over 15 mm from the
    /// nearest fruit, failed on perception; near a fruit, or another failure, keeps its class.
    #[test]
    fn a_grasp_aimed_far_from_any_fruit_is_mislocalized() {
        let pick = |failure: Option<&str>, error_mm: Option<f64>| RowAttempt {
            at: 1.0,
            chosen: error_mm.map(|e| (7, 6, e)),
            outcome: if failure.is_some() { "failure" } else { "success" }.into(),
            failure: failure.map(str::to_string),
        };
        let class = |f, e| pick(f, e).failure_class();
        assert_eq!(class(Some("grasp"), Some(113.0)).as_deref(), Some("mislocalized"));
        assert_eq!(class(Some("grasp"), Some(14.9)).as_deref(), Some("grasp"));
        assert_eq!(class(Some("grasp"), None).as_deref(), Some("grasp"));
        assert_eq!(class(Some("planning"), Some(113.0)).as_deref(), Some("planning"));
        assert_eq!(class(None, Some(5.0)), None);
        // Classing twice changes nothing (summaries re-class recorded picks).
        let mut a = pick(Some("grasp"), Some(40.0));
        a.failure = a.failure_class();
        assert_eq!(a.failure_class().as_deref(), Some("mislocalized"));
    }
}
