//! A benchmark added through the registry alone is a `bench` subcommand with its options and
//! runs by name through the dispatch the CLI and Python use (whole, resumed, or a trial at a
//! time as a worker runs it), with the same files every way.
//!
//! The test benchmark flips seeded coins: each trial publishes its flips on /coin into its
//! MCAP, and the judge counts heads from the recording, as judges read messages.

use agrisim_bench::cli::{self, TrialArgs};
use agrisim_bench::framework::{OptionSpec, OptionValue, OptionValues, Trial, TrialBenchmark, Whole};
use agrisim_bench::{Exec, Job, Registry};
use agrisim_bus::Recorder;
use agrisim_error::{err, Result};
use agrisim_math::Rng;
use agrisim_msgs::std_msgs::Float64;
use agrisim_msgs::Message;
use agrisim_session::{RunOptions, Scenario};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

struct Coin;

#[derive(Serialize, Deserialize)]
struct Flips {
    trial: u64,
    seed: u64,
    heads: u64,
    /// More heads than tails.
    success: bool,
    error: Option<String>,
}

#[derive(Serialize)]
struct CoinSummary {
    trials: u64,
    successes: u64,
    heads: u64,
}

const OPTIONS: [OptionSpec; 2] = [
    OptionSpec { name: "flips", help: "Flips per trial", default: OptionValue::U64(3) },
    OptionSpec { name: "p-heads", help: "Probability of heads", default: OptionValue::F64(0.5) },
];

/// The /coin values recorded in `mcap`.
fn recorded(mcap: &Path) -> Vec<f64> {
    let bytes = std::fs::read(mcap).unwrap();
    mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(|m| m.unwrap())
        .filter(|m| m.channel.topic == "/coin")
        .map(|m| Float64::from_cdr(&m.data).unwrap().data)
        .collect()
}

impl TrialBenchmark for Coin {
    type Setup = ();
    type Record = Flips;
    type Summary = CoinSummary;

    fn name(&self) -> &'static str {
        "coin"
    }
    fn about(&self) -> &'static str {
        "Seeded coin flips (a test benchmark)"
    }
    fn default_scenario(&self) -> &'static str {
        "default"
    }
    fn options(&self) -> &'static [OptionSpec] {
        &OPTIONS
    }
    fn check(&self, o: &OptionValues) -> Result<()> {
        let p = o.f64("p-heads");
        if (0.0..=1.0).contains(&p) {
            Ok(())
        } else {
            Err(err!("--p-heads {p}: a probability is in [0, 1]"))
        }
    }
    fn setup(&self, _: &Scenario, _: &OptionValues) -> Result<()> {
        Ok(())
    }
    fn trial(&self, t: &Trial<()>, mcap: &Path) -> Result<Flips> {
        let mut rng = Rng::new(t.seed);
        let mut rec = Recorder::create(mcap)?;
        for k in 0..t.options.u64("flips") {
            rec.publish("/coin", k as i64 * 1_000_000, &Float64 { data: rng.uniform() })?;
        }
        rec.finish()?;
        let p = t.options.f64("p-heads");
        let flips = recorded(mcap);
        let heads = flips.iter().filter(|&&u| u < p).count() as u64;
        Ok(Flips { trial: t.index, seed: t.seed, heads, success: 2 * heads > flips.len() as u64, error: None })
    }
    fn failed(&self, t: &Trial<()>, reason: String) -> Flips {
        Flips { trial: t.index, seed: t.seed, heads: 0, success: false, error: Some(reason) }
    }
    fn summarize(&self, _: &Whole<()>, results: &[Flips]) -> CoinSummary {
        CoinSummary {
            trials: results.len() as u64,
            successes: results.iter().filter(|r| r.success).count() as u64,
            heads: results.iter().map(|r| r.heads).sum(),
        }
    }
    fn report(&self, _: &Whole<()>, s: &CoinSummary, _: &[Flips]) -> Result<String> {
        Ok(format!("<html><body>{} of {} trials had more heads</body></html>\n", s.successes, s.trials))
    }
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn with_coin() -> Registry {
    agrisim_bench::registry().with(&Coin)
}

/// `bench <args>` parsed as the CLI parses it, as a job into `out`.
fn job(registry: &Registry, out: &Path, args: &[&str]) -> (&'static str, TrialArgs, Job) {
    let mut argv = vec!["bench"];
    argv.extend(args);
    let out_s = out.to_str().unwrap();
    argv.extend(["--out", out_s]);
    let m = cli::command(registry, &|c| c).try_get_matches_from(argv).unwrap();
    let (b, a, options) = cli::parse(registry, &m).unwrap();
    let scenario = Scenario::load(&root().join(cli::default_scenario_path(b))).unwrap();
    let run = RunOptions {
        fmu_dir: out.join("no-fmus"),
        cache_dir: out.join("cache"),
        seed: None,
        duration: None,
        fmu_overrides: Default::default(),
        fmu_log: None,
        record: None,
        nodes: Default::default(),
    };
    let plan = a.plan();
    (b.name(), a, Job { scenario, run, plan, options, out: out.to_path_buf() })
}

fn files(out: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<(String, Vec<u8>)> = ["trials.jsonl", "summary.json", "report.html"]
        .iter()
        .map(|f| (f.to_string(), std::fs::read(out.join(f)).unwrap()))
        .collect();
    for e in std::fs::read_dir(out.join("trials")).unwrap() {
        let p = e.unwrap().path();
        v.push((p.file_name().unwrap().to_string_lossy().into(), std::fs::read(&p).unwrap()));
    }
    v.sort();
    v
}

#[test]
fn a_benchmark_added_to_the_registry_is_listed_and_runs_by_name() {
    let registry = with_coin();
    let help = cli::command(&registry, &|c| c).render_help().to_string();
    for name in ["nav", "harvest", "row", "coin"] {
        assert!(help.lines().any(|l| l.trim_start().starts_with(name)), "{name} not in\n{help}");
    }
    assert!(help.contains("Seeded coin flips (a test benchmark)"), "{help}");
    assert!(!cli::command(&agrisim_bench::registry(), &|c| c).render_help().to_string().contains("coin"));
    let mut coin = cli::command(&registry, &|c| c).find_subcommand("coin").unwrap().clone();
    let coin_help = coin.render_long_help().to_string();
    assert!(coin_help.contains("--flips") && coin_help.contains("[default: 3]"), "{coin_help}");
    assert!(coin_help.contains("--trials") && coin_help.contains("models/scenarios/default.toml"), "{coin_help}");

    // The whole benchmark, through the registry's dispatch.
    let dir = tempfile::tempdir().unwrap();
    let whole = dir.path().join("whole");
    let (name, a, j) = job(&registry, &whole, &["coin", "--trials", "2", "--seed", "7", "--flips", "5"]);
    assert_eq!((name, a.trials, a.seed, j.options.u64("flips"), j.options.f64("p-heads")), ("coin", 2, 7, 5, 0.5));
    assert_eq!(a.jobs, None, "--jobs defaults to the core count when the run starts");
    let summary: serde_json::Value =
        serde_json::from_str(&registry.run(name, &j, false, Exec::InProcess, &mut |_, _| {}).unwrap()).unwrap();
    let lines: Vec<serde_json::Value> = std::fs::read_to_string(whole.join("trials.jsonl"))
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 2);
    assert_eq!(summary["trials"], 2);
    let successes = lines.iter().filter(|l| l["success"] == true).count();
    assert_eq!(summary["successes"], successes as u64);
    for (i, l) in lines.iter().enumerate() {
        assert_eq!(l["trial"], i as u64);
        assert_eq!(l["seed"], agrisim_bench::trial_seed(7, i as u64));
        let flips = recorded(&whole.join(format!("trials/{i:04}.mcap")));
        assert_eq!(flips.len(), 5, "--flips reached the trial");
        assert_eq!(l["heads"], flips.iter().filter(|&&u| u < 0.5).count() as u64);
    }
    assert_eq!(
        std::fs::read_to_string(whole.join("report.html")).unwrap(),
        format!("<html><body>{successes} of 2 trials had more heads</body></html>\n")
    );

    // A trial at a time, as worker processes (or Ray tasks) run them, then summed up by a
    // resumed run: the same files.
    let apart = dir.path().join("apart");
    let (_, _, j2) = job(&registry, &apart, &["coin", "--trials", "2", "--seed", "7", "--flips", "5"]);
    for i in [1, 0] {
        registry.run_one("coin", &j2, i).unwrap();
    }
    registry.run("coin", &j2, true, Exec::InProcess, &mut |_, _| {}).unwrap();
    assert_eq!(files(&whole), files(&apart));
    let e = registry.run_one("coin", &j2, 2).unwrap_err().to_string();
    assert!(e.contains("trial 2 is not among the 2 trials"), "{e}");

    // A worker process is started with the job's own arguments.
    let argv: Vec<String> = j.worker_args("coin", 1).iter().map(|a| a.to_string_lossy().into()).collect();
    let m = cli::command(&registry, &|c| c)
        .try_get_matches_from(std::iter::once("bench".to_string()).chain(argv.into_iter().skip(1)));
    let (b, wa, wo) = cli::parse(&registry, &m.unwrap()).unwrap();
    assert_eq!((b.name(), wa.worker_trial, wa.trials, wa.seed, wo), ("coin", Some(1), 2, 7, j.options.clone()));

    // The benchmark's own check and the registry's names.
    let (_, _, bad) = job(&registry, &dir.path().join("bad"), &["coin", "--p-heads", "1.5"]);
    let e = registry.run("coin", &bad, false, Exec::InProcess, &mut |_, _| {}).unwrap_err().to_string();
    assert!(e.contains("--p-heads 1.5"), "{e}");
    let e = registry.run("dice", &j, false, Exec::InProcess, &mut |_, _| {}).unwrap_err().to_string();
    assert!(e.contains("unknown benchmark 'dice' (known: nav, harvest, row, perception, coin)"), "{e}");
}

#[test]
fn the_built_in_benchmarks_and_their_options() {
    let registry = agrisim_bench::registry();
    assert_eq!(registry.names(), ["nav", "harvest", "row", "perception"]);
    let mut row = cli::command(&registry, &|c| c).find_subcommand("row").unwrap().clone();
    let help = row.render_long_help().to_string();
    assert!(help.contains("--length") && help.contains("[default: 2]"), "{help}");
    let dir = tempfile::tempdir().unwrap();
    let (_, _, j) = job(&registry, dir.path(), &["row", "--length", "2.5"]);
    assert_eq!(j.options.f64("length"), 2.5);
    // By sight by default (harvest.toml is the ground-truth mode).
    assert!(j.scenario.path.ends_with("models/scenarios/harvest_sight.toml"));
    let m = cli::command(&registry, &|c| c).try_get_matches_from(["bench", "nav", "--length", "2", "--out", "x"]);
    assert!(m.is_err(), "--length is the row benchmark's option only");
    let m = cli::command(&registry, &|c| c).try_get_matches_from([
        "bench",
        "nav",
        "--jobs",
        "2",
        "--in-process",
        "--out",
        "x",
    ]);
    assert!(m.is_err(), "--jobs and --in-process conflict");
}
