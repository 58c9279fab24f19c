//! Cost of the Greenhouse model on the default (6-row) and on the paper's complete 160-row
//! house: instantiate + initialize (scene generation, rapier world, first report), resident
//! memory, per-step cost while driving an aisle, one fruit_poses message, an FMU-state copy.
//!
//! `cargo run --release -p agrisim-fmu-world --example measure`

use agrisim_fmi::{Log, Model, Store, Value};
use agrisim_fmu_world::ground_truth::fruit_poses;
use agrisim_fmu_world::ports::*;
use agrisim_fmu_world::GreenhouseWorld;
use agrisim_greenhouse::config::GreenhouseConfig;
use agrisim_greenhouse::layout::Layout;
use agrisim_msgs::Message;
use std::time::Instant;

struct Quiet;
impl Log for Quiet {
    fn info(&mut self, _: &str) {}
    fn warning(&mut self, _: &str) {}
}

/// Resident set size [MiB] (Linux).
fn rss_mib() -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let kib = status
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<f64>().ok())
        .unwrap_or(f64::NAN);
    kib / 1024.0
}

/// Steps driving `aisle` end to end at 1 m/s (0.02 m per 0.02 s step); mean wall time per step.
fn drive(m: &mut GreenhouseWorld, io: &mut Store, layout: &Layout) -> (f64, usize) {
    let a = &layout.aisles[0];
    let steps = ((a.x_end - a.x_start) / 0.02) as usize;
    let t = Instant::now();
    for k in 0..steps {
        io.set_f64(BASE_X, a.x_start + 0.02 * k as f64);
        io.set_f64(BASE_Y, a.y);
        io.set_f64(BASE_YAW, 0.0);
        m.do_step(io, k as f64 * 0.02, 0.02, &mut Quiet).unwrap();
    }
    assert!(!io.bool(COLLISION));
    (t.elapsed().as_secs_f64() / steps as f64, steps)
}

fn measure(label: &str, scene: &str) {
    let cfg = GreenhouseConfig::from_toml_str(scene).unwrap();
    let layout = Layout::from_config(&cfg);
    let tg = Instant::now();
    drop(agrisim_greenhouse::generate(&cfg, cfg.seed));
    let generate_s = tg.elapsed().as_secs_f64();

    let rss0 = rss_mib();
    let t0 = Instant::now();
    let mut io = Store::new(GreenhouseWorld::VARIABLES);
    *io.value_mut(SCENE) = Value::String(scene.to_string());
    let [x, y, yaw] = layout.start_pose;
    io.set_f64(BASE_X, x);
    io.set_f64(BASE_Y, y);
    io.set_f64(BASE_YAW, yaw);
    io.set_i32(TARGET_FRUIT, 0);
    io.set_f64(FRUIT_RATE, 1e-3); // fruit_poses only at t = 0: the step cost without it
    let mut m = GreenhouseWorld::new();
    m.initialize(&mut io, 0.0, &mut Quiet).unwrap();
    let init = t0.elapsed().as_secs_f64();
    let rss1 = rss_mib();
    let objects = m.scene().map_or(0, |s| s.objects.len());
    let (step, steps) = drive(&mut m, &mut io, &layout);

    // One fruit_poses publication: build, encode, store.
    let n = 5;
    let t = Instant::now();
    let mut bytes = 0;
    for k in 0..n {
        let cdr = fruit_poses(m.scene().unwrap(), k).to_cdr();
        bytes = cdr.len();
        io.set_binary(FRUIT_POSES, &cdr);
    }
    let fruit_msg = t.elapsed().as_secs_f64() / n as f64;

    let t2 = Instant::now();
    let copy = m.clone();
    let clone_s = t2.elapsed().as_secs_f64();
    let rss2 = rss_mib();
    drop(copy);
    println!(
        "{label}: {objects} objects, {} fruit\n  instantiate+init {:.3} s (generator {:.3} s), +{:.0} MiB resident\n  \
         step {:.1} us (mean of {steps}, driving an aisle; collision_state at 10 Hz)\n  \
         fruit_poses message {:.2} ms ({:.2} MB CDR), i.e. +{:.1} us per 0.02 s step at fruit_rate 1 Hz\n  \
         FMU-state copy {:.3} s, +{:.0} MiB",
        io.i32(FRUIT_COUNT),
        init,
        generate_s,
        rss1 - rss0,
        step * 1e6,
        fruit_msg * 1e3,
        bytes as f64 / 1e6,
        fruit_msg * 1e6 / 50.0,
        clone_s,
        rss2 - rss1
    );
}

fn main() {
    measure("default (6 rows)", "");
    measure("160 rows", "rows = 160\nwidth = 420.0");
}
