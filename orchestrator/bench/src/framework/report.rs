//! report.html: a self-contained page (inline SVG, no scripts, no network) with the summary
//! table, a top-down map of the greenhouse and every trial's ground-truth path, and the
//! tables and charts the benchmarks share (rates by class, counts by category, histograms).

use agrisim_error::{Context, Result};
use agrisim_scene::{Kind, Layout, Object, Shape};
use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::Path;

/// One trial as drawn: its path, target and outcome.
pub struct TrialTrace {
    pub index: u64,
    pub success: bool,
    pub reason: String,
    pub target: [f64; 3],
    pub path: Vec<[f64; 2]>,
}

/// Every `every`-th point of `path`, and its last: what a trial keeps of its ground-truth path
/// for the map.
pub fn decimate(path: &[[f64; 2]], every: usize) -> Vec<[f64; 2]> {
    let mut v: Vec<[f64; 2]> = path.iter().step_by(every).copied().collect();
    if let Some(last) = path.last() {
        v.push(*last);
    }
    v
}

fn colour(kind: Kind) -> &'static str {
    match kind {
        Kind::Post | Kind::Wall => "#555",
        Kind::Gutter | Kind::Roof => "#bbb",
        Kind::HeatingPipe => "#c96",
        Kind::Stem | Kind::Leaf | Kind::Truss => "#4a8a3a",
        Kind::Fruit { .. } => "#d33",
        Kind::Obstacle => "#a0f",
        Kind::Robot => "#07c",
        Kind::Floor => "none",
    }
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// Writes the report. `summary` rows are (label, value) pairs shown in a table.
pub fn render(
    title: &str,
    summary: &[(String, String)],
    objects: &[Object],
    bounds: [f64; 4],
    trials: &[TrialTrace],
) -> String {
    render_with(title, summary, objects, bounds, trials, &[])
}

/// A histogram of `values` in bins `bin` wide, as an inline SVG bar chart labelled `label`.
pub fn bar_chart(values: &[f64], bin: f64, label: &str) -> String {
    if values.is_empty() {
        return "<p>no values</p>".into();
    }
    let max = values.iter().copied().fold(0.0, f64::max);
    let bins = ((max / bin).floor() as usize + 1).min(200);
    let mut counts = vec![0u64; bins];
    for v in values {
        counts[((v / bin).floor().max(0.0) as usize).min(bins - 1)] += 1;
    }
    let top = counts.iter().copied().max().unwrap_or(1).max(1) as f64;
    let (w, h, bw) = (60.0 + bins as f64 * 24.0, 200.0, 20.0);
    let mut svg = format!(r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w:.0}" height="{:.0}">"#, h + 40.0);
    for (i, &c) in counts.iter().enumerate() {
        let bh = c as f64 / top * h;
        let x = 40.0 + i as f64 * 24.0;
        let _ = write!(
            svg,
            r##"<rect x="{x:.1}" y="{:.1}" width="{bw}" height="{bh:.1}" fill="#4a7ab5"><title>{:.0}-{:.0}: {c}</title></rect>"##,
            h - bh,
            i as f64 * bin,
            (i + 1) as f64 * bin
        );
        if i % 2 == 0 {
            let _ = write!(svg, r#"<text x="{x:.1}" y="{:.0}" font-size="10">{:.0}</text>"#, h + 14.0, i as f64 * bin);
        }
    }
    let _ = write!(
        svg,
        r#"<text x="0" y="12" font-size="10">{}</text><text x="40" y="{:.0}" font-size="11">{}</text></svg>"#,
        top as u64,
        h + 34.0,
        escape(label)
    );
    svg
}

/// Series of (x, y) points as an inline SVG line chart, one coloured polyline each, titled
/// by its name; axes from 0 to the largest x and y, labelled `x_label` and `y_label`.
pub fn line_chart(series: &[(String, Vec<(f64, f64)>)], x_label: &str, y_label: &str) -> String {
    let points = series.iter().flat_map(|(_, s)| s.iter());
    let (xmax, ymax) = points.fold((0.0f64, 0.0f64), |(x, y), p| (x.max(p.0), y.max(p.1)));
    if series.iter().all(|(_, s)| s.is_empty()) || !(xmax > 0.0 && ymax > 0.0) {
        return "<p>no values</p>".into();
    }
    const COLOURS: [&str; 6] = ["#4a7ab5", "#c0504d", "#2e8b57", "#8064a2", "#d68a00", "#4bacc6"];
    let (w, h, left) = (480.0, 220.0, 40.0);
    let mut svg =
        format!(r#"<svg xmlns="http://www.w3.org/2000/svg" width="{:.0}" height="{:.0}">"#, w + left + 10.0, h + 40.0);
    let _ = write!(svg, r##"<rect x="{left}" y="0" width="{w}" height="{h}" fill="none" stroke="#999"/>"##);
    for (i, (name, s)) in series.iter().enumerate() {
        let pts: Vec<String> =
            s.iter().map(|&(x, y)| format!("{:.1},{:.1}", left + x / xmax * w, h - y / ymax * h)).collect();
        let _ = write!(
            svg,
            r#"<polyline points="{}" fill="none" stroke="{}" stroke-width="1.5"><title>{}</title></polyline>"#,
            pts.join(" "),
            COLOURS[i % COLOURS.len()],
            escape(name)
        );
    }
    let _ = write!(
        svg,
        r#"<text x="0" y="12" font-size="10">{ymax:.1}</text><text x="0" y="{h:.0}" font-size="10">0</text><text x="{:.0}" y="{:.0}" font-size="10">{xmax:.1}</text><text x="{left}" y="{:.0}" font-size="11">{}; {}</text></svg>"#,
        left + w - 20.0,
        h + 14.0,
        h + 34.0,
        escape(x_label),
        escape(y_label)
    );
    svg
}

/// A table of success rates: one row per (key, count, successes, Wilson 95 % interval), with
/// the fraction. `head` names the key, count and successes columns.
pub fn rate_table(head: [&str; 3], rows: impl IntoIterator<Item = (String, u64, u64, [f64; 2])>) -> String {
    let body: String = rows
        .into_iter()
        .map(|(k, n, ok, w)| {
            format!(
                "<tr><td>{}</td><td>{n}</td><td>{ok}</td><td>{:.3}</td><td>{}</td></tr>",
                escape(&k),
                ok as f64 / n.max(1) as f64,
                interval(w)
            )
        })
        .collect();
    let [k, n, ok] = head.map(escape);
    format!("<table><tr><th>{k}</th><th>{n}</th><th>{ok}</th><th>fraction</th><th>Wilson 95 %</th></tr>{body}</table>")
}

/// A table of counts by category (a failure taxonomy); `head` names the two columns.
pub fn count_table(head: [&str; 2], counts: &BTreeMap<String, u64>) -> String {
    let body: String = counts.iter().map(|(k, v)| format!("<tr><td>{}</td><td>{v}</td></tr>", escape(k))).collect();
    let [k, v] = head.map(escape);
    format!("<table><tr><th>{k}</th><th>{v}</th></tr>{body}</table>")
}

/// Means by kind as "kind 0.12, kind 0.03" ("none" when empty).
pub fn per_kind(means: &BTreeMap<String, f64>) -> String {
    if means.is_empty() {
        return "none".into();
    }
    means.iter().map(|(k, v)| format!("{k} {v:.2}")).collect::<Vec<_>>().join(", ")
}

/// A 95 % interval as "[lo, hi]", three decimals.
pub fn interval(w: [f64; 2]) -> String {
    format!("[{:.3}, {:.3}]", w[0], w[1])
}

/// An optional figure with one decimal, "-" when absent.
pub fn opt(v: Option<f64>) -> String {
    v.map_or("-".into(), |t| format!("{t:.1}"))
}

/// What the report's map shows: the rows, the headland and every path, with a margin (the
/// hall around them is mostly empty floor).
pub fn view_bounds(layout: &Layout, traces: &[TrialTrace]) -> [f64; 4] {
    let [hx0, hy0, hx1, hy1] = layout.headland;
    let mut b = [hx0, hy0, hx1, hy1];
    let mut grow = |x: f64, y: f64| {
        b = [b[0].min(x), b[1].min(y), b[2].max(x), b[3].max(y)];
    };
    for r in layout.rows.iter().filter(|r| r.active) {
        grow(r.x_start, r.y);
        grow(r.x_end, r.y);
    }
    for p in traces.iter().flat_map(|t| t.path.iter()) {
        grow(p[0], p[1]);
    }
    let m = 1.5;
    let [x0, y0, x1, y1] = layout.bounds;
    [(b[0] - m).max(x0), (b[1] - m).max(y0), (b[2] + m).min(x1), (b[3] + m).min(y1)]
}

/// Writes `html` to out/report.html.
pub fn write(out: &Path, html: &str) -> Result<()> {
    let rp = out.join("report.html");
    std::fs::write(&rp, html).context(|| rp.display().to_string())
}

/// [`render`] with extra sections (heading, HTML) after the map.
pub fn render_with(
    title: &str,
    summary: &[(String, String)],
    objects: &[Object],
    bounds: [f64; 4],
    trials: &[TrialTrace],
    sections: &[(String, String)],
) -> String {
    let [x0, y0, x1, y1] = bounds;
    let scale = 900.0 / (x1 - x0).max(y1 - y0).max(1e-6);
    let (w, h) = ((x1 - x0) * scale, (y1 - y0) * scale);
    // map frame: y up; SVG: y down.
    let px = |x: f64| (x - x0) * scale;
    let py = |y: f64| (y1 - y) * scale;
    let mut svg = String::new();
    let _ = write!(
        svg,
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="{w:.0}" height="{h:.0}" viewBox="0 0 {w:.1} {h:.1}" style="background:#f7f5ef">"##
    );
    for o in objects {
        let c = colour(o.kind);
        if c == "none" || matches!(o.kind, Kind::Gutter | Kind::Roof | Kind::Fruit { .. } | Kind::Leaf) {
            continue; // overhead or tiny: the top-down map shows what blocks the base
        }
        let [x, y, _] = o.placement.translation;
        match o.shape {
            Shape::Box { half } => {
                let [qx, qy, qz, qw] = o.placement.rotation;
                let yaw = (2.0 * (qw * qz + qx * qy)).atan2(1.0 - 2.0 * (qy * qy + qz * qz));
                let _ = write!(
                    svg,
                    r#"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="{c}" transform="rotate({:.2} {:.1} {:.1})"/>"#,
                    px(x - half[0]),
                    py(y + half[1]),
                    2.0 * half[0] * scale,
                    2.0 * half[1] * scale,
                    -yaw.to_degrees(),
                    px(x),
                    py(y)
                );
            }
            Shape::Cylinder { radius, .. } | Shape::Sphere { radius } => {
                let _ = write!(
                    svg,
                    r#"<circle cx="{:.1}" cy="{:.1}" r="{:.1}" fill="{c}"/>"#,
                    px(x),
                    py(y),
                    (radius * scale).max(0.6)
                );
            }
        }
    }
    for t in trials {
        let c = if t.success { "#1a7f37" } else { "#cf222e" };
        let pts: Vec<String> = t.path.iter().map(|p| format!("{:.1},{:.1}", px(p[0]), py(p[1]))).collect();
        let _ = write!(
            svg,
            r#"<polyline points="{}" fill="none" stroke="{c}" stroke-width="1.2" stroke-opacity="0.6"><title>trial {} {}</title></polyline>"#,
            pts.join(" "),
            t.index,
            escape(&t.reason)
        );
        let _ = write!(
            svg,
            r#"<circle cx="{:.1}" cy="{:.1}" r="3" fill="none" stroke="{c}" stroke-width="1.5"><title>target of trial {}</title></circle>"#,
            px(t.target[0]),
            py(t.target[1]),
            t.index
        );
    }
    svg.push_str("</svg>");
    let rows: String =
        summary.iter().map(|(k, v)| format!("<tr><th>{}</th><td>{}</td></tr>", escape(k), escape(v))).collect();
    let failures: String = trials
        .iter()
        .filter(|t| !t.success)
        .map(|t| format!("<li>trial {:04}: {}</li>", t.index, escape(&t.reason)))
        .collect();
    format!(
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{t}</title><style>body{{font-family:sans-serif;margin:2em}}table{{border-collapse:collapse}}th,td{{border:1px solid #ccc;padding:4px 10px;text-align:left}}</style></head>\n<body><h1>{t}</h1><table>{rows}</table><h2>Top-down map and trial paths</h2><p>Green: success, red: failure; circles: targets. Map frame x to the right, y up.</p>{svg}{extra}<h2>Failures</h2><ul>{failures}</ul></body></html>\n",
        t = escape(title),
        extra = sections.iter().map(|(h, body)| format!("<h2>{}</h2>{body}", escape(h))).collect::<String>()
    )
}

/// The per-scene section of a report (only when trials span more than one scene): each
/// scene's `outcome` count with its Wilson interval; the page's map is scene 0's.
pub fn per_scene_section(per_scene: &[super::scenes::SceneResult], outcome: &str) -> Option<(String, String)> {
    if per_scene.len() <= 1 {
        return None;
    }
    let scenes = per_scene.iter().map(|r| {
        let label = format!("{} (greenhouse seed {})", r.scene, r.scene_seed);
        (label, r.trials, r.successes, super::stats::wilson(r.successes, r.trials, super::stats::Z95))
    });
    let note = "<p>The map above is scene 0's; the trials of the other scenes are drawn on it.</p>";
    let mut title = format!("{outcome} per scene");
    title[..1].make_ascii_uppercase();
    Some((title, rate_table(["scene", "trials", outcome], scenes) + note))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_chart_draws_each_series_scaled_to_the_axes() {
        let series = vec![("a".to_string(), vec![(0.0, 0.0), (2.0, 10.0)]), ("b <x>".to_string(), vec![(1.0, 5.0)])];
        let svg = line_chart(&series, "t [s]", "F [N]");
        assert_eq!(svg.matches("<polyline").count(), 2);
        // x 0..2 -> 40..520, y 0..10 -> 220..0.
        assert!(svg.contains(r#"points="40.0,220.0 520.0,0.0""#), "{svg}");
        assert!(svg.contains(r#"points="280.0,110.0""#), "{svg}");
        assert!(svg.contains("<title>b &lt;x&gt;</title>"), "{svg}");
        assert_eq!(line_chart(&[], "t", "F"), "<p>no values</p>");
    }
}
