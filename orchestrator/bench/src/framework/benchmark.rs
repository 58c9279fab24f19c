//! What a benchmark is: its set-up of a scene, one trial, the judging of a trial that died, a
//! summary and a report ([`TrialBenchmark`]); the framework does the rest the same way for all
//! (scenes, trial seeds, the trial loop in this process or in workers, resume, interrupt,
//! summary.json, report.html). [`Benchmark`] is the same thing without its types, as the
//! registry, the CLI and Python hold it.

use super::options::{OptionSpec, OptionValues};
use super::report;
use super::scenes::Scenes;
use super::seeds::trial_seed;
use super::trials::{run_one, run_trials, write_summary, Exec, TrialPlan, Trials};
use agrisim_error::Result;
use agrisim_session::{Profile, RunOptions, Scenario};
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// One run of a benchmark: what the user asked for.
pub struct Job {
    /// The scenario (scene 0; scene k grows its greenhouse from seed + k).
    pub scenario: Scenario,
    /// How every trial runs (FMU directories, logging, recording, external nodes).
    pub run: RunOptions,
    pub plan: TrialPlan,
    /// The benchmark's own options.
    pub options: OptionValues,
    /// Where summary.json, trials.jsonl, trials/ and report.html go.
    pub out: PathBuf,
}

impl Job {
    /// The command-line arguments (after the program name) of a worker process that runs
    /// trial `i` of `bench` in this job: every flag the framework owns (a front end adds its
    /// own: FMU directories, recording).
    pub fn worker_args(&self, bench: &str, i: u64) -> Vec<std::ffi::OsString> {
        let mut a: Vec<std::ffi::OsString> = vec!["bench".into(), bench.into(), "--scenario".into()];
        a.push(self.scenario.path.clone().into());
        for (flag, v) in [("--trials", self.plan.trials), ("--seed", self.plan.seed), ("--scenes", self.plan.scenes)] {
            a.extend([flag.into(), v.to_string().into()]);
        }
        a.extend(self.options.args().into_iter().map(Into::into));
        a.extend(["--out".into(), self.out.clone().into(), "--worker-trial".into(), i.to_string().into()]);
        a
    }
}

/// What one trial is given.
pub struct Trial<'a, S> {
    /// The scenario of the trial's scene.
    pub scenario: &'a Scenario,
    pub run: &'a RunOptions,
    /// The benchmark's set-up of the trial's scene.
    pub setup: &'a S,
    pub options: &'a OptionValues,
    pub index: u64,
    /// The trial's scene (index i mod scenes).
    pub scene: u64,
    /// The trial's own seed ([`trial_seed`] of the master seed and the index).
    pub seed: u64,
}

/// The whole benchmark, as its summary and report see it.
pub struct Whole<'a, S> {
    /// The scenario as given (scene 0).
    pub scenario: &'a Scenario,
    pub plan: TrialPlan,
    pub options: &'a OptionValues,
    /// Every scene and its set-up, scene 0 first.
    pub scenes: &'a Scenes<S>,
}

/// A many-trial benchmark. Trial i must depend only on what [`Trial`] holds (its seed among
/// them), never on wall time or other trials: that makes results the same in this process,
/// in workers, resumed or spread over machines.
pub trait TrialBenchmark: Sync {
    /// What a scene's set-up makes once for all its trials (maps, target candidates).
    type Setup;
    /// One trial's result, kept in trials/NNNN.json.
    type Record: Serialize + DeserializeOwned;
    /// summary.json.
    type Summary: Serialize;

    /// The subcommand: `agrisim bench <name>`, `agrisim.bench.run("<name>", ...)`.
    fn name(&self) -> &'static str;
    /// One line for `agrisim bench --help`.
    fn about(&self) -> &'static str;
    /// The scenario when none is given: its name under models/scenarios/ (without .toml).
    fn default_scenario(&self) -> &'static str;
    /// The benchmark's own options.
    fn options(&self) -> &'static [OptionSpec] {
        &[]
    }
    /// Refuses option values the benchmark cannot run with (before anything is set up).
    fn check(&self, _options: &OptionValues) -> Result<()> {
        Ok(())
    }
    /// The set-up of one scene (`s` is that scene's scenario).
    fn setup(&self, s: &Scenario, options: &OptionValues) -> Result<Self::Setup>;
    /// Runs and judges one trial, recording it into `mcap`.
    fn trial(&self, t: &Trial<Self::Setup>, mcap: &Path) -> Result<Self::Record>;
    /// The record of a trial whose worker process died (`reason` says how).
    fn failed(&self, t: &Trial<Self::Setup>, reason: String) -> Self::Record;
    /// The trial's line of trials.jsonl.
    fn line(&self, r: &Self::Record) -> String {
        serde_json::to_string(r).expect("plain struct")
    }
    /// summary.json from the completed trials, in order.
    fn summarize(&self, w: &Whole<Self::Setup>, results: &[Self::Record]) -> Self::Summary;
    /// report.html: only what the seed determines, so the same seed gives the same page.
    fn report(&self, w: &Whole<Self::Setup>, summary: &Self::Summary, results: &[Self::Record]) -> Result<String>;
}

/// A benchmark as the registry holds it (every [`TrialBenchmark`] is one).
pub trait Benchmark: Sync {
    fn name(&self) -> &'static str;
    fn about(&self) -> &'static str;
    fn default_scenario(&self) -> &'static str;
    fn options(&self) -> &'static [OptionSpec];
    /// Runs the benchmark and writes its files; returns summary.json's content.
    fn run(&self, job: &Job, resume: bool, exec: Exec, progress: &mut dyn FnMut(u64, u64)) -> Result<String>;
    /// A worker process's part: trial `i` alone, its files written as the whole run writes
    /// them.
    fn run_one(&self, job: &Job, i: u64) -> Result<()>;
}

impl<B: TrialBenchmark> Benchmark for B {
    fn name(&self) -> &'static str {
        TrialBenchmark::name(self)
    }
    fn about(&self) -> &'static str {
        TrialBenchmark::about(self)
    }
    fn default_scenario(&self) -> &'static str {
        TrialBenchmark::default_scenario(self)
    }
    fn options(&self) -> &'static [OptionSpec] {
        TrialBenchmark::options(self)
    }
    fn run(&self, job: &Job, resume: bool, exec: Exec, progress: &mut dyn FnMut(u64, u64)) -> Result<String> {
        let summary = run(self, job, resume, exec, progress)?;
        Ok(serde_json::to_string_pretty(&summary).expect("plain struct serializes"))
    }
    fn run_one(&self, job: &Job, i: u64) -> Result<()> {
        self.check(&job.options)?;
        let o = job.run.record_default(&job.scenario, Profile::Standard);
        let scenes = Scenes::for_trial(&job.scenario, job.plan.scenes, i, |s| self.setup(s, &job.options))?;
        run_one(&job.out, i, |i, mcap| self.trial(&trial(&scenes, &o, job, i), mcap))
    }
}

/// Trial `i`'s view of a job.
fn trial<'a, S>(scenes: &'a Scenes<S>, run: &'a RunOptions, job: &'a Job, i: u64) -> Trial<'a, S> {
    let (scene, scenario, setup) = scenes.of(i);
    Trial { scenario, run, setup, options: &job.options, index: i, scene, seed: trial_seed(job.plan.seed, i) }
}

/// A benchmark's trials as the trial loop runs them.
struct Loop<'a, B: TrialBenchmark> {
    b: &'a B,
    scenes: &'a Scenes<B::Setup>,
    run: &'a RunOptions,
    job: &'a Job,
}

impl<B: TrialBenchmark> Trials for Loop<'_, B> {
    type Record = B::Record;
    fn run(&self, i: u64, mcap: &Path) -> Result<B::Record> {
        self.b.trial(&trial(self.scenes, self.run, self.job, i), mcap)
    }
    fn failed(&self, i: u64, reason: String) -> B::Record {
        self.b.failed(&trial(self.scenes, self.run, self.job, i), reason)
    }
    fn line(&self, r: &B::Record) -> String {
        self.b.line(r)
    }
}

/// Runs benchmark `b` as `job` asks: writes trials/, trials.jsonl, summary.json and
/// report.html, and returns the summary. Trials record the standard profile unless the job or
/// the scenario says otherwise.
pub fn run<B: TrialBenchmark>(
    b: &B,
    job: &Job,
    resume: bool,
    exec: Exec,
    progress: impl FnMut(u64, u64),
) -> Result<B::Summary> {
    b.check(&job.options)?;
    let o = job.run.record_default(&job.scenario, Profile::Standard);
    let scenes = Scenes::all(&job.scenario, job.plan.scenes, |s| b.setup(s, &job.options))?;
    let trials = Loop { b, scenes: &scenes, run: &o, job };
    let done = run_trials(&job.out, job.plan.trials, resume, exec, progress, &trials)?;
    let whole = Whole { scenario: &job.scenario, plan: job.plan, options: &job.options, scenes: &scenes };
    let summary = b.summarize(&whole, &done.results);
    write_summary(&job.out, &summary, done.interrupted)?;
    report::write(&job.out, &b.report(&whole, &summary, &done.results)?)?;
    Ok(summary)
}
