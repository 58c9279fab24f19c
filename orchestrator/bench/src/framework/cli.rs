//! The `bench` command line, built from a registry: one subcommand per benchmark, each with
//! the trial flags every benchmark shares ([`TrialArgs`]) and the benchmark's own options. A
//! front end adds its own flags to every subcommand (the `agrisim` CLI: FMU directories,
//! logging, recording, ROS 2 and Foxglove links) and its own non-trial subcommands.

use super::benchmark::Benchmark;
use super::options::{OptionValue, OptionValues};
use super::registry::Registry;
use super::trials::{Exec, TrialPlan};
use agrisim_error::{err, Result};
use clap::{Arg, ArgMatches, Args, Command, FromArgMatches};
use std::path::PathBuf;

/// What every many-trial benchmark takes.
#[derive(Args, Clone, Debug)]
pub struct TrialArgs {
    /// Scenario file (default: the benchmark's own).
    #[arg(long)]
    pub scenario: Option<PathBuf>,
    #[arg(long, default_value_t = 50)]
    pub trials: u64,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Scenes the trials are spread over (round robin): scene k is the scenario's greenhouse
    /// grown from its seed + k. The summary gives per-scene results and a cluster-bootstrap
    /// interval beside Wilson's.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..=10_000))]
    pub scenes: u64,
    /// Keep the trials already complete in DIR (an interrupted run) and run the others.
    #[arg(long)]
    pub resume: bool,
    /// Trials run at once, each in its own worker process (a trial whose process dies, e.g.
    /// a foreign FMU that segfaults, is recorded as an error and the benchmark goes on).
    /// Default: the machine's core count (results do not depend on it).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=4096))]
    pub jobs: Option<u64>,
    /// Run the trials one after the other inside this process (no worker processes).
    #[arg(long, conflicts_with = "jobs")]
    pub in_process: bool,
    /// Internal: run trial N only, as a worker process of a benchmark.
    #[arg(long, hide = true)]
    pub worker_trial: Option<u64>,
    /// Output directory: summary.json, trials.jsonl, trials/, report.html.
    #[arg(long)]
    pub out: PathBuf,
}

impl TrialArgs {
    pub fn plan(&self) -> TrialPlan {
        TrialPlan { trials: self.trials, seed: self.seed, scenes: self.scenes }
    }

    /// The scenario file: as given, else `models/scenarios/<default>.toml` (from the working
    /// directory, as the CLI's other defaults).
    pub fn scenario_path(&self, b: &dyn Benchmark) -> PathBuf {
        self.scenario.clone().unwrap_or_else(|| default_scenario_path(b))
    }

    /// How the trials run: in this process (`--in-process`), else in `--jobs` workers
    /// (`default_jobs` when not given) that `command(i)` starts.
    pub fn exec<'a>(&self, default_jobs: usize, command: &'a dyn Fn(u64) -> std::process::Command) -> Exec<'a> {
        if self.in_process {
            Exec::InProcess
        } else {
            Exec::Workers { jobs: self.jobs.map_or(default_jobs, |j| j as usize), command }
        }
    }
}

/// `models/scenarios/<the benchmark's default>.toml`.
pub fn default_scenario_path(b: &dyn Benchmark) -> PathBuf {
    PathBuf::from(format!("models/scenarios/{}.toml", b.default_scenario()))
}

/// Trials at once when `--jobs` is not given: one per core (trial results do not depend on
/// it, only the wall time does).
pub fn default_jobs() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// The `bench` command: a subcommand per registered benchmark, `shared` applied to each (to
/// add a front end's flags).
pub fn command(registry: &Registry, shared: &dyn Fn(Command) -> Command) -> Command {
    let mut c = Command::new("bench").about("Benchmarks").subcommand_required(true).arg_required_else_help(true);
    for b in registry.iter() {
        c = c.subcommand(subcommand(b, shared));
    }
    c
}

fn subcommand(b: &dyn Benchmark, shared: &dyn Fn(Command) -> Command) -> Command {
    let long = format!(
        "{}\n\nWrites DIR/summary.json, DIR/trials.jsonl (one line per trial), DIR/trials/<NNNN>.mcap and \
         DIR/report.html (default scenario: {}).",
        b.about(),
        default_scenario_path(b).display()
    );
    let mut c = TrialArgs::augment_args(Command::new(b.name()));
    for o in b.options() {
        let arg = Arg::new(o.name)
            .long(o.name)
            .value_name(o.name.to_uppercase())
            .help(o.help)
            .default_value(o.default.to_string());
        c = c.arg(match o.default {
            OptionValue::F64(_) => arg.value_parser(clap::value_parser!(f64)),
            OptionValue::U64(_) => arg.value_parser(clap::value_parser!(u64)),
        });
    }
    // After the flags: an `Args` derive sets the command's about from its own doc.
    shared(c).about(b.about()).long_about(long)
}

/// The benchmark a `bench` subcommand names, its trial flags and its options' values (`m`:
/// the matches of `bench`).
pub fn parse(registry: &Registry, m: &ArgMatches) -> Result<(&'static dyn Benchmark, TrialArgs, OptionValues)> {
    let (name, sub) =
        m.subcommand().ok_or_else(|| err!("bench: no benchmark named (one of {:?})", registry.names()))?;
    let b = registry.get(name)?;
    let args = TrialArgs::from_arg_matches(sub).map_err(|e| err!("bench {name}: {e}"))?;
    let mut values = OptionValues::defaults(b.options());
    for o in b.options() {
        let v = match o.default {
            OptionValue::F64(_) => sub.get_one::<f64>(o.name).copied().map(OptionValue::F64),
            OptionValue::U64(_) => sub.get_one::<u64>(o.name).copied().map(OptionValue::U64),
        };
        values.set(o.name, v.expect("every option has a default"));
    }
    Ok((b, args, values))
}
