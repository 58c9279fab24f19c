//! The many-trial benchmarks for Python, every one the registry holds (`agrisim bench <name>`):
//! the same dispatch, files and statistics as the CLI, and one trial at a time (`run_trial`)
//! for spreading trials over other executors (Ray tasks). Trial i depends only on (seed, i),
//! so every backend writes the same trials.

use crate::paths::{agrisim_bin, fmu_dirs, scenario_path};
use crate::{py_err, OnThisThread};
use agrisim_bench::framework::{OptionValue, OptionValues};
use agrisim_bench::{Exec, Job, TrialPlan};
use agrisim_session::{Profile, RunOptions, Scenario};
use pyo3::prelude::*;
use std::collections::BTreeMap;
use std::path::PathBuf;

/// Python's view of an option's default: a float or an int.
fn py_value<'py>(py: Python<'py>, v: OptionValue) -> PyResult<Bound<'py, PyAny>> {
    match v {
        OptionValue::F64(x) => Ok(x.into_pyobject(py)?.into_any()),
        OptionValue::U64(x) => Ok(x.into_pyobject(py)?.into_any()),
    }
}

/// A registered benchmark for Python: (name, one-line about, default scenario name,
/// {option: default}).
type Described<'py> = (String, String, String, BTreeMap<String, Bound<'py, PyAny>>);

/// The registered benchmarks in order.
#[pyfunction]
pub fn benchmarks(py: Python<'_>) -> PyResult<Vec<Described<'_>>> {
    agrisim_bench::registry()
        .iter()
        .map(|b| {
            let options = b.options().iter().map(|o| Ok((o.name.to_string(), py_value(py, o.default)?)));
            Ok((b.name().into(), b.about().into(), b.default_scenario().into(), options.collect::<PyResult<_>>()?))
        })
        .collect()
}

/// A benchmark run as Python describes it; `options` by name (a Python keyword's
/// underscores are the option's hyphens), as text so each is read by its declared type.
#[allow(clippy::too_many_arguments)]
fn job(
    name: &str,
    scenario: Option<PathBuf>,
    trials: u64,
    seed: u64,
    scenes: u64,
    record: Option<String>,
    options: BTreeMap<String, Bound<'_, PyAny>>,
    out: PathBuf,
) -> PyResult<Job> {
    let b = agrisim_bench::registry().get(name).map_err(py_err)?;
    if scenes == 0 {
        return Err(py_err("scenes must be at least 1"));
    }
    let given: Vec<(String, String)> =
        options.iter().map(|(k, v)| Ok((k.replace('_', "-"), v.str()?.to_string()))).collect::<PyResult<_>>()?;
    let options =
        OptionValues::parse(name, b.options(), given.iter().map(|(k, v)| (k.as_str(), v.as_str()))).map_err(py_err)?;
    let path = scenario_path(scenario.unwrap_or_else(|| b.default_scenario().into()));
    let scenario = Scenario::load(&path).map_err(py_err)?;
    let (fmu_dir, cache_dir) = fmu_dirs();
    let record = record.map(|r| r.parse::<Profile>().map_err(py_err)).transpose()?;
    let run = RunOptions {
        fmu_dir,
        cache_dir,
        seed: None,
        duration: None,
        fmu_overrides: Default::default(),
        fmu_log: None,
        record,
        nodes: Default::default(),
    };
    Ok(Job { scenario, run, plan: TrialPlan { trials, seed, scenes }, options, out })
}

/// A worker process for trial `i`: the CLI with the same benchmark arguments.
fn worker(name: &str, j: &Job, i: u64) -> std::process::Command {
    let mut c = std::process::Command::new(agrisim_bin());
    c.args(j.worker_args(name, i));
    c.arg("--fmu-dir").arg(&j.run.fmu_dir).arg("--cache-dir").arg(&j.run.cache_dir);
    if let Some(p) = j.run.record {
        c.args(["--record", p.name()]);
    }
    c.stdin(std::process::Stdio::null()).stdout(std::process::Stdio::null());
    c
}

/// `agrisim bench <benchmark>` from Python; returns summary.json's text. `jobs=0` runs the
/// trials in this process, `jobs=N` in N worker processes at once; `options`: the
/// benchmark's own (e.g. `{"length": 2.0}` for row).
#[pyfunction]
#[pyo3(signature = (benchmark, out, scenario=None, trials=50, seed=1, scenes=1, record=None, jobs=0, resume=false, options=BTreeMap::new()))]
#[allow(clippy::too_many_arguments)]
pub fn bench_run(
    py: Python<'_>,
    benchmark: &str,
    out: PathBuf,
    scenario: Option<PathBuf>,
    trials: u64,
    seed: u64,
    scenes: u64,
    record: Option<String>,
    jobs: usize,
    resume: bool,
    options: BTreeMap<String, Bound<'_, PyAny>>,
) -> PyResult<String> {
    let mut j = OnThisThread(job(benchmark, scenario, trials, seed, scenes, record, options, out)?);
    py.detach(move || {
        let j = j.get();
        let command = |i: u64| worker(benchmark, j, i);
        let exec = if jobs == 0 { Exec::InProcess } else { Exec::Workers { jobs, command: &command } };
        agrisim_bench::registry().run(benchmark, j, resume, exec, &mut |_, _| {})
    })
    .map_err(py_err)
}

/// Runs trial `index` of a benchmark alone, writing `out/trials/NNNN.mcap` and `NNNN.json`
/// exactly as the whole benchmark would; `bench_run(..., resume=True)` then sums them up.
#[pyfunction]
#[pyo3(signature = (benchmark, out, index, scenario=None, trials=50, seed=1, scenes=1, record=None, options=BTreeMap::new()))]
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
    options: BTreeMap<String, Bound<'_, PyAny>>,
) -> PyResult<()> {
    let mut j = OnThisThread(job(benchmark, scenario, trials, seed, scenes, record, options, out)?);
    py.detach(move || agrisim_bench::registry().run_one(benchmark, j.get(), index)).map_err(py_err)
}
