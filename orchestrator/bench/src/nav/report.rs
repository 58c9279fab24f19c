//! report.html of the nav benchmark: the rates, per-scene results, failure taxonomy, a
//! histogram of the time to goal, and scene 0's map with every trial's ground-truth path.

use super::setup::NavSetup;
use super::summary::NavSummary;
use super::trial::NavRecord;
use crate::framework::report::{
    bar_chart, count_table, interval, opt, per_scene_section, render_with, view_bounds, TrialTrace,
};

/// The report page: figures the seed determines only (the wall-clock ones are in
/// summary.json), so the same seed gives the same page. Drawn on `setup`'s map (scene 0).
pub fn report_html(setup: &NavSetup, sum: &NavSummary, records: &[NavRecord]) -> String {
    let traces: Vec<TrialTrace> = records
        .iter()
        .map(|r| TrialTrace {
            index: r.trial.trial,
            success: r.trial.outcome == "success",
            reason: r.trial.reason.clone().unwrap_or_else(|| "success".into()),
            target: r.trial.target,
            path: r.path.clone(),
        })
        .collect();
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
    sections.extend(per_scene_section(&sum.per_scene, "reached"));
    let times: Vec<f64> = records.iter().filter_map(|r| r.trial.time_to_goal).collect();
    sections.extend([
        ("Failure taxonomy (trials not reached)".to_string(), count_table(["reason", "trials"], &sum.failures)),
        ("Time to goal (successful trials, simulated)".to_string(), bar_chart(&times, 5.0, "time to goal [s]")),
    ]);
    render_with(
        &format!("agrisim nav benchmark: {}", sum.scenario),
        &rows,
        &setup.objects,
        view_bounds(&setup.layout, &traces),
        &traces,
        &sections,
    )
}
