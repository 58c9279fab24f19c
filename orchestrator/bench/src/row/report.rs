//! report.html of the row benchmark.

use super::summary::RowSummary;
use super::trial::RowTrial;
use crate::framework::report::{bar_chart, count_table, interval, opt, per_kind, rate_table, render_with, TrialTrace};

/// report.html: summary, per-class table, failure taxonomy, cycle-time histogram, and the
/// map of scene 0 with every segment's base path and fruit (green harvested, red not).
/// `g` is scene 0's greenhouse.
pub fn report_html(g: &agrisim_scene::Greenhouse, sum: &RowSummary, results: &[RowTrial]) -> String {
    let rows = vec![
        ("scenario".to_string(), sum.scenario.clone()),
        (
            "mode".to_string(),
            if sum.perception_in_loop {
                "by sight: perception and the sensed scene in the loop; the node finds the fruit".to_string()
            } else {
                "ground truth: the node is handed the reachable ripe fruit".to_string()
            },
        ),
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
        (
            "crop damage (all segments)".to_string(),
            sum.damage.iter().filter(|(_, v)| **v > 0).map(|(k, v)| format!("{k} {v}")).collect::<Vec<_>>().join(", "),
        ),
        (
            "leaves pressed aside per fruit; largest holding force [N]; largest stem load / strength".to_string(),
            format!("{:.1}; {:.1}; {:.2}", sum.leaf_pushes_per_fruit, sum.peak_leaf_force, sum.peak_stem_load),
        ),
        (
            "perception; mapping compute charged per fruit [s]".to_string(),
            format!("{:.2}; {:.2}", sum.perception_time_per_fruit, sum.mapping_time_per_fruit),
        ),
        (
            "fruit detached / unripe detached (share)".to_string(),
            format!("{} / {} ({:.3})", sum.detached, sum.unripe_detached, sum.unripe_share),
        ),
        (
            "unripe in the box / ripe in the box outside the targets".to_string(),
            format!("{} / {}", sum.unripe_placed, sum.other_ripe_placed),
        ),
        ("segments ended".to_string(), format!("{:?}", sum.segments_ended)),
        ("wall-clock figures".to_string(), "in summary.json (rtf, wall_time)".to_string()),
    ];
    let classes = sum.per_class.iter().map(|(k, c)| (k.clone(), c.targets, c.harvested, c.wilson95));
    let cycles: Vec<f64> = results.iter().flat_map(|t| t.cycle_times.iter().copied()).collect();
    let mut sections = vec![
        ("Harvested by visibility class".to_string(), rate_table(["class", "fruit", "harvested"], classes)),
        ("Failure taxonomy (fruit not harvested)".to_string(), count_table(["category", "fruit"], &sum.failures)),
    ];
    if sum.perception_in_loop {
        let title = format!("Failed picks by class (by sight: {} picks tried)", sum.attempts);
        sections.push((title, count_table(["category", "picks"], &sum.attempt_failures)));
    }
    sections.push(("Cycle times (placement to placement)".to_string(), bar_chart(&cycles, 5.0, "cycle time [s]")));
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
    render_with(
        &format!("agrisim row harvest benchmark: {}", sum.scenario),
        &rows,
        &g.objects,
        [x0, y0, x1, y1],
        &traces,
        &sections,
    )
}
