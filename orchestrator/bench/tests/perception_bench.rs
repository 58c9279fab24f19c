//! End to end: `agrisim bench perception` (through the framework, as the CLI runs it) on a
//! few trials of the sensor scenario at clear noon, with sane figures: ripe free fruit mostly
//! found, few false detections, centre errors of millimetres, overlay pictures written.

use agrisim_bench::framework::{OptionValue, OptionValues};
use agrisim_bench::perception::PerceptionBench;
use agrisim_bench::{registry, Exec, Job, TrialBenchmark, TrialPlan};
use agrisim_session::{RunOptions, Scenario};
use std::collections::BTreeMap;
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

#[test]
fn a_few_trials_at_noon_give_sane_figures() {
    let fmu_dir = root().join("target/fmu");
    assert!(fmu_dir.join("Camera.fmu").exists(), "no packed FMUs: run `target/release/agrisim fmu pack`");
    let dir = tempfile::tempdir().unwrap();
    let scenario = Scenario::load(&root().join("models/scenarios/sensors.toml")).unwrap();
    let run = RunOptions {
        fmu_dir,
        cache_dir: dir.path().join("cache"),
        seed: None,
        duration: None,
        fmu_overrides: BTreeMap::new(),
        fmu_log: None,
        record: None,
        nodes: Default::default(),
    };
    let mut options = OptionValues::defaults(PerceptionBench.options());
    options.set("environment", OptionValue::U64(1));
    options.set("overlays", OptionValue::U64(2));
    let out = dir.path().join("out");
    let job = Job { scenario, run, plan: TrialPlan { trials: 6, seed: 1, scenes: 2 }, options, out: out.clone() };
    let text = registry().run("perception", &job, false, Exec::InProcess, &mut |_, _| {}).unwrap();
    eprintln!("{text}");
    let s: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(s["errors"], 0, "{text}");
    assert!(s["frames"].as_u64().unwrap() >= 6, "{text}");
    // The judge's own geometry: free fruit project onto pixels labelled with their id (a
    // camera pose off by a few centimetres, or fruit paired with the wrong labels, fails it).
    let geometry = &s["centre_on_label"];
    assert!(geometry["total"].as_u64().unwrap() >= 10, "too few free fruit to check the judge: {text}");
    assert!(geometry["rate"].as_f64().unwrap() >= 0.9, "projected fruit centres off their labels: {text}");
    let causes = s["false_detections_by_cause"].as_object().unwrap();
    let fps: u64 = causes.values().map(|v| v.as_u64().unwrap()).sum();
    assert!(fps <= s["precision"]["total"].as_u64().unwrap(), "{text}");
    let free = &s["ripe_recall_by_visibility"]["free"];
    assert!(free["total"].as_u64().unwrap() >= 3, "too few ripe free fruit to judge: {text}");
    assert!(free["rate"].as_f64().unwrap() > 0.5, "recall of free ripe fruit: {text}");
    assert!(s["precision"]["rate"].as_f64().unwrap() > 0.8, "precision: {text}");
    let p50 = s["centre_error_by_distance"]["within_1m"]["p50_mm"].as_f64().unwrap();
    assert!(p50 > 0.0 && p50 < 15.0, "centre error p50 {p50} mm: {text}");
    // Radius against the colliders' (equatorial) radius: no bias of the fit beyond 3 mm (a
    // sphere fitted to the oblate fruit read about 2 mm small).
    let radius = &s["radius_error_within_1m"]["ripe"];
    assert!(radius["n"].as_u64().unwrap() >= 3, "{text}");
    let bias = radius["median_signed_mm"].as_f64().unwrap();
    assert!(bias.abs() < 3.0, "radius bias {bias} mm: {text}");
    assert!(s["ripe_accuracy"]["rate"].as_f64().unwrap() > 0.7, "ripeness: {text}");
    assert!(out.join("trials/0000.png").exists() && out.join("report.html").exists());
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(html.contains("trials/0000.png") && html.contains("Recall by ripeness stage"));
    assert!(html.contains("Radius error within 1 m, ripe"), "report.html gives the radius error");
}
