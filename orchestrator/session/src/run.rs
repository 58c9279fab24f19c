//! Building a session from a scenario (`agrisim run`, and every benchmark trial): the system
//! with the scenario's parameters, the recorder with the run's metadata, the nodes.

use crate::scenario::Scenario;
use crate::session::{message_types, Session};
use agrisim_bus::{Chunks, Node, Recorder};
use agrisim_cosim::system::ticks_of;
use agrisim_cosim::{LoadOptions, Master, System};
use agrisim_error::{err, Context, Result};
use agrisim_msgs::{sensor_msgs::Image, Message};
use agrisim_nodes::{CommandScript, FaultInjector, OdomTf, RobotStatePublisher};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Everything `agrisim run` needs besides the scenario.
#[derive(Clone, Debug)]
pub struct RunOptions {
    pub fmu_dir: PathBuf,
    pub cache_dir: PathBuf,
    pub seed: Option<u64>,
    pub duration: Option<f64>,
    /// Component -> FMU file (CLI `--fmu chassis=ChassisDynamic.fmu`), on top of the scenario's.
    pub fmu_overrides: BTreeMap<String, String>,
    /// FMU debug logging (CLI `--fmu-log [CATEGORIES]`), replacing the scenario's
    /// `[logging] fmu`: see [`agrisim_cosim::LoadOptions::fmu_log`]. `None` leaves it to the
    /// scenario (off unless it says otherwise).
    pub fmu_log: Option<Vec<String>>,
    /// Recording profile (CLI `--record`), replacing the scenario's `[recording] profile`.
    pub record: Option<agrisim_bus::Profile>,
    /// Built-in nodes turned off and nodes added (CLI `--external`, `--ros2`).
    pub nodes: NodePlan,
}

/// What the system exchanges with the algorithm layer.
#[derive(Clone, Debug, Default)]
pub struct SystemIo {
    /// Message inputs (the commands): topic and ROS 2 type.
    pub messages: Vec<(String, String)>,
    /// Scalar inputs (a lift set-point): their connector names on the bus.
    pub scalars: Vec<String>,
    /// Message outputs (sensors, ground truth): topic and ROS 2 type.
    pub outputs: Vec<(String, String)>,
}

/// Makes the extra nodes of one run (each run gets its own: a ROS 2 bridge joins DDS anew),
/// given the system's inputs.
pub type NodeFactory = Arc<dyn Fn(&SystemIo) -> Result<Vec<Box<dyn Node>>> + Send + Sync>;

/// How a run's nodes differ from what its scenario or benchmark would run: built-in nodes
/// named in `external` are left out (an external node takes their place, e.g. over ROS 2),
/// and `extra` adds nodes after all others (a bridge must see the others' messages).
#[derive(Clone, Default)]
pub struct NodePlan {
    /// Node names ([`Node::name`]): navigator, harvest, command_script, odom_tf, ...
    pub external: BTreeSet<String>,
    pub extra: Option<NodeFactory>,
}

impl std::fmt::Debug for NodePlan {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NodePlan").field("external", &self.external).field("extra", &self.extra.is_some()).finish()
    }
}

impl NodePlan {
    /// `nodes` without the external ones, then the extra ones. Naming a node that is not
    /// there is an error (a typo must not leave the built-in node running).
    pub fn apply(&self, nodes: Vec<Box<dyn Node>>, inputs: &SystemIo) -> Result<Vec<Box<dyn Node>>> {
        for name in &self.external {
            if !nodes.iter().any(|n| n.name() == name) {
                let names: Vec<&str> = nodes.iter().map(|n| n.name()).collect();
                return Err(err!("--external {name}: this run has no node '{name}' (its nodes: {})", names.join(", ")));
            }
        }
        let mut out: Vec<Box<dyn Node>> = nodes.into_iter().filter(|n| !self.external.contains(n.name())).collect();
        if let Some(extra) = &self.extra {
            out.extend(extra(inputs)?);
        }
        Ok(out)
    }
}

impl RunOptions {
    /// These options with `profile` unless the CLI or the scenario chose one (benchmarks
    /// default to `standard`).
    pub fn record_default(&self, s: &Scenario, profile: agrisim_bus::Profile) -> RunOptions {
        let mut o = self.clone();
        if o.record.is_none() && s.recording.is_none() {
            o.record = Some(profile);
        }
        o
    }
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
    let fmu_log = o.fmu_log.clone().or_else(|| s.logging.fmu.categories());
    LoadOptions {
        fmu_dir: o.fmu_dir.clone(),
        cache_dir: o.cache_dir.clone(),
        fmu_overrides,
        step: s.timing.step,
        message_period: 1.0 / s.timing.message_rate,
        fmu_log,
    }
}

/// Start-pose parameters of a mobile base (REP 103, map frame).
const START_POSE: [&str; 3] = ["x0", "y0", "yaw0"];

/// The scenario's parameters, plus: when the system builds the greenhouse scene (some
/// component takes the `scene` parameter), every component with start-pose parameters
/// starts at the layout's predefined initial pose unless the scenario says otherwise.
fn parameters(s: &Scenario, system: &System) -> Result<BTreeMap<String, BTreeMap<String, toml::Value>>> {
    let mut params = s.parameters.clone();
    if system.components.iter().any(|c| c.archive.md.settable_parameter("scene").is_some()) {
        let start_pose = crate::scene::layout(s)?.start_pose;
        for c in &system.components {
            if START_POSE.iter().all(|n| c.archive.md.settable_parameter(n).is_some()) {
                let start = params.entry(c.name.clone()).or_default();
                for (name, v) in START_POSE.iter().zip(start_pose) {
                    start.entry(name.to_string()).or_insert(toml::Value::Float(v));
                }
            }
        }
    }
    Ok(params)
}

/// The nodes of a plain `agrisim run`: the scenario's command script, odom TF, fault injection.
pub fn default_nodes(s: &Scenario) -> Vec<Box<dyn Node>> {
    vec![
        Box::new(CommandScript::new(s.base_commands.clone(), s.lift_commands.clone())),
        Box::new(OdomTf::default()),
        Box::new(FaultInjector::new(&s.inject)),
    ]
}

/// What a plain `agrisim run` shows viewers (RViz, Foxglove; live and in the MCAP): the
/// robot (robot_state_publisher: /robot_description, /joint_states, the links' TF) and the
/// greenhouse ([`crate::viewer::SceneView`]: /scene/markers, /scene/fruit_markers).
pub fn viewer_nodes(s: &Scenario) -> Result<Vec<Box<dyn Node>>> {
    let gh = crate::scene::generate_scene(s)?;
    Ok(vec![Box::new(RobotStatePublisher::agrisim()), Box::new(crate::viewer::SceneView::new(&gh))])
}

/// The topics and ROS 2 types the [`viewer_nodes`] (and the map -> odom of a plain run) publish.
pub fn viewer_topics() -> Vec<(String, String)> {
    use agrisim_msgs::sensor_msgs::JointState;
    use agrisim_msgs::tf2_msgs::TFMessage;
    use agrisim_msgs::visualization_msgs::MarkerArray;
    use agrisim_msgs::Message;
    let tf = TFMessage::TYPE_NAME;
    // robot_state_publisher's (agrisim_nodes::RobotStatePublisher).
    [
        ("/robot_description", agrisim_msgs::std_msgs::String::TYPE_NAME),
        ("/joint_states", JointState::TYPE_NAME),
        ("/tf", tf),
        (crate::viewer::TF_STATIC, tf),
        (crate::viewer::SCENE_MARKERS, MarkerArray::TYPE_NAME),
        (crate::viewer::FRUIT_MARKERS, MarkerArray::TYPE_NAME),
    ]
    .map(|(t, ty)| (t.to_string(), ty.to_string()))
    .to_vec()
}

/// Builds the session for a scenario with the algorithm layer's `nodes`, recording to `mcap`.
/// Setup errors come back before any file is written; from here on the MCAP exists and is
/// finished whatever happens.
pub fn prepare(s: &Scenario, o: &RunOptions, mcap: &Path, nodes: Vec<Box<dyn Node>>) -> Result<Session> {
    prepare_with(s, o, mcap, nodes, false)
}

/// The start pose \[m, m, rad\] of the component with start-pose parameters (the mobile base),
/// from the parameters the run applies.
fn start_pose(params: &BTreeMap<String, BTreeMap<String, toml::Value>>) -> Option<[f64; 3]> {
    params.values().find_map(|p| {
        let v: Vec<f64> = START_POSE
            .iter()
            .filter_map(|n| p.get(*n).and_then(|v| v.as_float().or(v.as_integer().map(|i| i as f64))))
            .collect();
        <[f64; 3]>::try_from(v).ok()
    })
}

/// [`prepare`]; with `map_odom`, map -> odom fixed at the start pose unless a node localizes
/// ([`crate::viewer::with_map_odom`]).
fn prepare_with(
    s: &Scenario,
    o: &RunOptions,
    mcap: &Path,
    nodes: Vec<Box<dyn Node>>,
    map_odom: bool,
) -> Result<Session> {
    let seed = o.seed.unwrap_or(s.seed);
    let lo = load_options(s, o);
    let mut system = System::load(&s.system_path(), &lo)?;
    // Checked before the MCAP file exists: a bad mimeType leaves nothing behind.
    let types = message_types(&system)?;
    let params = parameters(s, &system)?;
    let mut shared = BTreeMap::from([("scene".to_string(), s.scene_toml())]);
    // The scenario's [environment] (when it has one) for every component with a String
    // parameter `environment` (the sensors): light and weather, never geometry.
    let environment = s.environment_toml();
    if !environment.is_empty() {
        shared.insert("environment".to_string(), environment);
    }
    let applied = system.apply_parameters(&params, seed, &shared)?;
    let mut policy = s.recording.clone().unwrap_or_default();
    if let Some(p) = o.record {
        policy.profile = p;
    }
    // Camera images are megabytes each: large chunks (see `Chunks`).
    let chunks = if types.iter().flatten().any(|t| t == Image::TYPE_NAME) { Chunks::Large } else { Chunks::Small };
    let mut recorder =
        Recorder::with_chunks(mcap, policy, chunks).map_err(|e| err!("scenario {}: {e}", s.path.display()))?;
    let mut run_info = BTreeMap::from([
        ("scenario".to_string(), s.name.clone()),
        ("scenario_file".to_string(), s.path.display().to_string()),
        ("system".to_string(), system.structure.name.clone()),
        ("seed".to_string(), seed.to_string()),
        ("step".to_string(), format!("{:?}", s.timing.step)),
        ("message_rate".to_string(), format!("{:?}", s.timing.message_rate)),
        ("algorithm".to_string(), s.timing.algorithm.name().to_string()),
    ]);
    for c in &system.components {
        run_info.insert(format!("fmu.{}", c.name), c.archive.md.model_name.clone());
    }
    recorder.metadata("agrisim.run", run_info)?;
    for (comp, params) in applied {
        recorder.metadata(&format!("agrisim.parameters.{comp}"), params)?;
    }
    let master = Master::new(system, s.timing.step, lo.message_period)?.with_algorithm(s.timing.algorithm.into());
    let (mut messages, mut scalars, mut outputs) = (BTreeSet::new(), BTreeSet::new(), BTreeSet::new());
    for (r, ty) in master.system.routes.iter().zip(&types) {
        match (&r.from, &r.to, ty) {
            (agrisim_cosim::Port::Bus { topic }, _, Some(ty)) => messages.insert((topic.clone(), ty.clone())),
            (agrisim_cosim::Port::Bus { topic }, _, None) => scalars.insert(topic.clone()),
            (_, agrisim_cosim::Port::Bus { topic }, Some(ty)) => outputs.insert((topic.clone(), ty.clone())),
            _ => false,
        };
    }
    let inputs = SystemIo {
        messages: messages.into_iter().collect(),
        scalars: scalars.into_iter().collect(),
        outputs: outputs.into_iter().collect(),
    };
    // Before the external and extra nodes: `--external map_odom` leaves it to an outside localizer.
    let nodes = if map_odom { crate::viewer::with_map_odom(nodes, start_pose(&params)) } else { nodes };
    let nodes = o.nodes.apply(nodes, &inputs)?;
    let mut session = Session::new(master, nodes, recorder, types);
    session.master.initialize()?;
    Ok(session)
}

/// How the master would step and initialize the scenario's system (`agrisim run --explain`):
/// the order, the delayed connections and the exchange periods; nothing is run.
pub fn explain(s: &Scenario, o: &RunOptions) -> Result<String> {
    let lo = load_options(s, o);
    let system = System::load(&s.system_path(), &lo)?;
    let master = Master::new(system, s.timing.step, lo.message_period)?.with_algorithm(s.timing.algorithm.into());
    Ok(format!("System {} ({})\n{}", master.system.structure.name, s.system_path().display(), master.explain()))
}

/// Runs a scenario into `out_dir/run.mcap`.
pub fn run(s: &Scenario, o: &RunOptions, out_dir: &Path, progress: impl FnMut(u64, u64)) -> Result<RunSummary> {
    std::fs::create_dir_all(out_dir).context(|| format!("cannot create {}", out_dir.display()))?;
    let mcap = out_dir.join("run.mcap");
    let duration = o.duration.unwrap_or(s.duration);
    let steps = ticks_of(duration, s.timing.step, "duration")
        .map_err(|_| err!("duration {duration} s is not a whole number of {} s steps", s.timing.step))?;
    let mut nodes = viewer_nodes(s)?;
    nodes.extend(default_nodes(s));
    let mut session = prepare_with(s, o, &mcap, nodes, true)?;
    let mut progress = progress;
    let result = session.run(steps, |k| progress(k, steps));
    let finish = session.recorder_finish();
    result?;
    finish?;
    Ok(RunSummary { mcap, steps, simulated: steps as f64 * s.timing.step })
}
