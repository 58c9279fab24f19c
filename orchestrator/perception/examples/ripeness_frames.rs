//! The ripeness fronts of every detection in the first RGB-D frame of recordings (for
//! checking the coloured fraction against the scene): `ripeness_frames RUN.mcap...` prints
//! one JSON line per detection: the file, the label under its centre (object id + 1), the
//! fronts and the probability of ripe. The camera is taken as level (as the perception
//! benchmark's is).

use agrisim_msgs::sensor_msgs::{CameraInfo, Image};
use agrisim_msgs::Message;
use agrisim_perception::{Detector, DetectorConfig, Frame, Intrinsics};

fn main() {
    let mut det = Detector::new(DetectorConfig::default());
    for path in std::env::args().skip(1) {
        let bytes = std::fs::read(&path).expect("read the recording");
        let (mut rgb, mut depth, mut labels, mut k) = (None, None, None, None);
        for m in mcap::MessageStream::new(&bytes).expect("an MCAP file") {
            let m = m.expect("a valid record");
            match m.channel.topic.as_str() {
                "/camera/color/image_raw" if rgb.is_none() => rgb = Image::from_cdr(&m.data).ok(),
                "/camera/aligned_depth_to_color/image_raw" if depth.is_none() => {
                    depth = Image::from_cdr(&m.data).ok().map(|d| {
                        d.data
                            .chunks_exact(4)
                            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                            .collect::<Vec<f32>>()
                    })
                }
                "/camera/labels" if labels.is_none() => labels = Image::from_cdr(&m.data).ok(),
                "/camera/color/camera_info" if k.is_none() => {
                    k = Intrinsics::from_k(&CameraInfo::from_cdr(&m.data).expect("a CameraInfo").k)
                }
                _ => {}
            }
        }
        let (Some(i), Some(d), Some(l), Some(k)) = (rgb, depth, labels, k) else { continue };
        let (w, h) = (i.width as usize, i.height as usize);
        let f = Frame { width: w, height: h, rgb: &i.data, depth: &d, k, up: None };
        for x in det.detect(&f).detections {
            let uv = k.project(x.center);
            let (u, v) = (uv[0].floor() as usize, uv[1].floor() as usize);
            let label = if u < w && v < h {
                let j = 4 * (v * w + u);
                i32::from_le_bytes([l.data[j], l.data[j + 1], l.data[j + 2], l.data[j + 3]])
            } else {
                0
            };
            let Some(r) = x.ripeness else { continue };
            println!(
                "{{\"file\": \"{path}\", \"label\": {label}, \"stage\": {}, \"ripe\": {:.4}, \"any\": [{:.4}, {:.4}, {:.4}], \"pink\": [{:.4}, {:.4}, {:.4}], \"pixels\": {}, \"depth\": {:.3}, \"uv\": [{:.1}, {:.1}], \"disc_px\": {:.0}}}",
                x.stage,
                x.votes[4] + x.votes[5],
                r.any.fraction,
                r.any.upper,
                r.any.spread,
                r.pink.fraction,
                r.pink.upper,
                r.pink.spread,
                r.pink.pixels,
                x.center[2],
                uv[0],
                uv[1],
                std::f64::consts::PI * (k.fx * x.radius / x.center[2]).powi(2),
            );
        }
    }
}
