//! The navigator's global planner is chosen by the scenario's `[nav] planner` key alone: the
//! open-field scenario (models/scenarios/open_field.toml) runs a nav trial with the
//! straight-line planner, which publishes straight plans, and the same scenario text with
//! `planner = "astar"` runs it with A*; both reach the target. An unknown name is refused
//! before any trial, naming the file, the key and the names allowed.
//!
//! The trials need the packed FMUs (target/fmu, written by `agrisim fmu pack`, which
//! scripts/setup runs).

use agrisim_bench::framework::{OptionValues, Trial};
use agrisim_bench::nav::{trial, NavSetup, NavTrial};
use agrisim_bench::trial_seed;
use agrisim_msgs::nav_msgs::Path as PathMsg;
use agrisim_msgs::Message;
use agrisim_session::{RunOptions, Scenario};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().expect("workspace root")
}

fn open_field() -> (PathBuf, String) {
    let path = root().join("models/scenarios/open_field.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    (path, text)
}

/// The open-field scenario with its `[nav] planner` line set to `planner`, nothing else changed.
fn with_planner(planner: &str) -> Scenario {
    let (path, text) = open_field();
    let line = "\nplanner = \"straight_line\"\n";
    assert_eq!(text.matches(line).count(), 1, "{} should set the planner once", path.display());
    Scenario::parse(&text.replace(line, &format!("\nplanner = \"{planner}\"\n")), &path).unwrap()
}

/// Trial 0 (master seed 1) of `s`, recorded into `dir`: its result and every /plan published.
fn run_trial(s: &Scenario, dir: &Path, name: &str) -> (NavTrial, Vec<PathMsg>) {
    let fmu_dir = root().join("target/fmu");
    assert!(
        fmu_dir.join("Greenhouse.fmu").exists(),
        "{} has no packed FMUs: run `target/release/agrisim fmu pack` (scripts/setup does)",
        fmu_dir.display()
    );
    let run = RunOptions {
        fmu_dir,
        cache_dir: dir.join("cache"),
        seed: None,
        duration: None,
        fmu_overrides: BTreeMap::new(),
        fmu_log: None,
        record: None,
        nodes: Default::default(),
    };
    let setup = NavSetup::new(s).unwrap();
    let options = OptionValues::default();
    let t =
        Trial { scenario: s, run: &run, setup: &setup, options: &options, index: 0, scene: 0, seed: trial_seed(1, 0) };
    let mcap = dir.join(format!("{name}.mcap"));
    let record = trial::run(&t, &mcap).unwrap();
    let bytes = std::fs::read(&mcap).unwrap();
    let plans = mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(|m| m.unwrap())
        .filter(|m| m.channel.topic == agrisim_nav::topics::PLAN)
        .map(|m| PathMsg::from_cdr(&m.data).unwrap())
        .collect();
    (record.trial, plans)
}

/// The largest distance of a plan's points from the line through its first and last [m].
fn off_line(plan: &PathMsg) -> f64 {
    let p: Vec<(f64, f64)> = plan.poses.iter().map(|q| (q.pose.position.x, q.pose.position.y)).collect();
    let (a, b) = (p[0], p[p.len() - 1]);
    let len = (b.0 - a.0).hypot(b.1 - a.1);
    p.iter().map(|q| ((q.0 - a.0) * (b.1 - a.1) - (q.1 - a.1) * (b.0 - a.0)).abs() / len).fold(0.0, f64::max)
}

#[test]
fn the_scenario_key_alone_swaps_the_global_planner_in_an_open_field() {
    let dir = tempfile::tempdir().unwrap();
    let straight = with_planner("straight_line");
    let (t, plans) = run_trial(&straight, dir.path(), "straight_line");
    println!("straight_line: {t:?}, {} plans", plans.len());
    assert_eq!((t.outcome.as_str(), t.reason.as_deref()), ("success", None), "{t:?}");
    assert!(!plans.is_empty() && plans.iter().all(|p| p.poses.len() >= 2), "{} plans", plans.len());
    for p in &plans {
        assert!(off_line(p) < 1e-9, "a straight-line plan bends by {} m", off_line(p));
        let end = &p.poses[p.poses.len() - 1].pose.position;
        assert!((end.x - t.target[0]).hypot(end.y - t.target[1]) < 1e-9, "the plan ends at ({}, {})", end.x, end.y);
    }

    let astar = with_planner("astar");
    let (a, plans) = run_trial(&astar, dir.path(), "astar");
    println!("astar: {a:?}, {} plans", plans.len());
    assert_eq!((a.outcome.as_str(), a.reason.as_deref()), ("success", None), "{a:?}");
    // The same trial (same target), planned by the other planner: the scenario key is the
    // only difference, and A*'s plan, which keeps out of the walls' inflation, bends.
    assert_eq!(a.target, t.target);
    let bend = plans.iter().map(off_line).fold(0.0, f64::max);
    println!("A*'s plans bend up to {bend:.3} m off their chords");
    assert!(bend > 0.05, "A* planned straight lines: was the planner swapped?");
}

#[test]
fn an_unknown_planner_or_controller_is_refused_naming_the_file_the_key_and_the_choices() {
    let (path, text) = open_field();
    let s =
        Scenario::parse(&text.replace("\nplanner = \"straight_line\"\n", "\nplanner = \"a_star\"\n"), &path).unwrap();
    let e = NavSetup::new(&s).err().expect("an unknown planner is an error").to_string();
    assert!(e.contains(&path.display().to_string()), "{e}");
    assert!(e.contains("[nav] planner = \"a_star\" is unknown; allowed: \"astar\", \"straight_line\""), "{e}");
    let s = Scenario::parse(&text.replace("[nav]\n", "[nav]\ncontroller = \"teb\"\n"), &path).unwrap();
    let e = NavSetup::new(&s).err().expect("an unknown controller is an error").to_string();
    assert!(e.contains("[nav] controller = \"teb\" is unknown; allowed: \"dwa\""), "{e}");
}
