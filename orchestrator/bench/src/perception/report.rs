//! report.html: the summary's tables and the overlay pictures (trials/NNNN.png: found fruit
//! green, missed magenta, false detections red crosses).

use super::summary::{PerceptionSummary, Rate};
use super::trial::PerceptionRecord;
use std::fmt::Write;

fn pct(r: &Rate) -> String {
    match r.rate {
        Some(v) => format!("{}/{} = {:.1} % [{:.3}, {:.3}]", r.found, r.total, 100.0 * v, r.wilson95[0], r.wilson95[1]),
        None => "-".into(),
    }
}

pub fn report_html(s: &PerceptionSummary, results: &[PerceptionRecord]) -> String {
    let mut h = String::new();
    let _ = write!(
        h,
        "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>agrisim perception benchmark</title>\
         <style>body{{font-family:sans-serif;margin:2em}}td,th{{padding:2px 10px;text-align:left}}img{{margin:4px;width:480px}}</style></head><body>\
         <h1>Perception: {} ({}), {} trials, {} frames, {} scenes, seed {}</h1>",
        s.scenario, s.environment, s.trials, s.frames, s.scenes, s.seed
    );
    h.push_str("<h2>Recall by ripeness stage</h2><table><tr><th>stage</th><th>found / fruit</th></tr>");
    for (k, r) in &s.recall_by_stage {
        let _ = write!(h, "<tr><td>{k}</td><td>{}</td></tr>", pct(r));
    }
    h.push_str("</table><h2>Ripe fruit (stages 5-6) by visibility</h2><table>");
    for (k, r) in &s.ripe_recall_by_visibility {
        let _ = write!(h, "<tr><td>{k}</td><td>{}</td></tr>", pct(r));
    }
    let _ = write!(
        h,
        "</table><h2>Precision and ripeness</h2><table><tr><td>precision</td><td>{}</td></tr>\
         <tr><td>ripe precision</td><td>{}</td></tr><tr><td>stage accuracy</td><td>{}</td></tr>\
         <tr><td>ripe / not ripe accuracy</td><td>{}</td></tr></table>",
        pct(&s.precision),
        pct(&s.ripe_precision),
        pct(&s.stage_accuracy),
        pct(&s.ripe_accuracy)
    );
    h.push_str("<h2>Misses (stage/visibility) and false detections (what they sit on)</h2><table>");
    for (k, n) in &s.missed_by_stage_visibility {
        let _ = write!(h, "<tr><td>missed {k}</td><td>{n}</td></tr>");
    }
    for (k, n) in &s.false_detections_by_cause {
        let _ = write!(h, "<tr><td>false: {k}</td><td>{n}</td></tr>");
    }
    let _ = write!(
        h,
        "</table><p>Judge geometry check (free fruit whose projected centre is on their own label): {}</p>",
        pct(&s.centre_on_label)
    );
    h.push_str("<h2>3-D centre error</h2><table><tr><th>distance</th><th>n</th><th>p50 mm</th><th>p95 mm</th><th>max mm</th></tr>");
    let o = |v: Option<f64>| v.map_or("-".into(), |v| format!("{v:.1}"));
    let within: Vec<(String, &super::summary::ErrorStats)> =
        s.centre_error_within_1m_by_stage.iter().map(|(k, e)| (format!("within 1 m, stage {k}"), e)).collect();
    let by_distance = s.centre_error_by_distance.iter().map(|(k, e)| (k.clone(), e));
    for (k, e) in by_distance.chain(within) {
        let _ = write!(
            h,
            "<tr><td>{k}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            e.n,
            o(e.p50_mm),
            o(e.p95_mm),
            o(e.max_mm)
        );
    }
    let sp = &s.centre_error_split_within_1m;
    let _ = write!(
        h,
        "</table><p>Within 1 m: along the ray median {} mm (signed), p95 {} mm; across it p95 {} mm.</p>",
        o(sp.ray_median_signed_mm),
        o(sp.ray_p95_mm),
        o(sp.lateral_p95_mm)
    );
    for (k, r) in &s.radius_error_within_1m {
        let _ = write!(
            h,
            "<p>Radius error within 1 m, {k} ({} fruit): median {} mm (signed), p95 {} mm.</p>",
            r.n,
            o(r.median_signed_mm),
            o(r.p95_mm)
        );
    }
    h.push_str("<h2>Frames</h2><p>Green: found; magenta: missed; red cross: false detection.</p>");
    for r in results {
        let png = format!("trials/{:04}.png", r.line.trial);
        let _ = write!(
            h,
            "<figure style=\"display:inline-block\"><img src=\"{png}\" alt=\"trial {}\" onerror=\"this.parentNode.style.display='none'\"><figcaption>trial {}: {}/{} found, {} false</figcaption></figure>",
            r.line.trial, r.line.trial, r.line.found, r.line.fruit, r.line.false_positives
        );
    }
    h.push_str("</body></html>\n");
    h
}
