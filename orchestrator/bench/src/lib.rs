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
pub mod perception;
pub mod row;

pub use framework::cli;
pub use framework::{trial_seed, Benchmark, Exec, Job, Registry, TrialBenchmark, TrialPlan};
pub use overhead::{overhead, OverheadReport};

/// The built-in benchmarks, in the order `agrisim bench --help` lists them.
pub fn registry() -> Registry {
    Registry::default().with(&nav::Nav).with(&harvest::Harvest).with(&row::Row).with(&perception::PerceptionBench)
}

#[cfg(test)]
mod tests {
    // Here, not in framework/registry.rs: the framework knows no benchmark, the crate root all.
    use super::{harvest::Harvest, nav::Nav, registry, row::Row, Registry};

    #[test]
    #[should_panic(expected = "benchmark nav is registered twice")]
    fn a_name_is_registered_once() {
        let _ = registry().with(&Nav);
    }

    #[test]
    fn benchmarks_are_found_by_name_in_order() {
        let r = Registry::default().with(&Row).with(&Nav);
        assert_eq!(r.names(), ["row", "nav"]);
        assert_eq!(r.get("nav").unwrap().name(), "nav");
        let e = r.get("harvest").err().expect("not registered").to_string();
        assert!(e.contains("unknown benchmark 'harvest' (known: row, nav)"), "{e}");
        assert_eq!(r.with(&Harvest).names(), ["row", "nav", "harvest"]);
    }
}
