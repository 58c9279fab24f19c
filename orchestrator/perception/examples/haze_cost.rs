//! Calibrates the fog part of perception's [`CostModel`]: times the fog estimate and the
//! clearing ([`agrisim_perception::haze`]) on the colour and depth frames of a recording, the
//! least of `--repeat` passes per frame (camera `/camera`), and prints seconds per sampled and per cleared pixel.
//!
//! The recording: `agrisim bench perception --trials 4 --scenes 2 --environment 4 --jobs 1
//! --overlays 0 --out /tmp/fog`, then `cargo run --release -p agrisim-perception --example
//! haze_cost -- /tmp/fog/trials/0000.mcap [--repeat 5]`.

use agrisim_msgs::sensor_msgs::{CameraInfo, Image, Pinhole};
use agrisim_msgs::Message;
use agrisim_perception::haze::{estimate, HazeWork, Srgb};
use agrisim_perception::Frame;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(path) = args.first() else {
        eprintln!("usage: haze_cost RUN.mcap [--repeat N]");
        std::process::exit(2);
    };
    let repeat: usize =
        args.iter().position(|a| a == "--repeat").and_then(|i| args.get(i + 1)?.parse().ok()).unwrap_or(5);
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let (mut colour, mut depth, mut k) = (vec![], vec![], None);
    for m in mcap::MessageStream::new(&bytes).expect("an MCAP file") {
        let m = m.expect("a valid record");
        let topic = m.channel.topic.as_str();
        if !topic.starts_with("/camera/") {
            continue;
        }
        if topic.ends_with("/color/image_raw") {
            colour.push(Image::from_cdr(&m.data).expect("an Image"));
        } else if topic.ends_with("/aligned_depth_to_color/image_raw") {
            depth.push(Image::from_cdr(&m.data).expect("an Image"));
        } else if topic.ends_with("/color/camera_info") && k.is_none() {
            k = Pinhole::from_camera_info(&CameraInfo::from_cdr(&m.data).expect("a CameraInfo"));
        }
    }
    let k = k.expect("a CameraInfo in the recording");
    let t = Srgb::default();
    let (mut est_s, mut clear_s, mut work, mut foggy) = (0.0, 0.0, HazeWork::default(), 0);
    for (c, d) in colour.iter().zip(&depth) {
        let (w, h) = (c.width as usize, c.height as usize);
        let z: Vec<f32> = d.data.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
        let (mut best_e, mut best_c) = (f64::INFINITY, f64::INFINITY);
        let mut once = HazeWork::default();
        for _ in 0..repeat {
            once = HazeWork::default();
            let start = Instant::now();
            let f = Frame { width: w, height: h, rgb: &c.data, depth: &z, k, up: None };
            let haze = estimate(&t, &f, &mut once);
            best_e = best_e.min(start.elapsed().as_secs_f64());
            if let Some(haze) = haze {
                let start = Instant::now();
                std::hint::black_box(haze.clear(&t, &f, (0.15, 1.6), &mut once));
                best_c = best_c.min(start.elapsed().as_secs_f64());
            }
        }
        est_s += best_e;
        if best_c.is_finite() {
            clear_s += best_c;
            foggy += 1;
        }
        work.samples += once.samples;
        work.cleared += once.cleared;
    }
    println!("frames {}, foggy {foggy}", colour.len().min(depth.len()));
    println!(
        "per_haze_sample: {:.3e} s ({} samples, {:.3} ms per frame)",
        est_s / work.samples as f64,
        work.samples,
        1e3 * est_s / colour.len() as f64
    );
    if work.cleared > 0 {
        println!(
            "per_cleared: {:.3e} s ({} pixels, {:.3} ms per foggy frame)",
            clear_s / work.cleared as f64,
            work.cleared,
            1e3 * clear_s / foggy.max(1) as f64
        );
    }
}
