//! `agrisim`: the command-line front of the orchestrator: runs, benchmarks, FMU packing,
//! snapshots and scene export, with progress on a terminal and quiet in pipes.

mod live;
mod pack;
mod png;
mod snapshot;

use agrisim_bench::{Job, Registry};
use agrisim_error::Result;
use agrisim_session::{interrupt, Profile, RunOptions, Scenario};
use clap::{Args, CommandFactory, FromArgMatches, Parser, Subcommand};
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
        // Boxed: the largest flags by far, and the one variant that has them.
        #[command(flatten)]
        live: Box<live::LiveArgs>,
        /// Print how the master orders the system (step order, delayed connections,
        /// initialization, exchange periods) and exit without running.
        #[arg(long)]
        explain: bool,
        /// Output directory.
        #[arg(long, required_unless_present = "explain")]
        out: Option<PathBuf>,
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
    /// A synthetic perception dataset: per frame RGB, depth (16-bit mm), instance masks, camera
    /// intrinsics and pose, fruit poses; one COCO file (categories: ripeness stages). Seeded
    /// domain randomization of robot pose, camera mount, sun, weather, crop, exposure.
    Dataset {
        #[arg(long, default_value = "models/scenarios/default.toml")]
        scenario: PathBuf,
        /// Number of frames.
        #[arg(long)]
        frames: u64,
        /// Seed of every random draw (two runs with one seed write identical files).
        #[arg(long)]
        seed: u64,
        /// Spread the frames over this many greenhouses (seeds scene seed + 0..K), in blocks.
        #[arg(long, default_value_t = 1)]
        scenes: u64,
        /// Image width [px] (default: the scenario's [parameters.camera], else 1280).
        #[arg(long)]
        width: Option<u32>,
        /// Image height [px] (default: the scenario's [parameters.camera], else 720).
        #[arg(long)]
        height: Option<u32>,
        /// Complete the dataset in DIR (same settings): keep its complete frames, render the rest.
        #[arg(long)]
        resume: bool,
        /// Rewrite DIR/annotations.json after every this many frames (and at the end).
        #[arg(long, default_value_t = 25)]
        coco_every: u64,
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
        /// Directory with the built libraries of the FMU crates, those marked
        /// `[package.metadata.agrisim] fmu` in their Cargo.toml (default: this executable's directory).
        #[arg(long)]
        lib_dir: Option<PathBuf>,
        /// Output directory (default: target/fmu next to the build directory).
        #[arg(long)]
        out: Option<PathBuf>,
        /// System files to pack as .ssp archives (default: models/systems of the checkout);
        /// those in its fmi2/ subdirectory are packed with the FMI 2.0 archives into fmi2/.
        #[arg(long)]
        systems: Option<PathBuf>,
        /// Where the .ssp archives go (default: target/ssp).
        #[arg(long)]
        ssp_out: Option<PathBuf>,
    },
}

// `bench overhead`: not a many-trial benchmark, so not in the benchmark registry.
#[derive(clap::Args)]
struct OverheadArgs {
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

/// `--fmu` of `agrisim bench`: the same component swaps as `agrisim run`.
#[derive(clap::Args, Clone)]
struct Swaps {
    /// Replace a component's FMU: COMPONENT=FILE.fmu (e.g. chassis=target/fmu/thirdparty/PyChassis.fmu);
    /// on top of the scenario's [system] fmus.
    #[arg(long = "fmu", value_parser = parse_override)]
    fmus: Vec<(String, String)>,
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

/// `COMPONENT=FILE.fmu`. A FILE that exists from the working directory is made absolute (a
/// user's own FMU); a bare name is looked up beside the system file, then among the packed FMUs.
fn parse_override(s: &str) -> std::result::Result<(String, String), String> {
    let (component, file) = s.split_once('=').ok_or_else(|| format!("expected COMPONENT=FILE.fmu, got '{s}'"))?;
    let file = match std::fs::canonicalize(file) {
        Ok(p) if p.is_file() => p.display().to_string(),
        _ => file.to_string(),
    };
    Ok((component.to_string(), file))
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

/// The ROS 2 bridges' statistics of this process's runs.
type Bridges = std::sync::Arc<std::sync::Mutex<Vec<std::sync::Arc<std::sync::Mutex<agrisim_ros2::Stats>>>>>;

/// The whole command line: the derived commands, and `bench` built from the benchmark
/// registry (every benchmark with the trial flags, its own options and this CLI's run flags).
fn command(registry: &Registry) -> clap::Command {
    let shared = |c: clap::Command| {
        live::LiveArgs::augment_args(Record::augment_args(FmuLog::augment_args(Swaps::augment_args(
            Dirs::augment_args(c),
        ))))
    };
    let overhead = OverheadArgs::augment_args(clap::Command::new("overhead"))
        .about("Orchestrator cost per FMU and step, beside the bare fmi3DoStep cost (JSON on stdout)");
    Cli::command().subcommand(agrisim_bench::cli::command(registry, &shared).subcommand(overhead))
}

/// `T` from matches of a command it was added to (clap's own error and exit otherwise).
fn args<T: FromArgMatches>(m: &clap::ArgMatches) -> T {
    T::from_arg_matches(m).unwrap_or_else(|e| e.exit())
}

fn real_main() -> Result<()> {
    let registry = agrisim_bench::registry();
    let matches = command(&registry).get_matches();
    let bridges = Bridges::default();
    let (stats_file, result) = match matches.subcommand() {
        Some(("bench", m)) => {
            let stats = match m.subcommand() {
                Some((name, sub)) if name != "overhead" => args::<live::LiveArgs>(sub).ros2_stats,
                _ => None,
            };
            (stats, bench(&registry, m, &bridges))
        }
        _ => {
            let cli: Cli = args(&matches);
            let stats = match &cli.command {
                Command::Run { live, .. } => live.ros2_stats.clone(),
                _ => None,
            };
            (stats, dispatch(cli, &bridges))
        }
    };
    if let Some(line) = live::report(&bridges, stats_file.as_deref())? {
        eprintln!("{line}");
    }
    result
}

/// `agrisim bench ...` (`m`: the matches of `bench`): a registered benchmark, a worker
/// process's trial of one, or `overhead`.
fn bench(registry: &Registry, m: &clap::ArgMatches, bridges: &Bridges) -> Result<()> {
    let (_, target) = build_dirs();
    if let Some(("overhead", sub)) = m.subcommand() {
        let OverheadArgs { scenario, steps, dirs, log, record, out } = args(sub);
        let s = Scenario::load(&scenario)?;
        let mut opts = run_options(dirs, &target, None, None, BTreeMap::new(), log.categories());
        opts.record = record.profile;
        let report = agrisim_bench::overhead(&s, &opts, steps, &out)?;
        println!("{}", serde_json::to_string_pretty(&report).expect("plain struct serializes"));
        return Ok(());
    }
    let (b, a, options) = agrisim_bench::cli::parse(registry, m)?;
    let sub = m.subcommand().expect("a benchmark was named").1;
    let (dirs, swaps, log, record, live): (Dirs, Swaps, FmuLog, Record, live::LiveArgs) =
        (args(sub), args(sub), args(sub), args(sub), args(sub));
    let s = Scenario::load(&a.scenario_path(b))?;
    let mut o = run_options(dirs, &target, None, None, swaps.fmus.into_iter().collect(), log.categories());
    o.record = record.profile;
    // The live links run one trial at a time: trials would share the topics and the port.
    let linked = live.ros2 || live.zenoh || live.foxglove.is_some();
    if linked && a.jobs.is_some_and(|j| j > 1) {
        return Err(agrisim_error::err!(
            "--ros2, --zenoh and --foxglove run one trial at a time (trials would share the topics and the port): use --jobs 1"
        ));
    }
    o.nodes = live.plan(bridges)?;
    let job = Job { scenario: s, run: o, plan: a.plan(), options, out: a.out.clone() };
    if let Some(i) = a.worker_trial {
        return registry.run_one(b.name(), &job, i);
    }
    let command = worker_command;
    let jobs = if linked { 1 } else { agrisim_bench::cli::default_jobs() };
    let summary = registry.run(b.name(), &job, a.resume, a.exec(jobs, &command), &mut progress_printer())?;
    println!("{summary}");
    Ok(())
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
        Command::Snapshot { scenario, dirs, out } => {
            let s = Scenario::load(&scenario)?;
            let opts = run_options(dirs, &target, None, None, BTreeMap::new(), None);
            for p in snapshot::snapshot(&s, &opts, &out)? {
                println!("{}", p.display());
            }
        }
        Command::Dataset { scenario, frames, seed, scenes, width, height, resume, coco_every, dirs, out } => {
            let s = Scenario::load(&scenario)?;
            let opts = run_options(dirs, &target, None, None, BTreeMap::new(), None);
            let o = agrisim_dataset::Options { frames, seed, scenes, width, height, resume, coco_every, out };
            let summary = agrisim_dataset::write(&s, &opts, &o, &mut progress_printer())?;
            println!(
                "{} frames ({} rendered now), {} annotations -> {}",
                summary.frames,
                summary.rendered,
                summary.annotations,
                summary.coco.display()
            );
        }
        Command::Scene { command: SceneCommand::Export { scenario, out } } => {
            let s = Scenario::load(&scenario)?;
            let g = agrisim_session::scene::generate_scene(&s)?;
            agrisim_gltf::write_glb(&g.objects, &out)
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
            for p in pack::pack_systems(&systems, &out, &ssp_out.unwrap_or_else(|| target.join("ssp")))? {
                println!("{}", p.display());
            }
        }
    }
    Ok(())
}
