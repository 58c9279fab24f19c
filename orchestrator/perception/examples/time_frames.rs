//! Times the detector on the RGB-D frames of a recording (for python/bench_perception.py):
//! `time_frames RUN.mcap [REPEATS]` prints one JSON line: frames, detections, ms per frame,
//! and a digest of every detection of the last pass to the bit (its `Debug` text, whose
//! floats round-trip), so a change meant to keep results can be checked to keep them.

use agrisim_msgs::sensor_msgs::{CameraInfo, Image};
use agrisim_msgs::Message;
use agrisim_perception::{Detector, DetectorConfig, Frame, Intrinsics};
use std::collections::BTreeMap;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(path) = args.first() else {
        eprintln!("usage: time_frames RUN.mcap [REPEATS]");
        std::process::exit(2);
    };
    let repeats: usize = args.get(1).and_then(|r| r.parse().ok()).unwrap_or(5);
    let bytes = std::fs::read(path).expect("read the recording");
    let mut rgb: BTreeMap<i64, Image> = BTreeMap::new();
    let mut depth: BTreeMap<i64, Vec<f32>> = BTreeMap::new();
    let mut k = None;
    for m in mcap::MessageStream::new(&bytes).expect("an MCAP file") {
        let m = m.expect("a valid record");
        match m.channel.topic.as_str() {
            "/camera/color/image_raw" => {
                let i = Image::from_cdr(&m.data).expect("an Image");
                rgb.insert(i.header.stamp.to_nanos(), i);
            }
            "/camera/aligned_depth_to_color/image_raw" => {
                let d = Image::from_cdr(&m.data).expect("an Image");
                let z = d.data.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
                depth.insert(d.header.stamp.to_nanos(), z);
            }
            "/camera/color/camera_info" if k.is_none() => {
                k = Intrinsics::from_k(&CameraInfo::from_cdr(&m.data).expect("a CameraInfo").k);
            }
            _ => {}
        }
    }
    let k = k.expect("a CameraInfo in the recording");
    let frames: Vec<(&Image, &Vec<f32>)> = rgb.iter().filter_map(|(s, i)| depth.get(s).map(|d| (i, d))).collect();
    assert!(!frames.is_empty(), "no frame with colour and depth");
    let mut det = Detector::new(DetectorConfig::default());
    let mut found = 0;
    let mut digest = 0xcbf2_9ce4_8422_2325u64;
    let t = Instant::now();
    let mut first_ms = 0.0;
    for r in 0..repeats {
        found = 0;
        for (i, d) in &frames {
            let f = Frame { width: i.width as usize, height: i.height as usize, rgb: &i.data, depth: d, k, up: None };
            let out = det.detect(&f);
            found += out.detections.len();
            if r + 1 == repeats {
                // FNV-1a over the detections' text.
                for b in format!("{:?}", out.detections).bytes() {
                    digest = (digest ^ b as u64).wrapping_mul(0x0100_0000_01b3);
                }
            }
        }
        if r == 0 {
            first_ms = 1000.0 * t.elapsed().as_secs_f64() / frames.len() as f64;
        }
    }
    let ms = 1000.0 * t.elapsed().as_secs_f64() / (repeats * frames.len()) as f64;
    // The first pass starts with the detector's colour memo empty, as a run's first frames do.
    println!(
        "{{\"frames\": {}, \"detections\": {found}, \"ms_per_frame\": {ms:.3}, \"first_pass_ms_per_frame\": {first_ms:.3}, \"digest\": \"{digest:016x}\"}}",
        frames.len()
    );
}
