//! report.html of the harvest benchmark.

use super::summary::HarvestSummary;
use super::trial::HarvestTrial;
use crate::framework::report::{
    bar_chart, count_table, interval, line_chart, opt, per_kind, per_scene_section, rate_table, render_with,
    view_bounds, TrialTrace,
};

/// report.html: the rates (harvest, planning, conditional) with their intervals, results per
/// scene and per visibility class, the failure taxonomy, a histogram of the time to harvest,
/// and the map of scene 0 with every trial's ground-truth base path and target fruit (green
/// harvested, red not). Only figures the seed determines: the same seed gives the same page
/// (the wall-clock figures are in summary.json).
pub fn report_html(g: &agrisim_scene::Greenhouse, sum: &HarvestSummary, results: &[HarvestTrial]) -> String {
    let rows = vec![
        ("scenario".to_string(), sum.scenario.clone()),
        ("seed".to_string(), sum.seed.to_string()),
        (
            "perception".to_string(),
            if sum.perception_in_loop {
                format!(
                    "in the loop: the node found its fruit by sight and planned in the sensed scene; target error p50 {} mm, p95 {} mm",
                    opt(sum.target_error_mm_p50),
                    opt(sum.target_error_mm_p95)
                )
            } else {
                "ground truth: the node was handed the world's target and planning scene".to_string()
            },
        ),
        (
            "trials x scenes".to_string(),
            format!("{} in {} scene(s), {} distinct targets", sum.trials, sum.scenes, sum.distinct_targets),
        ),
        ("harvested".to_string(), format!("{} / {} = {:.3}", sum.successes, sum.trials, sum.success_rate)),
        ("harvest Wilson 95 %".to_string(), interval(sum.wilson95)),
        ("harvest cluster bootstrap 95 % (over scenes)".to_string(), interval(sum.cluster_bootstrap95)),
        (
            "harvested, of the tasks within the hand (a ripe fruit no wider than it opens)".to_string(),
            format!(
                "{} / {}, Wilson 95 % {}",
                sum.within_hand.successes,
                sum.within_hand.trials,
                interval(sum.within_hand.wilson95)
            ),
        ),
        (
            "planning (of decided trials)".to_string(),
            format!("{} / {} = {:.3}", sum.planning_successes, sum.planning_decided, sum.planning_success_rate),
        ),
        ("planning Wilson 95 %".to_string(), interval(sum.planning_wilson95)),
        (
            "fruit declined for want of a pre-grasp (trials)".to_string(),
            format!("{} ({})", sum.declined, sum.trials_declining),
        ),
        (
            "harvested given planning".to_string(),
            format!("{:.3}, Wilson 95 % {}", sum.conditional_success_rate, interval(sum.conditional_wilson95)),
        ),
        ("mean time to harvest [s]".to_string(), opt(sum.time_to_harvest_mean)),
        (
            "plans; planning time charged per trial [s]".to_string(),
            format!("{}; {:.3}", sum.plans, sum.thinking_time_mean),
        ),
        (
            "perception; mapping compute charged per trial [s]".to_string(),
            format!("{:.3}; {:.3}", sum.perception_time_mean, sum.mapping_time_mean),
        ),
        ("plant touches per trial".to_string(), per_kind(&sum.touches_per_trial)),
        ("crop damage (all trials)".to_string(), count_kinds(&sum.damage)),
        ("pedicel breaks by mode (trials)".to_string(), count_kinds(&sum.detach_modes)),
        ("mean detach force [N]".to_string(), opt(sum.detach_force_mean)),
        (
            "leaves pressed aside per trial; largest holding force [N]; largest stem load / strength".to_string(),
            format!("{:.1}; {:.1}; {:.2}", sum.leaf_pushes_per_trial, sum.peak_leaf_force, sum.peak_stem_load),
        ),
        ("joint tracking RMS mean [rad]".to_string(), format!("{:.2e}", sum.tracking_rms_mean)),
        (
            "wall-clock figures".to_string(),
            "in summary.json (rtf, planning_time_p50/p95/max, thinking_over_wall)".to_string(),
        ),
    ];
    let classes = sum.per_visibility.iter().map(|(k, c)| (k.clone(), c.trials, c.successes, c.wilson95));
    let times: Vec<f64> = results.iter().filter_map(|t| t.time_to_harvest).collect();
    let mut sections = vec![];
    sections.extend(per_scene_section(&sum.per_scene, "harvested"));
    sections.extend([
        ("Harvested by visibility class".to_string(), rate_table(["class", "trials", "harvested"], classes)),
        ("Failure taxonomy (trials not harvested)".to_string(), count_table(["category", "trials"], &sum.failures)),
        ("Time to harvest (successful trials, simulated)".to_string(), bar_chart(&times, 5.0, "time to harvest [s]")),
        ("Detachment per trial".to_string(), detach_table(results)),
        ("Pedicel force until it broke (first 6 trials with a grasp on the plant)".to_string(), force_chart(results)),
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

/// "kind n, kind m" of whole counts ("none" when empty).
fn count_kinds(m: &std::collections::BTreeMap<String, u64>) -> String {
    if m.is_empty() {
        return "none".into();
    }
    m.iter().map(|(k, v)| format!("{k} {v}")).collect::<Vec<_>>().join(", ")
}

/// The pedicel force on the hand over time, from each trial's first loaded step, for the
/// first 6 trials that loaded a pedicel.
fn force_chart(results: &[HarvestTrial]) -> String {
    let series: Vec<(String, Vec<(f64, f64)>)> = results
        .iter()
        .filter(|t| !t.pedicel_force.is_empty())
        .take(6)
        .map(|t| {
            let t0 = t.pedicel_force[0].0;
            let label =
                format!("pedicel force of trial {} ({})", t.trial, t.detach_mode.as_deref().unwrap_or("no break"));
            (label, t.pedicel_force.iter().map(|&(x, y)| (x - t0, y)).collect())
        })
        .collect();
    line_chart(&series, "time from the first loaded step [s]", "pedicel force on the hand [N]")
}

/// One row per trial: how its pedicel broke, the force and moment then, and its damage.
fn detach_table(results: &[HarvestTrial]) -> String {
    let esc = |s: &str| s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;");
    let mut html = String::from(
        "<table><tr><th>trial</th><th>detach mode</th><th>detach force [N]</th><th>moment [N m]</th><th>damage</th></tr>",
    );
    for t in results {
        let damage: std::collections::BTreeMap<String, u64> =
            t.damage.iter().filter(|(_, v)| **v > 0).map(|(k, v)| (k.clone(), *v)).collect();
        html.push_str(&format!(
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            t.trial,
            esc(t.detach_mode.as_deref().unwrap_or("-")),
            t.detach_force.map_or("-".into(), |f| format!("{f:.2}")),
            t.detach_moment.map_or("-".into(), |f| format!("{f:.3}")),
            esc(&count_kinds(&damage)),
        ));
    }
    html.push_str("</table>");
    html
}

#[cfg(test)]
mod tests {
    use super::super::summary::summarize;
    use super::super::targets::eligible;
    use super::*;
    use crate::framework::TrialPlan;
    use agrisim_session::Scenario;
    use std::path::Path;

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
        let hand = [true, true, false];
        let (sa, sb) = (summarize(&s, plan, &a, &hand), summarize(&s, plan, &b, &hand));
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
        assert!(html.contains("the hand (a ripe fruit no wider than it opens)</th><td>1 / 2,"), "{html}");
    }
}
