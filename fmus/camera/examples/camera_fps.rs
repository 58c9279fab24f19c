//! Frames per second of whole camera frames (render + CDR encoding of image, depth, labels,
//! CameraInfo) on the default greenhouse, the robot in the middle of aisle 0 looking along
//! the aisle and then at a row, at 1280x720 and 640x480, on 1 and 2 render threads (frames
//! are identical either way), fixed sun, no environment.
//! `cargo run --release -p agrisim-fmu-camera --example camera_fps [FRAMES] [ENVIRONMENT] [THREADS] [ROBOT_LINKS]`
//! (with THREADS: 1280x720 on that many threads only, e.g. to compare CPU and wall time;
//! ROBOT_LINKS `false`: the base box only, as before the links were seen).

use agrisim_fmi::{Model, Quiet, Store, Value};
use agrisim_fmu_camera::ports::*;
use agrisim_fmu_camera::Camera;
use agrisim_scene::{generate, GreenhouseConfig};
use std::time::Instant;

fn main() {
    let frames: usize = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(5);
    let environment = std::env::args().nth(2).unwrap_or_default();
    let robot_links = std::env::args().nth(4).is_none_or(|s| s != "false");
    let cfg = GreenhouseConfig::from_toml_str("").expect("scene");
    let gh = generate(&cfg, cfg.seed);
    let a = &gh.layout.aisles[0];
    let (x, y) = (0.5 * (a.x_start + a.x_end), a.y);
    let configs: Vec<(i32, i32, i32)> =
        match std::env::args().nth(3).and_then(|s| s.parse().ok()).filter(|&t: &i32| t > 0) {
            Some(t) => vec![(1280, 720, t)],
            None => vec![(1280, 720, 1), (1280, 720, 2), (640, 480, 2)],
        };
    for (w, h, threads) in configs {
        for (name, yaw) in [("along the aisle", 0.0), ("at a row", std::f64::consts::FRAC_PI_2)] {
            let mut io = Store::new(Camera::VARIABLES);
            *io.value_mut(WIDTH) = Value::Int32(w);
            *io.value_mut(HEIGHT) = Value::Int32(h);
            *io.value_mut(RENDER_THREADS) = Value::Int32(threads);
            *io.value_mut(ENVIRONMENT) = Value::String(environment.clone());
            *io.value_mut(ROBOT_LINKS) = Value::Boolean(robot_links);
            io.set_f64(BASE_X, x);
            io.set_f64(BASE_Y, y);
            io.set_f64(BASE_YAW, yaw);
            let mut m = Camera::new();
            m.initialize(&mut io, 0.0, &mut Quiet).expect("initialize");
            // One step per frame (step = frame period): every step publishes.
            m.do_step(&mut io, 0.0, 0.1, &mut Quiet).expect("warm-up");
            let t = Instant::now();
            for k in 1..=frames {
                m.do_step(&mut io, k as f64 * 0.1, 0.1, &mut Quiet).expect("step");
            }
            let s = t.elapsed().as_secs_f64();
            assert_eq!(io.i64(IMAGE_SEQ), frames as i64 + 1);
            println!(
                "{w}x{h} {name}, {threads} thread(s): {frames} frames in {s:.2} s = {:.2} frames/s ({:.2} M primary rays/s), {:.1} % valid depth",
                frames as f64 / s,
                (w as usize * h as usize * frames) as f64 / s * 1e-6,
                100.0 * io.i32(VALID_DEPTH) as f64 / (w * h) as f64
            );
            let f = m.capture(x, y, yaw);
            println!(
                "    frame digest {:016x} (FNV-1a of RGB, depth and labels: equal digests = identical frames)",
                digest(&f)
            );
            if w == 640 {
                let out = f.true_depth.iter().filter(|&&z| !(0.105..=10.0).contains(&z)).count();
                println!(
                    "    no data: {:.1} % out of range (or sky), {:.1} % discontinuity or left band",
                    100.0 * out as f64 / f.depth.len() as f64,
                    100.0 * (f.depth.len() - f.valid - out) as f64 / f.depth.len() as f64
                );
            }
        }
    }
}

/// FNV-1a over a frame's RGB, depth and label bytes.
fn digest(f: &agrisim_fmu_camera::render::Frame) -> u64 {
    let bytes = f
        .rgb
        .iter()
        .copied()
        .chain(f.depth.iter().flat_map(|v| v.to_le_bytes()))
        .chain(f.labels.iter().flat_map(|v| v.to_le_bytes()));
    bytes.fold(0xcbf2_9ce4_8422_2325u64, |h, b| (h ^ b as u64).wrapping_mul(0x0100_0000_01b3))
}
