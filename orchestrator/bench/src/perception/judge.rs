//! The judge of one frame: the detections the node published (camera frame) against the
//! fruit the camera's label image shows, placed by the world's fruit poses and the true
//! camera pose. Visibility of a fruit = its labelled pixels over the area of its projected
//! disc. A detection finds the fruit whose centre is nearest within [`MATCH_DISTANCE`] in 3-D;
//! a detection that finds none is a false detection, its cause the object under its
//! projected centre in the label image.
//!
//! The label image also checks the judge's own geometry: the projected centre of a fruit
//! that is free in view must land on a pixel labelled with that fruit
//! ([`FrameJudgement::centre_on_label`]); a mis-placed camera or fruit paired with the wrong
//! labels fails it.

use super::setup::PerceptionSetup;
use agrisim_msgs::sensor_msgs::Image;
use agrisim_msgs::vision_msgs::Detection3DArray;
use agrisim_perception::stage_of;
use agrisim_scene::Kind;
use serde::{Deserialize, Serialize};

/// Least labelled pixels of a fruit that counts (fewer: neither found nor missed).
pub const MIN_PIXELS: u32 = 30;
/// Farthest fruit centre that counts [m] (the detector's depth range).
pub const MAX_DEPTH: f64 = 1.5;
/// Largest distance of a detection to the fruit it finds [m].
pub const MATCH_DISTANCE: f64 = 0.035;

pub const VISIBILITY: [&str; 3] = ["free", "partly_occluded", "behind_stem_leaf"];

/// Visibility class of a fruit from its visible fraction.
pub fn visibility(fraction: f64) -> &'static str {
    if fraction >= 0.75 {
        VISIBILITY[0]
    } else if fraction >= 0.3 {
        VISIBILITY[1]
    } else {
        VISIBILITY[2]
    }
}

/// One fruit of one frame that counts.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FruitResult {
    pub fruit: u32,
    pub stage: u8,
    pub visibility: String,
    pub visible_fraction: f64,
    /// Depth of the centre in the camera [m].
    pub depth: f64,
    pub detected: bool,
    pub predicted_stage: Option<u8>,
    /// 3-D centre error [mm].
    pub error_mm: Option<f64>,
    /// Its part along the camera's ray to the true centre, signed (+: the estimate is too
    /// far) [mm]: depth-fit bias shows here, segmentation errors in the lateral rest.
    #[serde(default)]
    pub ray_error_mm: Option<f64>,
    /// Radius error, signed (+: the estimate is too large) [mm]: half the detection's box
    /// side against the fruit's collider radius (its equatorial radius, half its width).
    #[serde(default)]
    pub radius_error_mm: Option<f64>,
    /// Pixel position (for the overlay).
    pub uv: [f64; 2],
    pub radius_px: f64,
}

/// What a false detection sits on: the object under its projected centre.
pub const FALSE_CAUSES: [&str; 7] =
    ["fruit_off_centre", "duplicate", "leaf", "stem_truss", "structure", "robot", "background"];

/// A detection matching no fruit.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FalseDetection {
    /// Pixel of its projected centre.
    pub uv: [f64; 2],
    /// Stage the node gave it.
    pub stage: u8,
    /// One of [`FALSE_CAUSES`]: on a fruit whose centre is over [`MATCH_DISTANCE`] away
    /// (`fruit_off_centre`), or which another detection found (`duplicate`); on a leaf, a
    /// stem / truss / pedicel, the greenhouse, the robot, or nothing (sky, off the image).
    pub cause: String,
}

#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct FrameJudgement {
    pub fruit: Vec<FruitResult>,
    /// Detections matching no fruit (false positives).
    pub false_positives: Vec<FalseDetection>,
    /// Detections matching a fruit that does not count (too hidden or too far).
    pub ignored: u64,
    pub detections: u64,
    /// Fruit that count and are free (visibility class "free", at least 3 px radius): how
    /// many, and how many of them have their projected centre on a pixel of their own label
    /// (the 3x3 pixels around it). Near all when the judge's camera pose and fruit are right.
    pub centre_checks: u64,
    pub centre_on_label: u64,
}

/// The camera's optical frame in the map: base pose (x, y, yaw), camera_link at `mount` on
/// base_link (x forward, z up), optical axes z forward, x right, y down.
pub struct CameraPose {
    pub origin: [f64; 3],
    /// Rows: optical x, y, z axes in the map.
    pub axes: [[f64; 3]; 3],
}

impl CameraPose {
    pub fn new(base: [f64; 3], mount: [f64; 3], mount_yaw: f64) -> CameraPose {
        let (s, c) = base[2].sin_cos();
        let origin = [base[0] + c * mount[0] - s * mount[1], base[1] + s * mount[0] + c * mount[1], mount[2]];
        let (sy, cy) = (base[2] + mount_yaw).sin_cos();
        let forward = [cy, sy, 0.0];
        let left = [-sy, cy, 0.0];
        CameraPose { origin, axes: [[-left[0], -left[1], 0.0], [0.0, 0.0, -1.0], forward] }
    }
    pub fn to_camera(&self, p: [f64; 3]) -> [f64; 3] {
        let d = [p[0] - self.origin[0], p[1] - self.origin[1], p[2] - self.origin[2]];
        self.axes.map(|a| a[0] * d[0] + a[1] * d[1] + a[2] * d[2])
    }
}

/// The label image's value at pixel (u, v) (0 off the image or for another encoding).
fn label_at(labels: &Image, u: i64, v: i64) -> i32 {
    if labels.encoding != "32SC1" || u < 0 || v < 0 || u >= labels.width as i64 || v >= labels.height as i64 {
        return 0;
    }
    let i = 4 * (v as usize * labels.width as usize + u as usize);
    labels.data.get(i..i + 4).map_or(0, |b| i32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

/// The cause of a false detection from the label under it: `found` says whether each fruit
/// (by index) was found by another detection.
fn cause(setup: &PerceptionSetup, label: i32, found: &dyn Fn(usize) -> bool) -> &'static str {
    if label <= 0 {
        return "background";
    }
    let id = label as usize - 1;
    if let Some(Some(i)) = setup.by_id.get(id) {
        return if found(*i as usize) { "duplicate" } else { "fruit_off_centre" };
    }
    match setup.kinds.get(id) {
        Some(Kind::Leaf) => "leaf",
        Some(Kind::Stem | Kind::Truss) => "stem_truss",
        Some(Kind::Robot) | None => "robot",
        Some(_) => "structure",
    }
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// Judges one frame. `k` = (fx, fy, cx, cy) of the camera; `centers` the world's fruit poses
/// (order of the setup's fruit).
pub fn judge_frame(
    setup: &PerceptionSetup,
    centers: &[[f64; 3]],
    cam: &CameraPose,
    k: [f64; 4],
    labels: &Image,
    dets: &Detection3DArray,
) -> FrameJudgement {
    let mut counts = vec![0u32; setup.fruit.len()];
    if labels.encoding == "32SC1" {
        for px in labels.data.chunks_exact(4) {
            let v = i32::from_le_bytes([px[0], px[1], px[2], px[3]]);
            if v > 0 {
                if let Some(Some(i)) = setup.by_id.get(v as usize - 1) {
                    counts[*i as usize] += 1;
                }
            }
        }
    }
    let [fx, fy, cx, cy] = k;
    // Fruit in view: (index, camera-frame centre, counts).
    let seen: Vec<(usize, [f64; 3])> = counts
        .iter()
        .enumerate()
        .filter(|(_, c)| **c > 0)
        .map(|(i, _)| (i, cam.to_camera(centers.get(i).copied().unwrap_or(setup.fruit[i].center))))
        .filter(|(_, p)| p[2] > 0.05)
        .collect();
    let det: Vec<([f64; 3], u8)> = dets
        .detections
        .iter()
        .map(|d| {
            let p = &d.bbox.center.position;
            let stage = d.results.first().and_then(|h| stage_of(&h.hypothesis.class_id)).unwrap_or(0);
            ([p.x, p.y, p.z], stage)
        })
        .collect();
    let det_radius = |di: usize| 0.5 * dets.detections[di].bbox.size.x;
    let mut pairs: Vec<(f64, usize, usize)> = vec![];
    for (di, (p, _)) in det.iter().enumerate() {
        for (si, (_, c)) in seen.iter().enumerate() {
            let d = dist(*p, *c);
            if d <= MATCH_DISTANCE {
                pairs.push((d, di, si));
            }
        }
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let mut det_of = vec![None; seen.len()];
    let mut used = vec![false; det.len()];
    for (_, di, si) in pairs {
        if !used[di] && det_of[si].is_none() {
            used[di] = true;
            det_of[si] = Some(di);
        }
    }
    let mut out = FrameJudgement { detections: det.len() as u64, ..Default::default() };
    for (si, (i, c)) in seen.iter().enumerate() {
        let f = &setup.fruit[*i];
        let rpx = fx * f.radius / c[2];
        let area = std::f64::consts::PI * rpx * rpx;
        let frac = (counts[*i] as f64 / area.max(1.0)).min(1.0);
        let counts_here = counts[*i] >= MIN_PIXELS && c[2] <= MAX_DEPTH;
        if !counts_here {
            if det_of[si].is_some() {
                out.ignored += 1;
            }
            continue;
        }
        let m = det_of[si];
        let uv = [fx * c[0] / c[2] + cx, fy * c[1] / c[2] + cy];
        if frac >= 0.75 && rpx >= 3.0 {
            out.centre_checks += 1;
            let (u, v) = (uv[0].floor() as i64, uv[1].floor() as i64);
            let own = setup.fruit[*i].id as i32 + 1;
            if (-1..=1).any(|du| (-1..=1).any(|dv| label_at(labels, u + du, v + dv) == own)) {
                out.centre_on_label += 1;
            }
        }
        out.fruit.push(FruitResult {
            fruit: *i as u32,
            stage: f.stage,
            visibility: visibility(frac).into(),
            visible_fraction: frac,
            depth: c[2],
            detected: m.is_some(),
            predicted_stage: m.map(|di| det[di].1),
            error_mm: m.map(|di| 1000.0 * dist(det[di].0, *c)),
            ray_error_mm: m.map(|di| {
                let n = dist(*c, [0.0; 3]).max(1e-9);
                let d = det[di].0;
                1000.0 * ((d[0] - c[0]) * c[0] + (d[1] - c[1]) * c[1] + (d[2] - c[2]) * c[2]) / n
            }),
            radius_error_mm: m.map(|di| 1000.0 * (det_radius(di) - f.radius)),
            uv,
            radius_px: rpx,
        });
    }
    let found_fruit: Vec<usize> = seen.iter().zip(&det_of).filter(|(_, d)| d.is_some()).map(|((i, _), _)| *i).collect();
    let found = |i: usize| found_fruit.contains(&i);
    for (di, (p, stage)) in det.iter().enumerate() {
        if used[di] {
            continue;
        }
        let uv = if p[2] > 0.0 { [fx * p[0] / p[2] + cx, fy * p[1] / p[2] + cy] } else { [-1.0, -1.0] };
        let label = label_at(labels, uv[0].floor() as i64, uv[1].floor() as i64);
        out.false_positives.push(FalseDetection { uv, stage: *stage, cause: cause(setup, label, &found).into() });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::perception::setup::TruthFruit;
    use agrisim_msgs::vision_msgs::Detection3D;

    /// A 64x48 frame (f = 50 px) of a camera at the origin 1 m up facing +y: object 0 a leaf
    /// filling the left quarter, object 1 a fruit of 40 mm radius 1 m ahead at the centre.
    fn scene() -> (PerceptionSetup, Image, [f64; 4]) {
        let setup = PerceptionSetup {
            layout: agrisim_scene::Layout::from_config(&Default::default()),
            fruit: vec![TruthFruit { id: 1, center: [0.0, 1.0, 1.0], radius: 0.04, stage: 6 }],
            by_id: vec![None, Some(0)],
            kinds: vec![Kind::Leaf, Kind::Fruit { ripeness: 6 }],
        };
        let k = [50.0, 50.0, 32.0, 24.0];
        let mut data = vec![];
        for v in 0..48 {
            for u in 0..64 {
                let (du, dv) = (u as f64 + 0.5 - 32.0, v as f64 + 0.5 - 24.0);
                let l: i32 = if du * du + dv * dv <= 4.0 {
                    2
                } else if u < 16 {
                    1
                } else {
                    0
                };
                data.extend(l.to_le_bytes());
            }
        }
        let labels = Image { width: 64, height: 48, encoding: "32SC1".into(), step: 256, data, ..Default::default() };
        (setup, labels, k)
    }

    fn dets(points: &[[f64; 3]]) -> Detection3DArray {
        let mut a = Detection3DArray::default();
        for p in points {
            let mut d = Detection3D::default();
            (d.bbox.center.position.x, d.bbox.center.position.y, d.bbox.center.position.z) = (p[0], p[1], p[2]);
            a.detections.push(d);
        }
        a
    }

    #[test]
    fn judges_finds_false_causes_and_its_own_geometry() {
        let (setup, labels, k) = scene();
        let centers = [[0.0, 1.0, 1.0]];
        let cam = CameraPose::new([0.0, 0.0, std::f64::consts::FRAC_PI_2], [0.0, 0.0, 1.0], 0.0);
        // Found (10 mm off), a second detection on the same fruit 60 mm behind it, one on the
        // leaf, one on nothing.
        let d = dets(&[[0.0, 0.0, 1.01], [0.0, 0.0, 1.06], [-0.4, 0.0, 1.0], [0.3, -0.3, 1.0]]);
        let j = judge_frame(&setup, &centers, &cam, k, &labels, &d);
        // 13 labelled pixels of a 2 px disc (area 12.6): free, but under MIN_PIXELS.
        assert!(j.fruit.is_empty(), "{j:?}");
        assert_eq!(j.ignored, 1, "{j:?}");
        let causes: Vec<&str> = j.false_positives.iter().map(|f| f.cause.as_str()).collect();
        assert_eq!(causes, ["duplicate", "leaf", "background"], "{j:?}");
        // A fruit large enough to count: 0.5 m ahead.
        let (mut setup, mut labels, k) = (setup, labels, k);
        setup.fruit[0].center = [0.0, 0.5, 1.0];
        let mut data = vec![];
        for v in 0..48 {
            for u in 0..64 {
                let (du, dv) = (u as f64 + 0.5 - 32.0, v as f64 + 0.5 - 24.0);
                let l: i32 = if du * du + dv * dv <= 16.0 { 2 } else { 0 };
                data.extend(l.to_le_bytes());
            }
        }
        labels.data = data;
        let centers = [[0.0, 0.5, 1.0]];
        // Its box 76 mm wide: the radius read 2 mm small.
        let mut found = dets(&[[0.0, 0.0, 0.51]]);
        found.detections[0].bbox.size.x = 0.076;
        let j = judge_frame(&setup, &centers, &cam, k, &labels, &found);
        assert_eq!(j.fruit.len(), 1, "{j:?}");
        assert!(j.fruit[0].detected && (j.fruit[0].error_mm.unwrap() - 10.0).abs() < 1e-9, "{j:?}");
        assert!((j.fruit[0].radius_error_mm.unwrap() + 2.0).abs() < 1e-9, "{j:?}");
        assert_eq!((j.centre_checks, j.centre_on_label), (1, 1), "{j:?}");
        // The judge's camera 5 cm too high: the fruit's centre projects off its label.
        let high = CameraPose::new([0.0, 0.0, std::f64::consts::FRAC_PI_2], [0.0, 0.0, 1.05], 0.0);
        let j = judge_frame(&setup, &centers, &high, k, &labels, &dets(&[]));
        assert_eq!((j.centre_checks, j.centre_on_label), (1, 0), "{j:?}");
    }

    #[test]
    fn camera_pose_looks_along_the_base_heading() {
        // Base at the origin facing +y (yaw 90 deg), camera 0.32 ahead at 1.0 m height.
        let cam = CameraPose::new([0.0, 0.0, std::f64::consts::FRAC_PI_2], [0.32, 0.0, 1.0], 0.0);
        let p = cam.to_camera([0.1, 1.32, 1.2]);
        // 1 m ahead: z = 1; 0.1 m along map +x is to the right (x = 0.1); 0.2 m up is y = -0.2.
        assert!((p[0] - 0.1).abs() < 1e-12 && (p[1] + 0.2).abs() < 1e-12 && (p[2] - 1.0).abs() < 1e-12, "{p:?}");
        assert_eq!(visibility(0.9), "free");
        assert_eq!(visibility(0.5), "partly_occluded");
        assert_eq!(visibility(0.1), "behind_stem_leaf");
    }
}
