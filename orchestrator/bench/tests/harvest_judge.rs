//! The harvest judge shares nothing with the harvest node: it reads the node's messages
//! (/harvest/status, /harvest/plans) and the world's ground truth. A scripted node that
//! publishes the same messages is judged the same way, and ground truth has the last word.
//!
//! By sight, no node can read ground truth: the bus is sealed, and a node that reads a
//! ground-truth topic fails its trial.
//!
//! Needs the packed FMUs (target/fmu, written by `agrisim fmu pack`, which scripts/setup runs).

use agrisim_bench::framework::{OptionValues, Trial};
use agrisim_bench::harvest::{builtin_node, run_with, HarvestSetup, HarvestTrial, TRIAL_TIMEOUT};
use agrisim_bench::trial_seed;
use agrisim_bus::{Bus, Node};
use agrisim_error::Result;
use agrisim_harvest::{topics, HarvestNode, Task};
use agrisim_msgs::agrisim::{HarvestStatus, PlanResult};
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::std_msgs::Header;
use agrisim_msgs::Message;
use agrisim_session::{RunOptions, Scenario};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

#[derive(Clone)]
enum Said {
    Status(HarvestStatus),
    Plan(PlanResult),
}

/// Publishes a fixed script of harvest messages at their times, and nothing else: no arm,
/// base or gripper ever moves.
struct Scripted {
    script: Vec<(i64, Said)>,
}

impl Node for Scripted {
    fn name(&self) -> &str {
        "scripted_harvest"
    }

    fn step(&mut self, t_ns: i64, bus: &mut Bus) -> Result<()> {
        while self.script.first().is_some_and(|(t, _)| *t <= t_ns) {
            match self.script.remove(0).1 {
                Said::Status(m) => bus.publish(topics::STATUS, t_ns, &m),
                Said::Plan(m) => bus.publish(topics::PLANS, t_ns, &m),
            }
        }
        Ok(())
    }
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().expect("workspace root")
}

struct Bench {
    scenario: Scenario,
    options: RunOptions,
    setup: HarvestSetup,
    dir: tempfile::TempDir,
}

impl Bench {
    fn new() -> Bench {
        let mut b = Bench::of("harvest.toml");
        // The judge's checks need a harvest that succeeds: a fruit in plain view.
        b.scenario.harvest.visibility = vec!["free".into()];
        b.setup = HarvestSetup::new(&b.scenario).unwrap();
        b
    }

    /// The scenario `models/scenarios/<file>` as it is.
    fn of(file: &str) -> Bench {
        let fmu_dir = root().join("target/fmu");
        assert!(
            fmu_dir.join("Greenhouse.fmu").exists(),
            "{} has no packed FMUs: run `target/release/agrisim fmu pack` (scripts/setup does)",
            fmu_dir.display()
        );
        let dir = tempfile::tempdir().unwrap();
        let scenario = Scenario::load(&root().join("models/scenarios").join(file)).unwrap();
        let options = RunOptions {
            fmu_dir,
            cache_dir: dir.path().join("cache"),
            seed: None,
            duration: None,
            fmu_overrides: BTreeMap::new(),
            fmu_log: None,
            record: None,
            nodes: Default::default(),
        };
        let setup = HarvestSetup::new(&scenario).unwrap();
        Bench { scenario, options, setup, dir }
    }

    fn trial(&self, name: &str, node: &dyn Fn(Task, u64) -> Box<dyn Node>, timeout: f64) -> HarvestTrial {
        let options = OptionValues::default();
        let t = Trial {
            scenario: &self.scenario,
            run: &self.options,
            setup: &self.setup,
            options: &options,
            index: 0,
            scene: 0,
            seed: trial_seed(1, 0),
        };
        run_with(&t, &self.dir.path().join(format!("{name}.mcap")), node, timeout).unwrap()
    }
}

fn header(t_ns: i64) -> Header {
    Header { stamp: Time::from_nanos(t_ns), frame_id: "map".into() }
}

fn status(t_ns: i64, stage: &str, outcome: &str, category: &str, detail: &str) -> (i64, Said) {
    let m = HarvestStatus {
        header: header(t_ns),
        stage: stage.into(),
        target_id: 0,
        target_name: String::new(),
        outcome: outcome.into(),
        failure_category: category.into(),
        detail: detail.into(),
        plans: 0,
    };
    (t_ns, Said::Status(m))
}

fn plan(t_ns: i64, ok: bool, optional: bool) -> (i64, Said) {
    let m = PlanResult {
        header: header(t_ns),
        stage: "pre_grasp".into(),
        arm: "left".into(),
        kind: "free".into(),
        ok,
        optional,
        detail: if ok { String::new() } else { "no path".into() },
        planning_time: 0.004,
    };
    (t_ns, Said::Plan(m))
}

/// The harvest messages a recorded trial holds, at their log times.
fn harvest_messages(mcap: &Path) -> Vec<(i64, Said)> {
    let bytes = std::fs::read(mcap).unwrap();
    let mut out = vec![];
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        let t = m.log_time as i64;
        match m.channel.topic.as_str() {
            topics::STATUS => out.push((t, Said::Status(HarvestStatus::from_cdr(&m.data).unwrap()))),
            topics::PLANS => out.push((t, Said::Plan(PlanResult::from_cdr(&m.data).unwrap()))),
            _ => {}
        }
    }
    out
}

#[test]
fn a_scripted_node_is_judged_from_its_messages_and_the_ground_truth() {
    let b = Bench::new();

    // The built-in node harvests the fruit; a node replaying its messages, moving nothing,
    // is judged on the same plans, and the world says the fruit is still on the plant.
    let real = b.trial("builtin", &builtin_node, TRIAL_TIMEOUT);
    assert_eq!(real.outcome, "success", "{real:?}");
    assert!(real.plans > 0 && real.planning_ok);
    let said = harvest_messages(&b.dir.path().join("builtin.mcap"));
    assert_eq!(said.iter().filter(|(_, s)| matches!(s, Said::Plan(_))).count(), real.plans);
    let replay = b.trial("replay", &|_, _| Box::new(Scripted { script: said.clone() }), TRIAL_TIMEOUT);
    assert_eq!(replay.plans, real.plans);
    assert_eq!(replay.planning_times.len(), real.plans);
    assert!(replay.planning_ok);
    assert_eq!(replay.failure.as_deref(), Some("placement"), "{replay:?}");
    assert!(replay.detail.contains("world has not placed"), "{}", replay.detail);
    assert_eq!(replay.placed_count, 0);
    assert_eq!(replay.sim_time, real.sim_time, "the outcome is judged at the instant it is published");

    // A failure report is taken as the category and stage the node names. A failed plan
    // with a fallback does not fail planning, but a trial that ends (here at the grasp)
    // before asking for every plan leaves planning undecided; a failed required plan fails it.
    // A failed pre-grasp plan with a fallback is a fruit declined (by sight: another taken).
    let declined = {
        let (t, Said::Plan(mut m)) = plan(550_000_000, false, true) else { unreachable!() };
        m.kind = "pregrasp".into();
        (t, Said::Plan(m))
    };
    let grasp = b.trial(
        "grasp",
        &|_, _| {
            Box::new(Scripted {
                script: vec![
                    plan(500_000_000, false, true),
                    declined.clone(),
                    status(1_000_000_000, "grasp", "failure", "grasp", "closed on nothing"),
                ],
            })
        },
        10.0,
    );
    assert_eq!(
        (grasp.failure.as_deref(), grasp.failed_stage.as_deref(), grasp.detail.as_str()),
        (Some("grasp"), Some("grasp"), "closed on nothing")
    );
    assert!(!grasp.planning_ok && grasp.planning == "not_reached" && grasp.plans == 2);
    assert_eq!(grasp.declined, 1, "only the optional pre-grasp failure is a fruit declined");
    let planning = b.trial(
        "planning",
        &|_, _| {
            Box::new(Scripted {
                script: vec![
                    plan(500_000_000, true, false),
                    plan(600_000_000, false, false),
                    status(600_000_000, "approach", "failure", "planning", "no IK"),
                ],
            })
        },
        10.0,
    );
    assert_eq!(
        (planning.failure.as_deref(), planning.plans, planning.planning_ok, planning.planning.as_str()),
        (Some("planning"), 2, false, "failed")
    );

    // A node that says nothing times out.
    let silent = b.trial("silent", &|_, _| Box::new(Scripted { script: vec![] }), 1.0);
    assert_eq!((silent.failure.as_deref(), silent.plans, silent.time_to_harvest), (Some("timeout"), 0, None));
    assert!((silent.sim_time - 1.0).abs() < 1e-9, "{}", silent.sim_time);
}

/// Harvest by sight: the task is a region, the node finds its fruit with the perception node
/// and plans in the mapping node's scene, all under the ground-truth seal; the judge finds the
/// fruit it placed from the world. A node that reads ground truth fails the trial.
#[test]
fn a_harvest_by_sight_is_sealed_from_ground_truth() {
    let b = Bench::of("harvest_sight.toml");
    assert!(b.scenario.harvest.sight);
    // The ground-truth node, in a sight trial: it asks the world for its target.
    let cheat = b.trial("cheat", &|_, seed| Box::new(HarvestNode::new(0, seed)), 10.0);
    assert_eq!(cheat.failure.as_deref(), Some("error"), "{cheat:?}");
    assert!(cheat.detail.contains("node harvest read the ground-truth topic /target_fruit"), "{}", cheat.detail);
    assert!(cheat.sim_time < 1.0, "stopped at its first read, not at {} s", cheat.sim_time);

    // The built-in node by sight, seed 1 trial 0 (deterministic): it picks a ripe fruit of
    // its region, placed within 15 mm by perception, and the world has it in the box.
    let t = b.trial("sight", &builtin_node, TRIAL_TIMEOUT);
    assert!(t.sight && t.region.is_some());
    assert_eq!(t.outcome, "success", "{t:?}");
    let id = t.chosen_id.expect("the node named its target");
    let (stage, c) = (b.setup.fruit[&id].stage, b.setup.fruit[&id].center);
    let r = t.region.unwrap();
    assert!(
        stage >= 5 && (0..3).all(|k| r[k][0] <= c[k] && c[k] <= r[k][1]),
        "fruit {id} stage {stage} at {c:?}, region {r:?}"
    );
    assert!(t.target_error_mm.unwrap() < 15.0, "{:?}", t.target_error_mm);
    // The seeing nodes charged their compute (their outputs waited for it).
    assert!(t.perception_time > 1.0 && t.mapping_time > 1.0, "{} {}", t.perception_time, t.mapping_time);
}
