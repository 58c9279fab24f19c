//! summary.json: recall per ripeness stage and per visibility class (ripe fruit), precision,
//! ripeness classification, 3-D centre error by distance, the node's time per frame.

use super::judge::{FruitResult, FALSE_CAUSES, VISIBILITY};
use super::setup::PerceptionSetup;
use super::trial::PerceptionRecord;
use crate::framework::stats::{percentile, wilson};
use crate::framework::Whole;
use agrisim_perception::is_ripe;
use serde::Serialize;
use std::collections::BTreeMap;

#[derive(Serialize, Clone, Debug)]
pub struct Rate {
    pub found: u64,
    pub total: u64,
    pub rate: Option<f64>,
    pub wilson95: [f64; 2],
}

fn rate(found: u64, total: u64) -> Rate {
    Rate { found, total, rate: (total > 0).then(|| found as f64 / total as f64), wilson95: wilson(found, total, 1.96) }
}

#[derive(Serialize, Clone, Debug)]
pub struct ErrorStats {
    pub n: usize,
    pub p50_mm: Option<f64>,
    pub p95_mm: Option<f64>,
    pub max_mm: Option<f64>,
}

fn errors(mut v: Vec<f64>) -> ErrorStats {
    v.sort_by(f64::total_cmp);
    ErrorStats { n: v.len(), p50_mm: percentile(&v, 0.5), p95_mm: percentile(&v, 0.95), max_mm: v.last().copied() }
}

#[derive(Serialize, Debug)]
pub struct PerceptionSummary {
    pub benchmark: String,
    pub scenario: String,
    pub environment: String,
    pub trials: u64,
    pub scenes: u64,
    pub seed: u64,
    pub frames: u64,
    pub errors: u64,
    /// Recall per USDA stage ("1".."6"), every visibility class.
    pub recall_by_stage: BTreeMap<String, Rate>,
    /// Recall of ripe fruit (stages 5-6) per visibility class.
    pub ripe_recall_by_visibility: BTreeMap<String, Rate>,
    /// Missed fruit per "stage/visibility" (all stages): what the misses are.
    pub missed_by_stage_visibility: BTreeMap<String, u64>,
    /// False detections per cause (the object under the detection: see `judge::FALSE_CAUSES`).
    pub false_detections_by_cause: BTreeMap<String, u64>,
    /// The judge's geometry check: free fruit whose projected centre lies on their own label.
    pub centre_on_label: Rate,
    /// Detections that are some fruit, of all detections (those on fruit too hidden or far to
    /// count are left out).
    pub precision: Rate,
    /// Detections classed ripe that are ripe fruit, of all detections classed ripe.
    pub ripe_precision: Rate,
    /// Found fruit whose stage was called right, and whose ripe / not ripe was.
    pub stage_accuracy: Rate,
    pub ripe_accuracy: Rate,
    /// 3-D centre error of found fruit by centre depth: "<0.75 m", "0.75-1.0 m", "1.0-1.5 m",
    /// and "within_1m".
    pub centre_error_by_distance: BTreeMap<String, ErrorStats>,
    /// Within 1 m, the error split: along the ray (signed median = the fit's depth bias, p95
    /// of its size) and across it (p95).
    pub centre_error_split_within_1m: ErrorSplit,
    /// Within 1 m, the radius error of found fruit: signed median (the fit's bias) and p95 of
    /// its size, of every found fruit and of the ripe ones.
    pub radius_error_within_1m: BTreeMap<String, RadiusError>,
    /// Within 1 m, the centre error of found fruit by USDA stage ("1".."6") and of the ripe
    /// ones (stages 5-6, the harvest's targets) together: partly coloured fruit are placed
    /// from part of their surface.
    pub centre_error_within_1m_by_stage: BTreeMap<String, ErrorStats>,
    /// The node's wall time per frame in the trials [ms]: mean over trials.
    pub node_ms_per_frame: Option<f64>,
}

#[derive(Serialize, Clone, Debug)]
pub struct ErrorSplit {
    pub ray_median_signed_mm: Option<f64>,
    pub ray_p95_mm: Option<f64>,
    pub lateral_p95_mm: Option<f64>,
}

#[derive(Serialize, Clone, Debug)]
pub struct RadiusError {
    pub n: usize,
    pub median_signed_mm: Option<f64>,
    pub p95_mm: Option<f64>,
}

fn radius_errors<'a>(found: impl Iterator<Item = &'a &'a &'a FruitResult>) -> RadiusError {
    let mut signed: Vec<f64> = found.filter(|f| f.depth <= 1.0).filter_map(|f| f.radius_error_mm).collect();
    signed.sort_by(f64::total_cmp);
    let mut size: Vec<f64> = signed.iter().map(|e| e.abs()).collect();
    size.sort_by(f64::total_cmp);
    RadiusError { n: signed.len(), median_signed_mm: percentile(&signed, 0.5), p95_mm: percentile(&size, 0.95) }
}

fn split(found: &[&&FruitResult]) -> ErrorSplit {
    let near: Vec<(f64, f64)> =
        found.iter().filter(|f| f.depth <= 1.0).filter_map(|f| Some((f.error_mm?, f.ray_error_mm?))).collect();
    let sorted = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v
    };
    let signed = sorted(near.iter().map(|p| p.1).collect());
    let ray = sorted(near.iter().map(|p| p.1.abs()).collect());
    let lateral = sorted(near.iter().map(|p| (p.0 * p.0 - p.1 * p.1).max(0.0).sqrt()).collect());
    ErrorSplit {
        ray_median_signed_mm: percentile(&signed, 0.5),
        ray_p95_mm: percentile(&ray, 0.95),
        lateral_p95_mm: percentile(&lateral, 0.95),
    }
}

pub fn summarize(w: &Whole<PerceptionSetup>, results: &[PerceptionRecord]) -> PerceptionSummary {
    let fruit: Vec<&FruitResult> = results.iter().flat_map(|r| &r.frames).flat_map(|f| &f.fruit).collect();
    let mut recall_by_stage = BTreeMap::new();
    for s in 1..=6u8 {
        let of: Vec<_> = fruit.iter().filter(|f| f.stage == s).collect();
        recall_by_stage.insert(s.to_string(), rate(of.iter().filter(|f| f.detected).count() as u64, of.len() as u64));
    }
    let mut ripe_recall_by_visibility = BTreeMap::new();
    for v in VISIBILITY {
        let of: Vec<_> = fruit.iter().filter(|f| is_ripe(f.stage) && f.visibility == v).collect();
        ripe_recall_by_visibility
            .insert(v.to_string(), rate(of.iter().filter(|f| f.detected).count() as u64, of.len() as u64));
    }
    let mut missed_by_stage_visibility = BTreeMap::new();
    for f in fruit.iter().filter(|f| !f.detected) {
        *missed_by_stage_visibility.entry(format!("{}/{}", f.stage, f.visibility)).or_insert(0) += 1;
    }
    let mut false_detections_by_cause: BTreeMap<String, u64> =
        FALSE_CAUSES.iter().map(|c| (c.to_string(), 0)).collect();
    let frames = results.iter().flat_map(|r| &r.frames);
    let (mut dets, mut fps, mut ignored, mut ripe_calls, mut ripe_fp) = (0, 0, 0, 0, 0);
    let (mut checks, mut on_label) = (0, 0);
    for f in frames {
        dets += f.detections;
        fps += f.false_positives.len() as u64;
        ignored += f.ignored;
        ripe_fp += f.false_positives.iter().filter(|d| is_ripe(d.stage)).count() as u64;
        for d in &f.false_positives {
            *false_detections_by_cause.entry(d.cause.clone()).or_insert(0) += 1;
        }
        checks += f.centre_checks;
        on_label += f.centre_on_label;
    }
    let found: Vec<&&FruitResult> = fruit.iter().filter(|f| f.detected).collect();
    for f in &found {
        if f.predicted_stage.is_some_and(is_ripe) {
            ripe_calls += 1;
        }
    }
    let ripe_true = found.iter().filter(|f| f.predicted_stage.is_some_and(is_ripe) && is_ripe(f.stage)).count() as u64;
    let counted = dets - ignored;
    let stage_ok = found.iter().filter(|f| f.predicted_stage == Some(f.stage)).count() as u64;
    let ripe_ok = found.iter().filter(|f| f.predicted_stage.map(is_ripe) == Some(is_ripe(f.stage))).count() as u64;
    let mut by_dist: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    for f in &found {
        let e = f.error_mm.unwrap_or(f64::NAN);
        let bin = if f.depth < 0.75 {
            "<0.75 m"
        } else if f.depth < 1.0 {
            "0.75-1.0 m"
        } else {
            "1.0-1.5 m"
        };
        by_dist.entry(bin.into()).or_default().push(e);
        if f.depth <= 1.0 {
            by_dist.entry("within_1m".into()).or_default().push(e);
        }
    }
    let times: Vec<f64> = results.iter().filter_map(|r| r.line.node_ms_per_frame).collect();
    PerceptionSummary {
        benchmark: "perception".into(),
        scenario: w.scenario.name.clone(),
        environment: results.first().map_or(String::new(), |r| r.line.environment.clone()),
        trials: results.len() as u64,
        scenes: w.plan.scenes,
        seed: w.plan.seed,
        frames: results.iter().map(|r| r.frames.len() as u64).sum(),
        errors: results.iter().filter(|r| r.line.error.is_some()).count() as u64,
        recall_by_stage,
        ripe_recall_by_visibility,
        missed_by_stage_visibility,
        false_detections_by_cause,
        centre_on_label: rate(on_label, checks),
        precision: rate(counted - fps, counted),
        ripe_precision: rate(ripe_true, ripe_calls + ripe_fp),
        stage_accuracy: rate(stage_ok, found.len() as u64),
        ripe_accuracy: rate(ripe_ok, found.len() as u64),
        centre_error_split_within_1m: split(&found),
        radius_error_within_1m: BTreeMap::from([
            ("all".to_string(), radius_errors(found.iter())),
            ("ripe".to_string(), radius_errors(found.iter().filter(|f| is_ripe(f.stage)))),
        ]),
        centre_error_within_1m_by_stage: {
            let mut by: BTreeMap<String, Vec<f64>> = BTreeMap::new();
            for f in found.iter().filter(|f| f.depth <= 1.0) {
                let e = f.error_mm.unwrap_or(f64::NAN);
                by.entry(f.stage.to_string()).or_default().push(e);
                if is_ripe(f.stage) {
                    by.entry("ripe".into()).or_default().push(e);
                }
            }
            by.into_iter().map(|(k, v)| (k, errors(v))).collect()
        },
        centre_error_by_distance: by_dist.into_iter().map(|(k, v)| (k, errors(v))).collect(),
        node_ms_per_frame: (!times.is_empty()).then(|| times.iter().sum::<f64>() / times.len() as f64),
    }
}
