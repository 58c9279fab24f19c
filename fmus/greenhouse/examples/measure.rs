//! Cost of the Greenhouse model on the default (6-row) and on the paper's complete 160-row
//! house: instantiate + initialize (scene generation, rapier world, first report), resident
//! memory, per-step cost while driving an aisle, one fruit_poses message, an FMU-state copy;
//! and on the default house the step cost with the robot parked and its arms static, with
//! both arms moving, and while a released fruit falls, plus one planning_scene message.
//!
//! `cargo run --release -p agrisim-fmu-greenhouse --example measure`

use agrisim_fmi::{Model, Quiet, Store, Value};
use agrisim_fmu_greenhouse::ground_truth::fruit_poses;
use agrisim_fmu_greenhouse::ports::*;
use agrisim_fmu_greenhouse::GreenhouseWorld;
use agrisim_msgs::Message;
use agrisim_scene::config::GreenhouseConfig;
use agrisim_scene::layout::Layout;
use std::time::Instant;

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
    drop(agrisim_scene::generate(&cfg, cfg.seed));
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

/// Mean wall time per step [us] over `n` steps of `drive(k)` (inputs set per step).
fn time_steps(
    m: &mut GreenhouseWorld,
    io: &mut Store,
    t0: f64,
    n: usize,
    mut drive: impl FnMut(&mut Store, usize),
) -> f64 {
    let t = Instant::now();
    for k in 0..n {
        drive(io, k);
        m.do_step(io, t0 + k as f64 * 0.02, 0.02, &mut Quiet).unwrap();
    }
    t.elapsed().as_secs_f64() / n as f64 * 1e6
}

const LEFT_Q: [usize; 7] = [LEFT_Q1, LEFT_Q2, LEFT_Q3, LEFT_Q4, LEFT_Q5, LEFT_Q6, LEFT_Q7];
const RIGHT_Q: [usize; 7] = [RIGHT_Q1, RIGHT_Q2, RIGHT_Q3, RIGHT_Q4, RIGHT_Q5, RIGHT_Q6, RIGHT_Q7];

fn measure_arms() {
    use agrisim_fmu_greenhouse::robot_model::READY_POSE;
    let layout = Layout::from_config(&GreenhouseConfig::default());
    let a = &layout.aisles[1];
    let mut io = Store::new(GreenhouseWorld::VARIABLES);
    io.set_f64(BASE_X, 0.5 * (a.x_start + a.x_end));
    io.set_f64(BASE_Y, a.y);
    io.set_f64(FRUIT_RATE, 1e-3);
    io.set_f64(PLANNING_SCENE_RATE, 1e-3);
    let mut m = GreenhouseWorld::new();
    m.initialize(&mut io, 0.0, &mut Quiet).unwrap();
    let n = 1000;
    let parked = time_steps(&mut m, &mut io, 0.0, n, |_, _| {});
    let moving = time_steps(&mut m, &mut io, 20.0, n, |io, k| {
        let s = (k as f64 * 0.02).sin();
        for (i, vr) in LEFT_Q.into_iter().enumerate() {
            io.set_f64(vr, READY_POSE[i] + 0.3 * s);
        }
        for (i, vr) in RIGHT_Q.into_iter().enumerate() {
            io.set_f64(vr, READY_POSE[i] - 0.3 * s);
        }
        io.set_f64(LIFT_POSITION, 0.3 + 0.2 * s);
    });
    // Driving with the arms static (the navigation case).
    let x0 = io.f64(BASE_X);
    let driving = time_steps(&mut m, &mut io, 40.0, n, |io, k| io.set_f64(BASE_X, x0 - 0.01 * k as f64));
    let falling = measure_fall();
    let scene = m.scene().unwrap();
    let harvest_free = agrisim_fmu_greenhouse::harvest::Harvest::new(
        agrisim_fmu_greenhouse::harvest::HarvestParams::new(0.003, 0.005),
        [0.08; 2],
        [agrisim_robot::Pose::IDENTITY; 2],
    );
    let t = Instant::now();
    let msg = agrisim_fmu_greenhouse::planning_scene::planning_scene(
        scene,
        &harvest_free,
        [io.f64(BASE_X), io.f64(BASE_Y)],
        2.5,
        0,
    );
    let bytes = msg.to_cdr().len();
    let scene_ms = t.elapsed().as_secs_f64() * 1e3;
    println!(
        "arms (default house, mean of {n} steps of 0.02 s):\n  parked, arms static {parked:.1} us\n  parked, both arms + lift moving {moving:.1} us\n  \
         driving, arms static {driving:.1} us\n  a released fruit falling (physics substeps of 5 ms) {falling:.1} us\n  planning_scene message: {} objects, {:.1} kB CDR, {scene_ms:.2} ms",
        msg.objects.len(),
        bytes as f64 / 1e3
    );
}

/// Mean step cost [us] while a released fruit falls: the base is put so the left TCP (ready
/// pose) is on a fruit, the gripper closes, the lift rises 0.2 m, the gripper opens.
fn measure_fall() -> f64 {
    use agrisim_fmu_greenhouse::robot_model::{Coords, RobotModel};
    let model = RobotModel::load().unwrap();
    let cfg = GreenhouseConfig::default();
    let gh = agrisim_scene::generate(&cfg, cfg.seed);
    let mut fk = Vec::new();
    model.fk(&Coords::default(), &mut fk);
    let tcp0 = fk[model.link_index("left_hand_tcp").unwrap()].trans;
    let fruit = gh
        .objects
        .iter()
        .find(|o| {
            matches!(o.kind, agrisim_scene::scene::Kind::Fruit { .. }) && o.placement.translation[2] > tcp0[2] + 0.1
        })
        .unwrap();
    let p = fruit.placement.translation;
    let lift = p[2] - tcp0[2];
    model.fk(&Coords { lift, ..Coords::default() }, &mut fk);
    let tcp = fk[model.link_index("left_hand_tcp").unwrap()].trans;
    let mut io = Store::new(GreenhouseWorld::VARIABLES);
    let (x, y) = (p[0] - tcp[0], p[1] - tcp[1]);
    io.set_f64(BASE_X, x);
    io.set_f64(BASE_Y, y);
    io.set_f64(LIFT_POSITION, lift);
    io.set_f64(FRUIT_RATE, 1e-3);
    io.set_f64(PLANNING_SCENE_RATE, 1e-3);
    // Lifted straight up, a fruit on its pedicel is pushed toward its truss and never comes
    // off: this measures the fall, so the fruit leaves its plant as the fingers close.
    io.set_bool(PEDICEL_ENABLED, false);
    let mut m = GreenhouseWorld::new();
    m.initialize(&mut io, 0.0, &mut Quiet).unwrap();
    time_steps(&mut m, &mut io, 0.0, 10, |io, k| io.set_f64(LEFT_FINGER_WIDTH, 0.08 - 0.01 * (k + 1) as f64));
    assert!(io.i32(LEFT_HELD_ID) >= 0, "grasped");
    time_steps(&mut m, &mut io, 0.2, 20, |io, k| io.set_f64(LIFT_POSITION, lift + 0.01 * (k + 1) as f64));
    io.set_f64(LEFT_FINGER_WIDTH, 0.08);
    let mut n = 0;
    let t = Instant::now();
    while io.i32(DROPPED_COUNT) + io.i32(PLACED_COUNT) == 0 && n < 500 {
        m.do_step(&mut io, 0.6 + n as f64 * 0.02, 0.02, &mut Quiet).unwrap();
        n += 1;
    }
    assert!(n < 500, "the fruit settles");
    t.elapsed().as_secs_f64() / n as f64 * 1e6
}

fn main() {
    measure_arms();
    measure("default (6 rows)", "");
    measure("160 rows", "rows = 160\nwidth = 420.0");
}
