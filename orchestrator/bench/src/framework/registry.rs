//! The benchmarks by name. One list drives the `agrisim bench` subcommands, the worker
//! processes (`--worker-trial i` of a named benchmark) and Python's `agrisim.bench.run`, so a
//! benchmark added here is in all three.

use super::benchmark::{Benchmark, Job};
use super::trials::Exec;
use agrisim_error::{err, Result};

/// Benchmarks in the order `agrisim bench --help` lists them.
#[derive(Clone, Default)]
pub struct Registry {
    list: Vec<&'static dyn Benchmark>,
}

impl Registry {
    /// This registry and `b` after it. A name may be taken once (panics otherwise: two
    /// benchmarks under one subcommand is a programming error).
    pub fn with(mut self, b: &'static dyn Benchmark) -> Registry {
        assert!(self.find(b.name()).is_none(), "benchmark {} is registered twice", b.name());
        self.list.push(b);
        self
    }

    pub fn iter(&self) -> impl Iterator<Item = &'static dyn Benchmark> + '_ {
        self.list.iter().copied()
    }

    pub fn names(&self) -> Vec<&'static str> {
        self.iter().map(|b| b.name()).collect()
    }

    fn find(&self, name: &str) -> Option<&'static dyn Benchmark> {
        self.iter().find(|b| b.name() == name)
    }

    /// The benchmark called `name`; the error lists the known ones.
    pub fn get(&self, name: &str) -> Result<&'static dyn Benchmark> {
        self.find(name).ok_or_else(|| err!("unknown benchmark '{name}' (known: {})", self.names().join(", ")))
    }

    /// Runs benchmark `name` (see [`Benchmark::run`]): what the CLI and Python both call.
    pub fn run(
        &self,
        name: &str,
        job: &Job,
        resume: bool,
        exec: Exec,
        progress: &mut dyn FnMut(u64, u64),
    ) -> Result<String> {
        self.get(name)?.run(job, resume, exec, progress)
    }

    /// Trial `i` of benchmark `name` alone (a worker process's part, or one Ray task's).
    pub fn run_one(&self, name: &str, job: &Job, i: u64) -> Result<()> {
        if i >= job.plan.trials {
            return Err(err!("trial {i} is not among the {} trials", job.plan.trials));
        }
        self.get(name)?.run_one(job, i)
    }
}
