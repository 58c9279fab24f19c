//! `agrisim bench overhead`: what the master costs per FMU and step, beside what the FMUs
//! themselves cost. Wall-clock time is read here only to report speed; it never enters a
//! simulation result or a log.

use agrisim_error::Result;
use agrisim_session::run::{default_nodes, prepare};
use agrisim_session::{RunOptions, Scenario};
use serde::Serialize;
use std::path::Path;
use std::time::Instant;

#[derive(Debug, Serialize)]
pub struct OverheadReport {
    pub steps: u64,
    pub fmus: usize,
    /// Full master loop (exchange, nodes, recording, stepping) per FMU and step [µs].
    pub master_us_per_fmu_step: f64,
    /// Bare `fmi3DoStep` calls on the same instances per FMU and step [µs].
    pub do_step_us_per_fmu_step: f64,
    /// The difference: the orchestrator's own cost per FMU and step [µs].
    pub overhead_us_per_fmu_step: f64,
}

pub fn overhead(s: &Scenario, o: &RunOptions, steps: u64, out_dir: &Path) -> Result<OverheadReport> {
    std::fs::create_dir_all(out_dir).map_err(|e| agrisim_error::err!("cannot create {}: {e}", out_dir.display()))?;
    let mut master = prepare(s, o, &out_dir.join("bench.mcap"), default_nodes(s))?;
    let fmus = master.system().components.len();
    let t0 = Instant::now();
    master.run(steps, |_| {})?;
    let master_s = t0.elapsed().as_secs_f64();
    let h = s.timing.step;
    let start = master.time();
    let t1 = Instant::now();
    for k in 0..steps {
        let t = start + k as f64 * h;
        for c in &mut master.system().components {
            c.instance.do_step(t, h)?;
        }
    }
    let step_s = t1.elapsed().as_secs_f64();
    master.recorder_finish()?;
    let per = |secs: f64| secs * 1e6 / (steps as f64 * fmus as f64);
    Ok(OverheadReport {
        steps,
        fmus,
        master_us_per_fmu_step: per(master_s),
        do_step_us_per_fmu_step: per(step_s),
        overhead_us_per_fmu_step: per(master_s - step_s),
    })
}
