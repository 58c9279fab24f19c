//! The many-trial benchmarks for Python: the same code, files and statistics as
//! `agrisim bench nav|harvest`, and one trial at a time (`run_trial`) for spreading trials over
//! other executors (Ray tasks). Trial i depends only on (seed, i), so every backend writes the
//! same trials.

use crate::paths::{agrisim_bin, fmu_dirs, scenario_path};
use crate::{py_err, OnThisThread};
use agrisim_bench::trials::{Exec, TrialPlan};
use agrisim_session::{Profile, RunOptions, Scenario};
use pyo3::prelude::*;
use std::path::{Path, PathBuf};

#[derive(Clone, Copy)]
enum Kind {
    Nav,
    Harvest,
}

impl Kind {
    fn parse(s: &str) -> PyResult<Kind> {
        match s {
            "nav" => Ok(Kind::Nav),
            "harvest" => Ok(Kind::Harvest),
            other => Err(py_err(format!("unknown benchmark '{other}' (nav or harvest)"))),
        }
    }
    fn name(self) -> &'static str {
        match self {
            Kind::Nav => "nav",
            Kind::Harvest => "harvest",
        }
    }
    fn default_scenario(self) -> &'static str {
        match self {
            Kind::Nav => "default",
            Kind::Harvest => "harvest",
        }
    }
}

struct Job {
    kind: Kind,
    scenario: Scenario,
    options: RunOptions,
    plan: TrialPlan,
    out: PathBuf,
}

fn job(
    kind: Kind,
    scenario: Option<PathBuf>,
    trials: u64,
    seed: u64,
    scenes: u64,
    record: Option<String>,
    out: PathBuf,
) -> PyResult<Job> {
    if scenes == 0 {
        return Err(py_err("scenes must be at least 1"));
    }
    let path = scenario_path(scenario.unwrap_or_else(|| kind.default_scenario().into()));
    let scenario = Scenario::load(&path).map_err(py_err)?;
    let (fmu_dir, cache_dir) = fmu_dirs();
    let record = record.map(|r| r.parse::<Profile>().map_err(py_err)).transpose()?;
    let options = RunOptions {
        fmu_dir,
        cache_dir,
        seed: None,
        duration: None,
        fmu_overrides: Default::default(),
        fmu_log: None,
        record,
        nodes: Default::default(),
    };
    Ok(Job { kind, scenario, options, plan: TrialPlan { trials, seed, scenes }, out })
}

/// A worker process for trial `i`: the CLI with the same benchmark arguments.
fn worker(j: &Job, i: u64) -> std::process::Command {
    let mut c = std::process::Command::new(agrisim_bin());
    c.args(["bench", j.kind.name(), "--scenario"]).arg(&j.scenario.path);
    c.args([
        "--trials",
        &j.plan.trials.to_string(),
        "--seed",
        &j.plan.seed.to_string(),
        "--scenes",
        &j.plan.scenes.to_string(),
    ]);
    c.arg("--fmu-dir").arg(&j.options.fmu_dir).arg("--cache-dir").arg(&j.options.cache_dir);
    if let Some(p) = j.options.record {
        c.args(["--record", p.name()]);
    }
    c.arg("--out").arg(&j.out).args(["--worker-trial", &i.to_string()]);
    c.stdin(std::process::Stdio::null()).stdout(std::process::Stdio::null());
    c
}

fn run_bench(py: Python<'_>, j: Job, jobs: usize, resume: bool) -> PyResult<String> {
    let mut j = OnThisThread(j);
    py.detach(move || {
        let j = j.get();
        let command = |i: u64| worker(j, i);
        let exec = if jobs == 0 { Exec::InProcess } else { Exec::Workers { jobs, command: &command } };
        let json = match j.kind {
            Kind::Nav => {
                agrisim_bench::nav::bench_nav(&j.scenario, &j.options, j.plan, &j.out, resume, exec, |_, _| {})
                    .map(|s| serde_json::to_string(&s))
            }
            Kind::Harvest => {
                agrisim_bench::harvest::bench_harvest(&j.scenario, &j.options, j.plan, &j.out, resume, exec, |_, _| {})
                    .map(|s| serde_json::to_string(&s))
            }
        };
        json.map(|r| r.expect("plain struct serializes"))
    })
    .map_err(py_err)
}

/// `agrisim bench nav` from Python; returns summary.json's text. `jobs=0` runs the trials in
/// this process, `jobs=N` in N worker processes at once.
#[pyfunction]
#[pyo3(signature = (out, scenario=None, trials=50, seed=1, scenes=1, record=None, jobs=0, resume=false))]
#[allow(clippy::too_many_arguments)]
pub fn bench_nav(
    py: Python<'_>,
    out: PathBuf,
    scenario: Option<PathBuf>,
    trials: u64,
    seed: u64,
    scenes: u64,
    record: Option<String>,
    jobs: usize,
    resume: bool,
) -> PyResult<String> {
    run_bench(py, job(Kind::Nav, scenario, trials, seed, scenes, record, out)?, jobs, resume)
}

/// `agrisim bench harvest` from Python; as [`bench_nav`].
#[pyfunction]
#[pyo3(signature = (out, scenario=None, trials=50, seed=1, scenes=1, record=None, jobs=0, resume=false))]
#[allow(clippy::too_many_arguments)]
pub fn bench_harvest(
    py: Python<'_>,
    out: PathBuf,
    scenario: Option<PathBuf>,
    trials: u64,
    seed: u64,
    scenes: u64,
    record: Option<String>,
    jobs: usize,
    resume: bool,
) -> PyResult<String> {
    run_bench(py, job(Kind::Harvest, scenario, trials, seed, scenes, record, out)?, jobs, resume)
}

/// Runs trial `index` of a benchmark alone, writing `out/trials/NNNN.mcap` and `NNNN.json`
/// exactly as the whole benchmark would; `bench_*(..., resume=True)` then sums them up.
#[pyfunction]
#[pyo3(signature = (benchmark, out, index, scenario=None, trials=50, seed=1, scenes=1, record=None))]
#[allow(clippy::too_many_arguments)]
pub fn run_trial(
    py: Python<'_>,
    benchmark: &str,
    out: PathBuf,
    index: u64,
    scenario: Option<PathBuf>,
    trials: u64,
    seed: u64,
    scenes: u64,
    record: Option<String>,
) -> PyResult<()> {
    let j = job(Kind::parse(benchmark)?, scenario, trials, seed, scenes, record, out)?;
    if index >= j.plan.trials {
        return Err(py_err(format!("trial {index} is not among the {} trials", j.plan.trials)));
    }
    let mut j = OnThisThread(j);
    py.detach(move || {
        let j = j.get();
        let out: &Path = &j.out;
        match j.kind {
            Kind::Nav => agrisim_bench::nav::nav_worker(&j.scenario, &j.options, j.plan, out, index),
            Kind::Harvest => agrisim_bench::harvest::harvest_worker(&j.scenario, &j.options, j.plan, out, index),
        }
    })
    .map_err(py_err)
}
