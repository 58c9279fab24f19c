//! The machinery every benchmark shares: what a benchmark is ([`benchmark`]), the registry
//! that drives the CLI, the worker processes and Python ([`registry`], [`cli`]), a
//! benchmark's own options, trial seeds, scenes, the trial loop (in this process or in worker
//! processes, resume, interrupt), statistics and the report page. A benchmark (`nav/`,
//! `harvest/`, `row/`) brings only its set-up, trial, judge, summary and report.

pub mod benchmark;
pub mod cli;
pub mod options;
pub mod registry;
pub mod report;
pub mod scenes;
pub mod seeds;
pub mod stats;
pub mod trials;

pub use benchmark::{run, Benchmark, Job, Trial, TrialBenchmark, Whole};
pub use options::{OptionSpec, OptionValue, OptionValues};
pub use registry::Registry;
pub use seeds::trial_seed;
pub use trials::{Exec, TrialPlan};
