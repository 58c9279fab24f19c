//! `agrisim bench row`: the whole-row harvest. Each trial is an aisle segment (both sides):
//! the robot starts at its beginning and harvests every ripe fruit it can reach there
//! ([`super::harvest_targets::eligible`]: every visibility class), in order along the aisle,
//! moving the base between picks and returning each fruit to the box
//! ([`agrisim_harvest::RowNode`]).
//!
//! Judged from ground truth and messages only: a fruit is harvested when the world has
//! placed it in the box (`placed_count`, `last_placed_id` after every exchange); the node's
//! `/harvest/status` gives each fruit's failure category; contacts come from the world's
//! counters (structure, arm-arm, carried fruit: they end the segment) and `/collision`
//! (plant touches, counted). Figures: fraction harvested (by visibility class), fruit per
//! hour, cycle time per fruit, plant touches per fruit, dropped fruit.

use super::harvest::{base_contact, harvest_session, HarvestSetup, Touches, COLLISION_COUNTERS};
use super::harvest_targets::HarvestTarget;
use super::nav::trial_seed;
use super::report::{self, bar_chart, count_table, interval, opt, per_kind, rate_table, render_with, TrialTrace};
use super::stats::{cluster_bootstrap95, percentile, wilson, Z95};
use crate::scenes::Scenes;
use crate::trials::{run_one, run_trials, write_summary, Exec, TrialPlan};
use agrisim_bus::Reader;
use agrisim_error::{err, Result};
use agrisim_harvest::{topics, RowNode};
use agrisim_math::Rng;
use agrisim_msgs::agrisim::{CollisionState, HarvestStatus, PlanResult};
use agrisim_session::{RunOptions, Scenario};
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use std::time::Instant;

/// Simulated time a segment may take per fruit, and on top [s].
pub const TIME_PER_FRUIT: f64 = 90.0;
pub const TIME_EXTRA: f64 = 60.0;
/// How long the judge waits after the last outcome for released fruit to come to rest [s]
/// (the world settles a fruit still moving after 10 s).
const SETTLE_LIMIT: f64 = 11.0;
/// The robot starts this far before the segment's first stand-off [m].
const LEAD_IN: f64 = 0.8;

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
    /// Simulated planning time the node charged [s].
    pub thinking_time: f64,
    pub fruit: Vec<RowFruit>,
    /// Ground-truth base path (every 10th exchange); in trials/NNNN.json, not in
    /// trials.jsonl.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub path: Vec<[f64; 2]>,
    pub sim_time: f64,
    pub wall_time: f64,
    pub mcap: String,
}

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
    pub thinking_time_per_fruit: f64,
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

/// One trial's segment: its aisle, extent, fruit in harvesting order and start pose.
#[derive(Debug, Clone)]
pub struct Segment {
    pub aisle_y: f64,
    pub x_range: [f64; 2],
    pub targets: Vec<HarvestTarget>,
    pub start: [f64; 3],
}

/// Draws a segment `length` m long: a uniformly chosen aisle with reachable ripe fruit,
/// a uniformly placed stretch of it within the reachable fruit's extent; its fruit (both
/// sides) in order along +x, the robot on the centre line before the first, facing +x.
pub fn draw_segment(setup: &HarvestSetup, length: f64, rng: &mut Rng) -> Option<Segment> {
    // Aisle centre lines, in order (every candidate of an aisle starts on the same one).
    let mut aisles: Vec<f64> = setup.candidates.iter().map(|t| t.start[1]).collect();
    aisles.sort_by(f64::total_cmp);
    aisles.dedup();
    if aisles.is_empty() {
        return None;
    }
    let aisle_y = aisles[((rng.uniform() * aisles.len() as f64) as usize).min(aisles.len() - 1)];
    let along: Vec<&HarvestTarget> = setup.candidates.iter().filter(|t| (t.start[1] - aisle_y).abs() < 1e-9).collect();
    let lo = along.iter().map(|t| t.center[0]).fold(f64::INFINITY, f64::min);
    let hi = along.iter().map(|t| t.center[0]).fold(f64::NEG_INFINITY, f64::max);
    let x0 = lo + (hi - lo - length).max(0.0) * rng.uniform();
    let x1 = x0 + length;
    let mut targets: Vec<HarvestTarget> =
        along.into_iter().filter(|t| (x0..x1).contains(&t.center[0])).cloned().collect();
    targets.sort_by(|a, b| a.center[0].total_cmp(&b.center[0]).then(a.fruit_index.cmp(&b.fruit_index)));
    let first = targets.first().map_or(x0, |t| agrisim_harvest::geometry::standoff(t.center, t.side)[0]);
    Some(Segment { aisle_y, x_range: [x0, x1], start: [first - LEAD_IN, aisle_y, 0.0], targets })
}

/// Runs one segment into `mcap` with the built-in row node.
pub fn run_trial(
    s: &Scenario,
    o: &RunOptions,
    setup: &HarvestSetup,
    length: f64,
    index: u64,
    seed: u64,
    mcap: &Path,
) -> Result<RowTrial> {
    let wall = Instant::now();
    let seg = draw_segment(setup, length, &mut Rng::new(seed))
        .ok_or_else(|| err!("scenario {}: no aisle with reachable ripe fruit", s.path.display()))?;
    let node = RowNode::new(seg.targets.iter().map(|t| t.fruit_index).collect(), seed);
    let mut m = harvest_session(s, o, setup, seg.start, seed, mcap, Box::new(node), None)?;
    let (world, chassis) = (m.component("world", "row benchmark")?, m.component("chassis", "row benchmark")?);
    let step = s.timing.step;
    let timeout = TIME_PER_FRUIT * seg.targets.len() as f64 + TIME_EXTRA;
    let max_ticks = (timeout / step).round() as u64;
    let mut statuses = Reader::subscribe(&mut m.bus, topics::STATUS);
    let mut plans = Reader::subscribe(&mut m.bus, topics::PLANS);
    let mut collisions = Reader::subscribe(&mut m.bus, "/collision");
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
            for st in statuses.take::<HarvestStatus>(&mut m.bus)? {
                if st.outcome == "success" || st.outcome == "failure" {
                    outcomes.entry(st.target_id).or_insert(st);
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
            if seg.targets.iter().all(|t| outcomes.contains_key(&(t.fruit_index as i32))) {
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
            let failure = match (placed_at, st) {
                (Some(_), _) => None,
                (None, Some(st)) if st.outcome == "failure" => Some(st.failure_category.clone()),
                // The node believed in success, but the world has not placed it.
                (None, Some(_)) => Some("placement".into()),
                (None, None) => Some("not_reached".into()),
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
    Ok(RowTrial {
        trial: index,
        scene: 0,
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
        thinking_time: thinking,
        fruit,
        path,
        sim_time,
        wall_time: wall.elapsed().as_secs_f64(),
        mcap: format!("trials/{index:04}.mcap"),
    })
}

/// The record of a segment whose process died.
fn failed_trial(setup: &HarvestSetup, length: f64, index: u64, seed: u64, reason: String) -> RowTrial {
    let seg = draw_segment(setup, length, &mut Rng::new(seed));
    let targets = seg.as_ref().map_or(0, |s| s.targets.len() as u64);
    RowTrial {
        trial: index,
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

/// Runs `plan.trials` segments and writes trials.jsonl, summary.json, report.html and
/// trials/*.mcap.
#[allow(clippy::too_many_arguments)]
pub fn bench_row(
    s: &Scenario,
    o: &RunOptions,
    plan: TrialPlan,
    length: f64,
    out: &Path,
    resume: bool,
    exec: Exec,
    progress: impl FnMut(u64, u64),
) -> Result<RowSummary> {
    check_length(length)?;
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
            run_trial(s, &o, setup, length, i, trial_seed(seed, i), mcap).map(|t| RowTrial { scene: k, ..t })
        },
        |i, reason| {
            let (k, _, setup) = scenes.of(i);
            RowTrial { scene: k, ..failed_trial(setup, length, i, trial_seed(seed, i), reason) }
        },
        // trials.jsonl without the path (it is in trials/NNNN.json).
        |t| serde_json::to_string(&RowTrial { path: vec![], ..t.clone() }).expect("plain struct"),
    )?;
    let summary = summarize(s, plan, length, &done.results);
    write_summary(out, &summary, done.interrupted)?;
    write_report(s, &summary, &done.results, out)?;
    Ok(summary)
}

/// A worker process's job: segment `i` of the benchmark `bench_row` runs.
pub fn row_worker(s: &Scenario, o: &RunOptions, plan: TrialPlan, length: f64, out: &Path, i: u64) -> Result<()> {
    check_length(length)?;
    let o = o.record_default(s, agrisim_session::Profile::Standard);
    let scenes = Scenes::for_trial(s, plan.scenes, i, HarvestSetup::new)?;
    let (k, s, setup) = scenes.of(i);
    run_one(out, i, |i, mcap| {
        run_trial(s, &o, setup, length, i, trial_seed(plan.seed, i), mcap).map(|t| RowTrial { scene: k, ..t })
    })
}

fn check_length(length: f64) -> Result<()> {
    if length.is_finite() && length > 0.0 && length <= 200.0 {
        Ok(())
    } else {
        Err(err!("--length {length}: the segment length must be in (0, 200] m"))
    }
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
    let clusters: Vec<(u64, u64)> =
        results.iter().filter(|t| t.targets > 0).map(|t| (t.harvested, t.targets)).collect();
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
        thinking_time_per_fruit: results.iter().map(|t| t.thinking_time).sum::<f64>() / targets.max(1) as f64,
        rtf: if wall > 0.0 { sim / wall } else { 0.0 },
        sim_time: sim,
        wall_time: wall,
    }
}

/// report.html: summary, per-class table, failure taxonomy, cycle-time histogram, and the
/// map of scene 0 with every segment's base path and fruit (green harvested, red not).
fn write_report(s: &Scenario, sum: &RowSummary, results: &[RowTrial], out: &Path) -> Result<()> {
    let g = agrisim_session::scene::generate_scene(s)?;
    let rows = vec![
        ("scenario".to_string(), sum.scenario.clone()),
        ("segments x length".to_string(), format!("{} x {} m", sum.segments, sum.segment_length)),
        ("ripe fruit reachable / harvested".to_string(), format!("{} / {}", sum.targets, sum.harvested)),
        (
            "harvested fraction".to_string(),
            format!("{:.3} (cluster bootstrap 95 % {})", sum.harvested_fraction, interval(sum.cluster_bootstrap95)),
        ),
        ("fruit per hour".to_string(), format!("{:.1}", sum.fruit_per_hour)),
        (
            "cycle time mean / p50 / p95 [s]".to_string(),
            format!("{} / {} / {}", opt(sum.cycle_time_mean), opt(sum.cycle_time_p50), opt(sum.cycle_time_p95)),
        ),
        ("plant touches per fruit".to_string(), per_kind(&sum.touches_per_fruit)),
        ("dropped fruit".to_string(), sum.dropped.to_string()),
        ("segments ended".to_string(), format!("{:?}", sum.segments_ended)),
        ("real-time factor".to_string(), format!("{:.2}", sum.rtf)),
    ];
    let classes = sum.per_class.iter().map(|(k, c)| (k.clone(), c.targets, c.harvested, c.wilson95));
    let cycles: Vec<f64> = results.iter().flat_map(|t| t.cycle_times.iter().copied()).collect();
    let sections = vec![
        ("Harvested by visibility class".to_string(), rate_table(["class", "fruit", "harvested"], classes)),
        ("Failure taxonomy (fruit not harvested)".to_string(), count_table(["category", "fruit"], &sum.failures)),
        ("Cycle times (placement to placement)".to_string(), bar_chart(&cycles, 5.0, "cycle time [s]")),
    ];
    let traces: Vec<TrialTrace> = results
        .iter()
        .filter(|t| t.scene == 0)
        .flat_map(|t| {
            let path = TrialTrace {
                index: t.trial,
                success: t.harvested == t.targets,
                reason: format!("segment {}: {}/{} harvested, ended {}", t.trial, t.harvested, t.targets, t.ended),
                target: t.start,
                path: t.path.clone(),
            };
            std::iter::once(path).chain(t.fruit.iter().map(move |f| TrialTrace {
                index: t.trial,
                success: f.harvested,
                reason: f.failure.clone().unwrap_or_default(),
                target: f.fruit,
                path: vec![],
            }))
        })
        .collect();
    let [x0, y0, x1, y1] = g.layout.bounds;
    let html = render_with(
        &format!("agrisim row harvest benchmark: {}", s.name),
        &rows,
        &g.objects,
        [x0, y0, x1, y1],
        &traces,
        &sections,
    );
    report::write(out, &html)
}
