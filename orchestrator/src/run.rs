//! `agrisim run`: a scenario's system, driven by its command script, recorded to one MCAP.

use crate::error::{Context, Result};
use crate::master::Master;
use crate::nodes::{CommandScript, FaultInjector, Node, OdomTf};
use crate::recorder::Recorder;
use crate::scenario::Scenario;
use crate::system::{LoadOptions, System};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Everything `agrisim run` needs besides the scenario.
#[derive(Clone, Debug)]
pub struct RunOptions {
    pub fmu_dir: PathBuf,
    pub cache_dir: PathBuf,
    pub seed: Option<u64>,
    pub duration: Option<f64>,
    /// Component -> FMU file (CLI `--fmu chassis=ChassisDynamic.fmu`), on top of the scenario's.
    pub fmu_overrides: BTreeMap<String, String>,
}

/// What a finished run reports.
#[derive(Clone, Debug)]
pub struct RunSummary {
    pub mcap: PathBuf,
    pub steps: u64,
    pub simulated: f64,
}

fn load_options(s: &Scenario, o: &RunOptions) -> LoadOptions {
    let mut fmu_overrides = s.system.fmus.clone();
    fmu_overrides.extend(o.fmu_overrides.clone());
    LoadOptions { fmu_dir: o.fmu_dir.clone(), cache_dir: o.cache_dir.clone(), fmu_overrides, step: s.timing.step, message_period: 1.0 / s.timing.message_rate }
}

/// Builds the master for a scenario, recording to `mcap`. Setup errors come back before any
/// file is written; from here on the MCAP exists and is finished whatever happens.
pub fn prepare(s: &Scenario, o: &RunOptions, mcap: &Path) -> Result<Master> {
    let nodes: Vec<Box<dyn Node>> = vec![Box::new(CommandScript::new(s.base_commands.clone(), s.lift_commands.clone())), Box::new(OdomTf::default()), Box::new(FaultInjector::new(&s.inject))];
    prepare_with(s, o, mcap, nodes)
}

/// [`prepare`] with the algorithm layer's nodes chosen by the caller.
pub fn prepare_with(s: &Scenario, o: &RunOptions, mcap: &Path, nodes: Vec<Box<dyn Node>>) -> Result<Master> {
    let seed = o.seed.unwrap_or(s.seed);
    let lo = load_options(s, o);
    let mut system = System::load(&s.system_path(), &lo)?;
    // The base starts at the greenhouse's predefined initial pose unless the scenario says otherwise.
    let mut params = s.parameters.clone();
    if system.structure.components.iter().any(|c| c.name == "world") {
        let g = crate::scene::generate_scene(s)?;
        let start = params.entry("chassis".to_string()).or_default();
        for (name, v) in ["x0", "y0", "yaw0"].iter().zip(g.layout.start_pose) {
            start.entry(name.to_string()).or_insert(toml::Value::Float(v));
        }
    }
    let applied = system.apply_parameters(&params, seed, &s.scene_toml(), &s.environment_toml())?;
    let mut recorder = Recorder::create(mcap)?;
    let mut run_info = BTreeMap::from([
        ("scenario".to_string(), s.name.clone()),
        ("scenario_file".to_string(), s.path.display().to_string()),
        ("system".to_string(), system.structure.name.clone()),
        ("seed".to_string(), seed.to_string()),
        ("step".to_string(), format!("{:?}", s.timing.step)),
        ("message_rate".to_string(), format!("{:?}", s.timing.message_rate)),
    ]);
    for c in &system.components {
        run_info.insert(format!("fmu.{}", c.name), c.archive.md.model_name.clone());
    }
    recorder.metadata("agrisim.run", run_info)?;
    for (comp, params) in applied {
        recorder.metadata(&format!("agrisim.parameters.{comp}"), params)?;
    }
    let mut master = Master::new(system, nodes, recorder, s.timing.step, lo.message_period)?;
    master.initialize()?;
    Ok(master)
}

/// Runs a scenario into `out_dir/run.mcap`.
pub fn run(s: &Scenario, o: &RunOptions, out_dir: &Path, progress: impl FnMut(u64, u64)) -> Result<RunSummary> {
    std::fs::create_dir_all(out_dir).context(|| format!("cannot create {}", out_dir.display()))?;
    let mcap = out_dir.join("run.mcap");
    let duration = o.duration.unwrap_or(s.duration);
    let steps = crate::system::ticks_of(duration, s.timing.step, "duration").or_else(|_| -> Result<u64> {
        Err(crate::err!("duration {duration} s is not a whole number of {} s steps", s.timing.step))
    })?;
    let mut master = prepare(s, o, &mcap)?;
    let mut progress = progress;
    let result = master.run(steps, |k| progress(k, steps));
    let finish = master.recorder_finish();
    result?;
    finish?;
    Ok(RunSummary { mcap, steps, simulated: steps as f64 * s.timing.step })
}
