//! `agrisim`: the command-line front of the orchestrator: runs, benchmarks, FMU packing,
//! snapshots and scene export, with progress on a terminal and quiet in pipes.

mod live;
mod pack;
mod png;
mod snapshot;

use agrisim_error::Result;
use agrisim_session::{interrupt, Profile, RunOptions, Scenario};
use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "agrisim",
    version,
    about = "Greenhouse-robotics co-simulation: FMUs, SSP systems, ROS 2 messages, MCAP logs"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scenario's system and record DIR/run.mcap.
    Run {
        /// Scenario file (TOML).
        #[arg(long, default_value = "models/scenarios/default.toml")]
        scenario: PathBuf,
        /// Simulated duration [s] (default: the scenario's).
        #[arg(long)]
        duration: Option<f64>,
        /// Master seed (default: the scenario's).
        #[arg(long)]
        seed: Option<u64>,
        /// Replace a component's FMU: COMPONENT=FILE.fmu (e.g. chassis=ChassisDynamic.fmu).
        #[arg(long = "fmu", value_parser = parse_override)]
        fmus: Vec<(String, String)>,
        #[command(flatten)]
        dirs: Dirs,
        #[command(flatten)]
        log: FmuLog,
        #[command(flatten)]
        record: Record,
        #[command(flatten)]
        live: live::LiveArgs,
        /// Print how the master orders the system (step order, delayed connections,
        /// initialization, exchange periods) and exit without running.
        #[arg(long)]
        explain: bool,
        /// Output directory.
        #[arg(long, required_unless_present = "explain")]
        out: Option<PathBuf>,
    },
    /// Benchmarks.
    Bench {
        #[command(subcommand)]
        command: BenchCommand,
    },
    /// Pictures of the default view: DIR/rgb.png, DIR/depth.png, DIR/lidar_top.png, DIR/lidar_near.png.
    Snapshot {
        #[arg(long, default_value = "models/scenarios/default.toml")]
        scenario: PathBuf,
        #[command(flatten)]
        dirs: Dirs,
        #[arg(long)]
        out: PathBuf,
    },
    /// The greenhouse scene.
    Scene {
        #[command(subcommand)]
        command: SceneCommand,
    },
    /// FMU packaging.
    Fmu {
        #[command(subcommand)]
        command: FmuCommand,
    },
}

#[derive(Subcommand)]
enum FmuCommand {
    /// Write target/fmu/<Name>.fmu (FMI 3.0), target/fmu/fmi2/<Name>.fmu (FMI 2.0) and a
    /// self-contained target/ssp/<system>.ssp for every system file.
    Pack {
        /// Directory with the built FMU libraries (default: this executable's directory).
        #[arg(long)]
        lib_dir: Option<PathBuf>,
        /// Output directory (default: target/fmu next to the build directory).
        #[arg(long)]
        out: Option<PathBuf>,
        /// System files to pack as .ssp archives (default: models/systems of the checkout).
        #[arg(long)]
        systems: Option<PathBuf>,
        /// Where the .ssp archives go (default: target/ssp).
        #[arg(long)]
        ssp_out: Option<PathBuf>,
    },
}

#[derive(Subcommand)]
enum BenchCommand {
    /// The navigation experiment: N trials to seeded targets; DIR/summary.json, trials.jsonl,
    /// trials/<NNNN>.mcap, report.html (default scenario: models/scenarios/default.toml).
    Nav(TrialArgs),
    /// The dual-arm harvesting experiment: N trials on seeded ripe fruit; DIR/summary.json,
    /// trials.jsonl, trials/<NNNN>.mcap, report.html (default scenario:
    /// models/scenarios/harvest.toml).
    Harvest(TrialArgs),
    /// The whole-row harvest: N aisle segments (both sides), every reachable ripe fruit in
    /// them harvested in turn; DIR/summary.json, trials.jsonl, trials/<NNNN>.mcap, report.html
    /// (default scenario: models/scenarios/harvest.toml; --trials is the number of segments).
    Row {
        #[command(flatten)]
        trials: TrialArgs,
        /// Segment length along the aisle [m].
        #[arg(long, default_value_t = 10.0)]
        length: f64,
    },
    /// Orchestrator cost per FMU and step, beside the bare fmi3DoStep cost (JSON on stdout).
    Overhead {
        #[arg(long, default_value = "models/scenarios/default.toml")]
        scenario: PathBuf,
        #[arg(long, default_value_t = 5000)]
        steps: u64,
        #[command(flatten)]
        dirs: Dirs,
        #[command(flatten)]
        log: FmuLog,
        #[command(flatten)]
        record: Record,
        #[arg(long)]
        out: PathBuf,
    },
}

/// What a many-trial benchmark takes.
#[derive(clap::Args)]
struct TrialArgs {
    /// Scenario file (default: the benchmark's own).
    #[arg(long)]
    scenario: Option<PathBuf>,
    #[arg(long, default_value_t = 50)]
    trials: u64,
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Scenes the trials are spread over (round robin): scene k is the scenario's greenhouse
    /// grown from its seed + k. The summary gives per-scene results and a cluster-bootstrap
    /// interval beside Wilson's.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..=10_000))]
    scenes: u64,
    #[command(flatten)]
    dirs: Dirs,
    #[command(flatten)]
    log: FmuLog,
    #[command(flatten)]
    record: Record,
    #[command(flatten)]
    live: live::LiveArgs,
    /// Keep the trials already complete in DIR (an interrupted run) and run the others.
    #[arg(long)]
    resume: bool,
    /// Trials run at once, each in its own worker process (a trial whose process dies, e.g.
    /// a foreign FMU that segfaults, is recorded as an error and the benchmark goes on).
    #[arg(long, default_value_t = 1)]
    jobs: usize,
    /// Run the trials one after the other inside this process (no worker processes).
    #[arg(long, conflicts_with = "jobs")]
    in_process: bool,
    /// Internal: run trial N only, as a worker process of a benchmark.
    #[arg(long, hide = true)]
    worker_trial: Option<u64>,
    #[arg(long)]
    out: PathBuf,
}

impl TrialArgs {
    fn plan(&self) -> agrisim_bench::trials::TrialPlan {
        agrisim_bench::trials::TrialPlan { trials: self.trials, seed: self.seed, scenes: self.scenes }
    }
}

#[derive(Subcommand)]
enum SceneCommand {
    /// Write the scenario's greenhouse as binary glTF (.glb) for any 3D viewer.
    Export {
        #[arg(long, default_value = "models/scenarios/default.toml")]
        scenario: PathBuf,
        #[arg(long)]
        out: PathBuf,
    },
}

#[derive(clap::Args, Clone)]
struct Dirs {
    /// Directory of packed FMUs (default: target/fmu next to this executable's build directory).
    #[arg(long)]
    fmu_dir: Option<PathBuf>,
    /// Where FMU archives are unpacked (default: target/fmu-cache).
    #[arg(long)]
    cache_dir: Option<PathBuf>,
}

#[derive(clap::Args, Clone)]
struct FmuLog {
    /// FMU debug logging to stderr (off by default; warnings and errors are always shown):
    /// bare = every category, or comma-separated categories (e.g. logModel,logCalls).
    /// Replaces the scenario's [logging] fmu.
    #[arg(long = "fmu-log", value_name = "CATEGORIES", num_args = 0..=1, default_missing_value = "")]
    fmu_log: Option<String>,
}

#[derive(clap::Args, Clone)]
struct Record {
    /// Recording profile: full, standard, judge or none (default: full for `run` and
    /// `bench overhead`, standard for the trial benchmarks); replaces the scenario's
    /// [recording] profile.
    #[arg(long = "record", value_name = "PROFILE")]
    profile: Option<Profile>,
}

impl FmuLog {
    /// As `RunOptions::fmu_log`: `Some(empty)` = every category.
    fn categories(&self) -> Option<Vec<String>> {
        self.fmu_log.as_ref().map(|s| s.split(',').map(str::trim).filter(|c| !c.is_empty()).map(String::from).collect())
    }
}

fn parse_override(s: &str) -> std::result::Result<(String, String), String> {
    s.split_once('=')
        .map(|(a, b)| (a.to_string(), b.to_string()))
        .ok_or_else(|| format!("expected COMPONENT=FILE.fmu, got '{s}'"))
}

/// target/<profile>/ of this executable, and target/.
fn build_dirs() -> (PathBuf, PathBuf) {
    let exe_dir = std::env::current_exe()
        .ok()
        .and_then(|p| p.parent().map(|d| d.to_path_buf()))
        .unwrap_or_else(|| PathBuf::from("target/release"));
    let target = exe_dir.parent().map(|p| p.to_path_buf()).unwrap_or_else(|| PathBuf::from("target"));
    (exe_dir, target)
}

/// A progress bar on stderr (k done of n); indicatif hides it when stderr is not a terminal,
/// so pipes and CI logs get nothing.
fn progress_printer() -> impl FnMut(u64, u64) {
    let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template("[{bar:40}] {percent:>3}% {pos}/{len} ({elapsed}, eta {eta})")
            .expect("valid template")
            .progress_chars("# "),
    );
    move |k, n| {
        if bar.length() != Some(n) {
            bar.set_length(n);
        }
        bar.set_position(k);
        if k >= n && !bar.is_finished() {
            bar.finish();
        }
    }
}

fn run_options(
    dirs: Dirs,
    target: &std::path::Path,
    seed: Option<u64>,
    duration: Option<f64>,
    fmu_overrides: BTreeMap<String, String>,
    fmu_log: Option<Vec<String>>,
) -> RunOptions {
    RunOptions {
        fmu_dir: dirs.fmu_dir.unwrap_or_else(|| target.join("fmu")),
        cache_dir: dirs.cache_dir.unwrap_or_else(|| target.join("fmu-cache")),
        seed,
        duration,
        fmu_overrides,
        fmu_log,
        record: None,
        nodes: Default::default(),
    }
}

/// Exit status after a stop request (128 + SIGINT, as shells report it).
const EXIT_INTERRUPTED: u8 = 130;

fn main() -> ExitCode {
    // SIGINT/SIGTERM: stop at the next step boundary (files finished, completed trials
    // summarized); a second one exits at once.
    let _ = ctrlc::set_handler(|| {
        if interrupt::request() {
            eprintln!("agrisim: second interrupt: exiting now");
            std::process::exit(EXIT_INTERRUPTED as i32);
        }
        eprintln!(
            "agrisim: interrupt: stopping at the next step and finishing the files (interrupt again to exit at once)"
        );
    });
    let result = real_main();
    if interrupt::requested() {
        match result {
            Err(e) if !e.0.starts_with(interrupt::INTERRUPTED) => eprintln!("agrisim: error: {e}"),
            Err(e) => eprintln!("agrisim: {e}; what was recorded up to there is complete"),
            Ok(()) => eprintln!("agrisim: interrupted; the files of what completed are written"),
        }
        return ExitCode::from(EXIT_INTERRUPTED);
    }
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("agrisim: error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// This very command line, as a worker process that runs trial `i` only.
fn worker_command(i: u64) -> std::process::Command {
    let exe = std::env::current_exe().unwrap_or_else(|_| PathBuf::from("agrisim"));
    let mut c = std::process::Command::new(exe);
    c.args(std::env::args_os().skip(1))
        .arg("--worker-trial")
        .arg(i.to_string())
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::null());
    c
}

/// How a benchmark runs its trials.
fn exec<'a>(a: &TrialArgs, command: &'a dyn Fn(u64) -> std::process::Command) -> agrisim_bench::trials::Exec<'a> {
    if a.in_process {
        agrisim_bench::trials::Exec::InProcess
    } else {
        agrisim_bench::trials::Exec::Workers { jobs: a.jobs, command }
    }
}

/// The scenario (or the benchmark's default) and run options of a many-trial benchmark.
fn trial_setup(
    a: &TrialArgs,
    default_scenario: &str,
    target: &Path,
    bridges: &Bridges,
) -> Result<(Scenario, RunOptions)> {
    let s = Scenario::load(a.scenario.as_deref().unwrap_or(Path::new(default_scenario)))?;
    let mut o = run_options(a.dirs.clone(), target, None, None, BTreeMap::new(), a.log.categories());
    o.record = a.record.profile;
    if (a.live.ros2 || a.live.foxglove.is_some()) && a.jobs > 1 {
        return Err(agrisim_error::err!("--ros2 and --foxglove run one trial at a time (trials would share the DDS topics and the port): use --jobs 1"));
    }
    o.nodes = a.live.plan(bridges)?;
    Ok((s, o))
}

/// The ROS 2 bridges' statistics of this process's runs.
type Bridges = std::sync::Arc<std::sync::Mutex<Vec<std::sync::Arc<std::sync::Mutex<agrisim_ros2::Stats>>>>>;

fn real_main() -> Result<()> {
    let cli = Cli::parse();
    let bridges = Bridges::default();
    let stats_file = match &cli.command {
        Command::Run { live, .. } => live.ros2_stats.clone(),
        Command::Bench {
            command: BenchCommand::Nav(a) | BenchCommand::Harvest(a) | BenchCommand::Row { trials: a, .. },
        } => a.live.ros2_stats.clone(),
        _ => None,
    };
    let result = dispatch(cli, &bridges);
    if let Some(line) = live::report(&bridges, stats_file.as_deref())? {
        eprintln!("{line}");
    }
    result
}

fn dispatch(cli: Cli, bridges: &Bridges) -> Result<()> {
    let (exe_dir, target) = build_dirs();
    match cli.command {
        Command::Run { scenario, duration, seed, fmus, dirs, log, record, live, explain, out } => {
            let s = Scenario::load(&scenario)?;
            let mut opts = run_options(dirs, &target, seed, duration, fmus.into_iter().collect(), log.categories());
            opts.record = record.profile;
            opts.nodes = live.plan(bridges)?;
            if explain {
                print!("{}", agrisim_session::run::explain(&s, &opts)?);
                return Ok(());
            }
            let out = out.expect("clap requires --out without --explain");
            let summary = agrisim_session::run::run(&s, &opts, &out, progress_printer())?;
            println!("{} steps ({} s simulated) -> {}", summary.steps, summary.simulated, summary.mcap.display());
        }
        Command::Bench { command: BenchCommand::Nav(a) } => {
            let (s, opts) = trial_setup(&a, "models/scenarios/default.toml", &target, bridges)?;
            if let Some(i) = a.worker_trial {
                return agrisim_bench::nav::nav_worker(&s, &opts, a.plan(), &a.out, i);
            }
            let command = worker_command;
            let summary = agrisim_bench::nav::bench_nav(
                &s,
                &opts,
                a.plan(),
                &a.out,
                a.resume,
                exec(&a, &command),
                progress_printer(),
            )?;
            println!("{}", serde_json::to_string_pretty(&summary).expect("plain struct serializes"));
        }
        Command::Bench { command: BenchCommand::Harvest(a) } => {
            let (s, opts) = trial_setup(&a, "models/scenarios/harvest.toml", &target, bridges)?;
            if let Some(i) = a.worker_trial {
                return agrisim_bench::harvest::harvest_worker(&s, &opts, a.plan(), &a.out, i);
            }
            let command = worker_command;
            let summary = agrisim_bench::harvest::bench_harvest(
                &s,
                &opts,
                a.plan(),
                &a.out,
                a.resume,
                exec(&a, &command),
                progress_printer(),
            )?;
            println!("{}", serde_json::to_string_pretty(&summary).expect("plain struct serializes"));
        }
        Command::Bench { command: BenchCommand::Row { trials: a, length } } => {
            let (s, opts) = trial_setup(&a, "models/scenarios/harvest.toml", &target, bridges)?;
            if let Some(i) = a.worker_trial {
                return agrisim_bench::row::row_worker(&s, &opts, a.plan(), length, &a.out, i);
            }
            let command = worker_command;
            let summary = agrisim_bench::row::bench_row(
                &s,
                &opts,
                a.plan(),
                length,
                &a.out,
                a.resume,
                exec(&a, &command),
                progress_printer(),
            )?;
            println!("{}", serde_json::to_string_pretty(&summary).expect("plain struct serializes"));
        }
        Command::Bench { command: BenchCommand::Overhead { scenario, steps, dirs, log, record, out } } => {
            let s = Scenario::load(&scenario)?;
            let mut opts = run_options(dirs, &target, None, None, BTreeMap::new(), log.categories());
            opts.record = record.profile;
            let report = agrisim_bench::overhead(&s, &opts, steps, &out)?;
            println!("{}", serde_json::to_string_pretty(&report).expect("plain struct serializes"));
        }
        Command::Snapshot { scenario, dirs, out } => {
            let s = Scenario::load(&scenario)?;
            let opts = run_options(dirs, &target, None, None, BTreeMap::new(), None);
            for p in snapshot::snapshot(&s, &opts, &out)? {
                println!("{}", p.display());
            }
        }
        Command::Scene { command: SceneCommand::Export { scenario, out } } => {
            let s = Scenario::load(&scenario)?;
            let g = agrisim_session::scene::generate_scene(&s)?;
            agrisim_greenhouse::gltf::write_glb(&g.objects, &out)
                .map_err(|e| agrisim_error::err!("cannot write {}: {e}", out.display()))?;
            println!("{} objects -> {}", g.objects.len(), out.display());
        }
        Command::Fmu { command: FmuCommand::Pack { lib_dir, out, systems, ssp_out } } => {
            let lib_dir = lib_dir.unwrap_or(exe_dir);
            let out = out.unwrap_or_else(|| target.join("fmu"));
            for p in pack::pack_all(&lib_dir, &out)? {
                match &p.fmi2 {
                    Some(f2) => println!("{}: {} {}", p.model_identifier, p.fmi3.display(), f2.display()),
                    None => println!("{}: {}", p.model_identifier, p.fmi3.display()),
                }
            }
            let systems = systems.unwrap_or_else(|| target.parent().unwrap_or(Path::new(".")).join("models/systems"));
            for p in pack::pack_ssps(&systems, &out, &ssp_out.unwrap_or_else(|| target.join("ssp")))? {
                println!("{}", p.display());
            }
        }
    }
    Ok(())
}
