//! Scenario files (TOML, models/scenarios/): which system to run, timing, seed, parameter
//! overrides per component, and the scripted inputs of a plain `agrisim run`.
//!
//! Unknown keys are errors (a typo must not silently fall back to a default).

use agrisim_error::{Context, Result};
pub use agrisim_nodes::{BaseCommand, Injection, LiftCommand};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    #[serde(default = "default_name")]
    pub name: String,
    #[serde(default)]
    pub description: String,
    /// Master seed: every component's `seed` parameter is derived from it.
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// Simulated duration of `agrisim run` \[s\].
    #[serde(default = "default_duration")]
    pub duration: f64,
    #[serde(default)]
    pub timing: Timing,
    pub system: SystemRef,
    /// The greenhouse (agrisim_scene::GreenhouseConfig keys). Passed verbatim, as TOML
    /// text, to every component with a String parameter `scene`, so all of them build the
    /// same scene. Its `seed` (the scene's layout seed) defaults to the scenario's seed.
    #[serde(default)]
    pub greenhouse: toml::Table,
    /// Sun, weather and render quality (agrisim_sky::environment keys). Passed as TOML
    /// text to every component with a String parameter `environment` (the camera and the
    /// LiDAR); changes images and ranges, never the scene's geometry. Absent = the sensors'
    /// fixed defaults.
    #[serde(default)]
    pub environment: Option<toml::Table>,
    /// Navigation benchmark settings.
    #[serde(default)]
    pub nav: NavSettings,
    /// Harvest benchmark settings.
    #[serde(default)]
    pub harvest: HarvestSettings,
    /// Parameter overrides: component name -> parameter name -> value.
    #[serde(default)]
    pub parameters: BTreeMap<String, BTreeMap<String, toml::Value>>,
    /// Timed base velocity commands (base frame, REP 103), published on /cmd_vel.
    #[serde(default)]
    pub base_commands: Vec<BaseCommand>,
    /// Timed lift position set-points.
    #[serde(default)]
    pub lift_commands: Vec<LiftCommand>,
    /// Fault injection: raw bytes published on a topic at a time (robustness tests).
    #[serde(default)]
    pub inject: Vec<Injection>,
    /// What is logged beyond warnings and errors (which always reach the user).
    #[serde(default)]
    pub logging: Logging,
    /// `[recording]`: which messages the MCAP keeps (profile, include/exclude, decimation);
    /// absent: everything for `agrisim run`, the `standard` profile for benchmarks.
    #[serde(default)]
    pub recording: Option<agrisim_bus::RecordPolicy>,
    /// Where the file was read from (relative paths resolve against its directory).
    #[serde(skip)]
    pub path: PathBuf,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Timing {
    /// Master communication step \[s\].
    #[serde(default = "default_step")]
    pub step: f64,
    /// Rate of message connections \[Hz\] (those without their own period in the system file).
    #[serde(default = "default_message_rate")]
    pub message_rate: f64,
    /// How the components step within a step: `gauss-seidel` (the default, in the planned
    /// order) or `jacobi` (all from the values at the step's start, as libcosim does).
    #[serde(default)]
    pub algorithm: MasterAlgorithm,
}

impl Default for Timing {
    fn default() -> Self {
        Timing { step: default_step(), message_rate: default_message_rate(), algorithm: MasterAlgorithm::default() }
    }
}

/// `[timing] algorithm`: the engine's [`agrisim_cosim::master::Algorithm`], by name.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MasterAlgorithm {
    #[default]
    GaussSeidel,
    Jacobi,
}

impl MasterAlgorithm {
    /// The name a scenario gives it.
    pub fn name(self) -> &'static str {
        match self {
            MasterAlgorithm::GaussSeidel => "gauss-seidel",
            MasterAlgorithm::Jacobi => "jacobi",
        }
    }
}

impl From<MasterAlgorithm> for agrisim_cosim::master::Algorithm {
    fn from(a: MasterAlgorithm) -> Self {
        match a {
            MasterAlgorithm::GaussSeidel => agrisim_cosim::master::Algorithm::GaussSeidel,
            MasterAlgorithm::Jacobi => agrisim_cosim::master::Algorithm::Jacobi,
        }
    }
}

/// `[nav]`: how navigation trials are set up and judged.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct NavSettings {
    /// Simulated time limit of a trial \[s\].
    pub trial_timeout: f64,
    /// Success radius around the target for the ground-truth base centre \[m\] (Nav2's default).
    pub goal_tolerance: f64,
    /// Where targets are drawn: aisles and the headland.
    pub targets_in_headland: bool,
    /// Keep targets at least this far from the aisle ends \[m\].
    pub aisle_margin: f64,
    /// Standard deviations [m, m, rad] of the error of the localizer's initial pose estimate
    /// (an operator's estimate of the start pose; the robot must converge from it).
    pub initial_pose_std: [f64; 3],
    /// The robot's prior map (never the trial scene's own plant parts).
    pub prior_map: PriorMap,
    /// The navigator's global planner by name: `astar` (the default) or `straight_line` (for
    /// open ground); the names are agrisim_nav's plugins, checked when a benchmark starts.
    pub planner: String,
    /// The navigator's controller by name: `dwa`.
    pub controller: String,
}

/// `[harvest]`: how harvest trials draw their targets.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct HarvestSettings {
    /// Visibility classes targets are drawn from (free, partly_occluded, behind_stem); all
    /// by default. `["free"]` is close to the paper's experiment (fruit in plain view).
    pub visibility: Vec<String>,
    /// Harvest by sight: the task is a 1 m stretch of the row on one side, not a fruit; the
    /// node finds a ripe fruit there with the perception node's fruit map and plans in the
    /// mapping node's scene sensed from depth. The system must carry the row cameras
    /// (`camera_left`, `camera_right`, as models/systems/harvest_sight.ssd). Off: the node is
    /// handed the world's target and planning scene (ground truth, as the paper).
    pub sight: bool,
    /// By sight: the radii of the crop's fruit in metres, least and largest, that the perception
    /// node fits; a prior about the cultivar, as a grower knows it (cherry tomatoes are
    /// 12-18 mm). Unset: the detector's 20-45 mm, for round and truss tomatoes.
    pub fruit_radius: Option<[f64; 2]>,
}

impl Default for HarvestSettings {
    fn default() -> Self {
        HarvestSettings {
            visibility: ["free", "partly_occluded", "behind_stem"].map(String::from).to_vec(),
            sight: false,
            fruit_radius: None,
        }
    }
}

/// Where the robot's prior map comes from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PriorMap {
    /// The building plan: structure, and each crop row as its foliage envelope.
    #[default]
    Plan,
    /// A mapping run through the same greenhouse with the crop grown from another plant
    /// seed (the crop a week earlier): stems where they stand, other leaves and fruit.
    MappingRun,
}

impl Default for NavSettings {
    fn default() -> Self {
        NavSettings {
            trial_timeout: 120.0,
            goal_tolerance: 0.25,
            targets_in_headland: true,
            aisle_margin: 1.0,
            initial_pose_std: [0.1, 0.1, 3f64.to_radians()],
            prior_map: PriorMap::Plan,
            planner: "astar".into(),
            controller: "dwa".into(),
        }
    }
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SystemRef {
    /// SSP SystemStructure.ssd, relative to the scenario file.
    pub file: PathBuf,
    /// Component -> FMU file override (e.g. `chassis = "ChassisDynamic.fmu"`).
    #[serde(default)]
    pub fmus: BTreeMap<String, String>,
}

/// `[logging]`.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Logging {
    /// FMU debug logging, printed to stderr: `false` (the default) off, `true` every category,
    /// or a list of categories as the FMUs' modelDescription declares them (e.g.
    /// `["logModel"]`; the project's FMUs have logStatusWarning, logStatusError, logModel,
    /// logCalls). The CLI's `--fmu-log` replaces it.
    #[serde(default)]
    pub fmu: FmuLog,
}

/// The value of `[logging] fmu`: a boolean or a non-empty list of category names.
#[derive(Clone, Debug, PartialEq, Eq, Deserialize)]
#[serde(try_from = "toml::Value")]
pub enum FmuLog {
    All(bool),
    Categories(Vec<String>),
}

impl Default for FmuLog {
    fn default() -> Self {
        FmuLog::All(false)
    }
}

impl TryFrom<toml::Value> for FmuLog {
    type Error = String;
    fn try_from(v: toml::Value) -> std::result::Result<FmuLog, String> {
        let expected = "expected true, false or a non-empty list of log category names";
        match v {
            toml::Value::Boolean(b) => Ok(FmuLog::All(b)),
            toml::Value::Array(a) if !a.is_empty() => a
                .into_iter()
                .map(|c| match c {
                    toml::Value::String(s) => Ok(s),
                    other => Err(format!("{expected}, got {other} in the list")),
                })
                .collect::<std::result::Result<_, _>>()
                .map(FmuLog::Categories),
            other => Err(format!("{expected}, got {other}")),
        }
    }
}

impl FmuLog {
    /// As [`agrisim_cosim::LoadOptions::fmu_log`]: `None` off, `Some(empty)` all categories.
    pub fn categories(&self) -> Option<Vec<String>> {
        match self {
            FmuLog::All(false) => None,
            FmuLog::All(true) => Some(Vec::new()),
            FmuLog::Categories(c) => Some(c.clone()),
        }
    }
}

fn default_name() -> String {
    "unnamed".into()
}
fn default_seed() -> u64 {
    1
}
fn default_duration() -> f64 {
    20.0
}
fn default_step() -> f64 {
    0.02
}
fn default_message_rate() -> f64 {
    10.0
}

impl Scenario {
    pub fn load(path: &Path) -> Result<Scenario> {
        let text = std::fs::read_to_string(path).context(|| format!("cannot read scenario {}", path.display()))?;
        Self::parse(&text, path)
    }

    pub fn parse(text: &str, path: &Path) -> Result<Scenario> {
        let mut s: Scenario = toml::from_str(text).context(|| format!("scenario {}", path.display()))?;
        s.path = path.to_path_buf();
        s.validate()?;
        Ok(s)
    }

    fn validate(&self) -> Result<()> {
        let file = self.path.display();
        let positive = |v: f64| v.is_finite() && v > 0.0;
        if !positive(self.duration) {
            return Err(agrisim_error::err!("scenario {file}: duration must be positive, got {}", self.duration));
        }
        if !positive(self.timing.step) || !positive(self.timing.message_rate) {
            return Err(agrisim_error::err!("scenario {file}: timing.step and timing.message_rate must be positive"));
        }
        for (i, c) in self.base_commands.iter().enumerate() {
            if !(c.t.is_finite() && c.t >= 0.0 && c.vx.is_finite() && c.vy.is_finite() && c.wz.is_finite()) {
                return Err(agrisim_error::err!(
                    "scenario {file}: base_commands[{i}] has a negative or non-finite value"
                ));
            }
            if i > 0 && c.t < self.base_commands[i - 1].t {
                return Err(agrisim_error::err!("scenario {file}: base_commands[{i}].t goes back in time"));
            }
        }
        for (i, c) in self.lift_commands.iter().enumerate() {
            if !(c.t.is_finite() && c.t >= 0.0 && c.position.is_finite())
                || (i > 0 && c.t < self.lift_commands[i - 1].t)
            {
                return Err(agrisim_error::err!(
                    "scenario {file}: lift_commands[{i}] is not finite, negative or out of order"
                ));
            }
        }
        if self.environment.is_some() {
            agrisim_sky::environment::Environment::from_toml_str(&self.environment_toml())
                .map_err(|e| agrisim_error::err!("scenario {file}: [environment]: {e}"))?;
        }
        for inj in &self.inject {
            inj.bytes().map_err(|e| agrisim_error::err!("scenario {file}: {e}"))?;
        }
        if let Some([lo, hi]) = self.harvest.fruit_radius {
            if !(positive(lo) && lo < hi && hi <= 0.1) {
                return Err(agrisim_error::err!(
                    "scenario {file}: [harvest] fruit_radius must be [least, largest] in metres, 0 < least < largest <= 0.1, got [{lo}, {hi}]"
                ));
            }
        }
        Ok(())
    }

    /// The `[greenhouse]` section as TOML text, with its layout `seed` filled in.
    pub fn scene_toml(&self) -> String {
        let mut t = self.greenhouse.clone();
        t.entry("seed").or_insert(toml::Value::Integer(self.seed as i64));
        toml::to_string(&t).expect("a TOML table serializes")
    }

    /// The `[environment]` section as TOML text; empty when the scenario has none.
    pub fn environment_toml(&self) -> String {
        self.environment.as_ref().map_or(String::new(), |t| toml::to_string(t).expect("a TOML table serializes"))
    }

    /// The system file, resolved against the scenario's directory.
    pub fn system_path(&self) -> PathBuf {
        self.path.parent().unwrap_or(Path::new(".")).join(&self.system.file)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unknown_keys_are_errors_naming_the_file() {
        let e = Scenario::parse("[system]\nfile = \"a.ssd\"\nduraton = 3\n", Path::new("x.toml")).unwrap_err();
        assert!(e.0.contains("x.toml") && e.0.contains("duraton"), "{e}");
    }

    #[test]
    fn defaults_are_the_papers_timing() {
        let s = Scenario::parse("[system]\nfile = \"a.ssd\"\n", Path::new("dir/x.toml")).unwrap();
        assert_eq!((s.timing.step, s.timing.message_rate), (0.02, 10.0));
        assert_eq!(s.timing.algorithm, MasterAlgorithm::GaussSeidel);
        assert_eq!(s.system_path(), Path::new("dir/a.ssd"));
    }

    #[test]
    fn the_master_algorithm_is_chosen_by_name() {
        let parse = |a: &str| {
            Scenario::parse(
                &format!("[system]\nfile = \"a.ssd\"\n[timing]\nalgorithm = \"{a}\"\n"),
                Path::new("x.toml"),
            )
        };
        assert_eq!(parse("jacobi").unwrap().timing.algorithm, MasterAlgorithm::Jacobi);
        assert_eq!(parse("gauss-seidel").unwrap().timing.algorithm.name(), "gauss-seidel");
        let e = parse("parallel").unwrap_err();
        assert!(e.0.contains("x.toml") && e.0.contains("jacobi"), "{e}");
    }

    #[test]
    fn fmu_logging_is_off_by_default_and_chosen_by_category() {
        let parse = |extra: &str| Scenario::parse(&format!("[system]\nfile = \"a.ssd\"\n{extra}"), Path::new("x.toml"));
        assert_eq!(parse("").unwrap().logging.fmu.categories(), None);
        assert_eq!(parse("[logging]\nfmu = false\n").unwrap().logging.fmu.categories(), None);
        assert_eq!(parse("[logging]\nfmu = true\n").unwrap().logging.fmu.categories(), Some(vec![]));
        let s = parse("[logging]\nfmu = [\"logModel\", \"logCalls\"]\n").unwrap();
        assert_eq!(s.logging.fmu.categories(), Some(vec!["logModel".to_string(), "logCalls".to_string()]));
        for bad in ["[logging]\nfmu = []\n", "[logging]\nfmu = 3\n", "[logging]\nfmu = [1]\n"] {
            let e = parse(bad).unwrap_err();
            assert!(e.0.contains("x.toml") && e.0.contains("expected true, false or a non-empty list"), "{e}");
        }
        let e = parse("[logging]\nfmus = true\n").unwrap_err();
        assert!(e.0.contains("x.toml") && e.0.contains("fmus"), "{e}");
    }

    #[test]
    fn nav_planner_and_controller_are_named_with_astar_and_dwa_by_default() {
        let s = Scenario::parse("[system]\nfile = \"a.ssd\"\n", Path::new("x.toml")).unwrap();
        assert_eq!((s.nav.planner.as_str(), s.nav.controller.as_str()), ("astar", "dwa"));
        let s =
            Scenario::parse("[system]\nfile = \"a.ssd\"\n[nav]\nplanner = \"straight_line\"\n", Path::new("x.toml"))
                .unwrap();
        assert_eq!((s.nav.planner.as_str(), s.nav.controller.as_str()), ("straight_line", "dwa"));
    }

    #[test]
    fn environment_is_validated_naming_the_key() {
        let e = Scenario::parse(
            "[system]\nfile = \"a.ssd\"\n[environment]\nweather = \"fog\"\nhumidity = 140.0\n",
            Path::new("x.toml"),
        )
        .unwrap_err();
        assert!(e.0.contains("x.toml") && e.0.contains("environment") && e.0.contains("humidity"), "{e}");
        let s = Scenario::parse("[system]\nfile = \"a.ssd\"\n[environment]\nweather = \"fog\"\n", Path::new("x.toml"))
            .unwrap();
        assert_eq!(s.environment_toml().trim(), "weather = \"fog\"");
        let s = Scenario::parse("[system]\nfile = \"a.ssd\"\n", Path::new("x.toml")).unwrap();
        assert_eq!(s.environment_toml(), "");
    }

    #[test]
    fn the_fruit_radius_prior_is_checked() {
        let parse = |v: &str| {
            Scenario::parse(
                &format!("[system]\nfile = \"a.ssd\"\n[harvest]\nfruit_radius = {v}\n"),
                Path::new("x.toml"),
            )
        };
        assert_eq!(parse("[0.012, 0.018]").unwrap().harvest.fruit_radius, Some([0.012, 0.018]));
        for bad in ["[0.018, 0.012]", "[0.0, 0.02]", "[12.0, 18.0]"] {
            let e = parse(bad).unwrap_err();
            assert!(e.0.contains("x.toml") && e.0.contains("fruit_radius"), "{bad}: {e}");
        }
        assert!(parse("[0.012]").is_err());
    }
}
