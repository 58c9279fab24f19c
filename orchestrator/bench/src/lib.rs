//! agrisim-bench: the evaluations. Many-trial benchmarks (navigation, dual-arm harvest,
//! whole-row harvest) on one framework, with honest statistics and every trial recorded, and
//! the master's overhead.
//!
//! A judge reads only what was published on the bus (the messages every trial records) and
//! the world's ground-truth outputs through the engine; never a node's memory. So a node
//! written elsewhere (a ROS 2 node, a Python script) is judged by the same harness.
//!
//! A benchmark is a folder (`nav/`, `harvest/`, `row/`: set-up, trial and judge, summary,
//! report) implementing [`TrialBenchmark`], plus its line in [`registry`]; the CLI, the
//! worker processes and Python then run it by name.

pub mod framework;
pub mod harvest;
pub mod initial_pose;
pub mod map;
pub mod nav;
pub mod overhead;
pub mod row;

pub use framework::cli;
pub use framework::{trial_seed, Benchmark, Exec, Job, Registry, TrialBenchmark, TrialPlan};
pub use overhead::{overhead, OverheadReport};

/// The built-in benchmarks, in the order `agrisim bench --help` lists them.
pub fn registry() -> Registry {
    Registry::default().with(&nav::Nav).with(&harvest::Harvest).with(&row::Row)
}
