//! Whole camera frames of one size on the default greenhouse, for timing the whole process
//! from outside (a baseline build side by side) and for checking that two builds render the
//! same frames: the robot in the middle of aisle 0 looking along the aisle and at a row,
//! FRAMES frames each, then each view's frame digest (FNV-1a of RGB, depth and labels).
//! `cargo run --release -p agrisim-fmu-camera --example camera_frames WIDTH HEIGHT [FRAMES] [THREADS] [ENVIRONMENT]`
//! (defaults: 4 frames, 1 thread, fixed sun and no environment).

use agrisim_fmi::{Model, Quiet, Store, Value};
use agrisim_fmu_camera::ports::*;
use agrisim_fmu_camera::Camera;
use agrisim_scene::{generate, GreenhouseConfig};
use std::time::Instant;

fn main() {
    let arg = |i: usize| std::env::args().nth(i);
    let (Some(w), Some(h)) = (arg(1).and_then(|s| s.parse().ok()), arg(2).and_then(|s| s.parse().ok())) else {
        eprintln!("usage: camera_frames WIDTH HEIGHT [FRAMES] [THREADS] [ENVIRONMENT]");
        std::process::exit(2);
    };
    let frames: usize = arg(3).and_then(|s| s.parse().ok()).unwrap_or(4);
    let threads: i32 = arg(4).and_then(|s| s.parse().ok()).unwrap_or(1);
    let environment = arg(5).unwrap_or_default();
    let cfg = GreenhouseConfig::from_toml_str("").expect("scene");
    let gh = generate(&cfg, cfg.seed);
    let a = &gh.layout.aisles[0];
    let (x, y) = (0.5 * (a.x_start + a.x_end), a.y);
    let mut total = 0.0;
    for (name, yaw) in [("along the aisle", 0.0), ("at a row", std::f64::consts::FRAC_PI_2)] {
        let mut io = Store::new(Camera::VARIABLES);
        *io.value_mut(WIDTH) = Value::Int32(w);
        *io.value_mut(HEIGHT) = Value::Int32(h);
        *io.value_mut(RENDER_THREADS) = Value::Int32(threads);
        *io.value_mut(ENVIRONMENT) = Value::String(environment.clone());
        io.set_f64(BASE_X, x);
        io.set_f64(BASE_Y, y);
        io.set_f64(BASE_YAW, yaw);
        let mut m = Camera::new();
        m.initialize(&mut io, 0.0, &mut Quiet).expect("initialize");
        let t = Instant::now();
        for k in 0..frames {
            m.do_step(&mut io, k as f64 * 0.1, 0.1, &mut Quiet).expect("step");
        }
        let s = t.elapsed().as_secs_f64();
        total += s;
        let f = m.capture(x, y, yaw);
        println!(
            "{w}x{h} {name}, {threads} thread(s): {frames} frames in {s:.3} s = {:.1} ms/frame; digest {:016x}",
            1e3 * s / frames.max(1) as f64,
            digest(&f)
        );
    }
    println!("steps {total:.3} s");
}

/// FNV-1a over a frame's RGB, depth and label bytes.
fn digest(f: &agrisim_fmu_camera::render::Frame) -> u64 {
    let bytes = f
        .rgb
        .iter()
        .copied()
        .chain(f.depth.iter().flat_map(|v| v.to_le_bytes()))
        .chain(f.labels.iter().flat_map(|v| v.to_le_bytes()))
        .chain(f.true_depth.iter().flat_map(|v| v.to_le_bytes()));
    bytes.fold(0xcbf2_9ce4_8422_2325u64, |h, b| (h ^ b as u64).wrapping_mul(0x0100_0000_01b3))
}
