//! Rays per second of whole frames: the default greenhouse, the robot at the layout's start
//! pose and in the middle of aisle 0, default sensor, the robot's links in their default pose.
//! `cargo run --release -p agrisim-fmu-lidar --example frame_rate [SCENE.toml-keys-file|-] [ROBOT_LINKS]`
//! (ROBOT_LINKS `false`: the base box only, as before the links were seen; THREADS: the
//! `cast_threads` parameter, default 2).
//! It prints a digest of the published clouds: equal digests = identical clouds.

use agrisim_fmi::{Model, Quiet, Store, Value};
use agrisim_fmu_lidar::ports::*;
use agrisim_fmu_lidar::Lidar;
use agrisim_scene::{generate, GreenhouseConfig};
use std::time::Instant;

fn main() {
    let scene = std::env::args()
        .nth(1)
        .filter(|p| p != "-")
        .map(|p| std::fs::read_to_string(p).expect("scene file"))
        .unwrap_or_default();
    let robot_links = std::env::args().nth(2).is_none_or(|s| s != "false");
    let threads: i32 = std::env::args().nth(3).map_or(2, |s| s.parse().expect("THREADS"));
    let cfg = GreenhouseConfig::from_toml_str(&scene).expect("scene");
    let t = Instant::now();
    let gh = generate(&cfg, cfg.seed);
    let aisle = &gh.layout.aisles[0];
    let poses =
        [("start pose", gh.layout.start_pose), ("aisle 0 middle", [0.5 * (aisle.x_start + aisle.x_end), aisle.y, 0.0])];
    let mut io = Store::new(Lidar::VARIABLES);
    *io.value_mut(SCENE) = Value::String(scene.clone());
    *io.value_mut(ROBOT_LINKS) = Value::Boolean(robot_links);
    *io.value_mut(CAST_THREADS) = Value::Int32(threads);
    let mut m = Lidar::new();
    m.initialize(&mut io, 0.0, &mut Quiet).expect("initialize");
    println!(
        "scene: {} objects, generated and prepared in {:.2} s",
        m.scene().unwrap().object_count(),
        t.elapsed().as_secs_f64()
    );
    let mut k = 0;
    for (name, [x, y, yaw]) in poses {
        io.set_f64(BASE_X, x);
        io.set_f64(BASE_Y, y);
        io.set_f64(BASE_YAW, yaw);
        // One second to settle on the new pose, then 2 s (20 frames) timed.
        for _ in 0..50 {
            m.do_step(&mut io, k as f64 * 0.02, 0.02, &mut Quiet).expect("step");
            k += 1;
        }
        let (mut rays, mut returns, mut secs) = (0usize, 0usize, 0.0);
        let mut digest = 0xcbf2_9ce4_8422_2325u64;
        for _ in 0..100 {
            let t = Instant::now();
            m.do_step(&mut io, k as f64 * 0.02, 0.02, &mut Quiet).expect("step");
            secs += t.elapsed().as_secs_f64();
            k += 1;
            if k % 5 == 0 {
                rays += io.i32(POINTS_IN_FRAME) as usize;
                returns += io.i32(RETURNS_IN_FRAME) as usize;
                digest = io.binary(POINTS).iter().fold(digest, |h, &b| (h ^ b as u64).wrapping_mul(0x0100_0000_01b3));
            }
        }
        println!("{name}: {rays} rays in {secs:.3} s = {:.0} rays/s ({:.1} % returns), {threads} thread(s), clouds {digest:016x}", rays as f64 / secs, 100.0 * returns as f64 / rays as f64);
    }
}
