//! The perception node: RGB, aligned depth, CameraInfo and TF in; vision_msgs detections in
//! the camera frame and in the world frame, and the fruit map, out. A frame it cannot use
//! (no CameraInfo yet, no valid depth, no TF to a world frame, a malformed image) is skipped
//! and reported on /agrisim/status, never a panic or an error of the run.
//!
//! Compute is charged in simulated time ([`CostModel`], as the harvest node charges its
//! planning): a frame's outputs (detections, fruit map, its status) are held back until the
//! simulated time has passed the frame's cost from when the node took it up, and carry the
//! frame's stamp, as a real driver's would. While the node is busy, newer frames wait; only
//! the newest waiting frame of each camera is kept (the others are dropped, as a node that
//! cannot keep up drops them). Resolution: nodes step at the bus's message instants (every
//! 1 / `timing.message_rate`, 0.1 s in the scenarios), so an output appears at the first
//! message instant at or after its finish: the delay is the cost rounded up to that period,
//! while the busy time itself is not rounded (the next frame starts when the last finished,
//! or when it arrived if later). [`CostModel::FREE`] gives every output at the step its
//! frame arrives.

use crate::colour::STAGES;
use crate::cost::CostModel;
use crate::detect::{DetectWork, Detection, Detector, DetectorConfig, Frame, Intrinsics};
use crate::tf::TfBuffer;
use crate::tracker::{FruitMap, Look, Observation, Track};
use agrisim_bus::{Bus, Charged, Node, Reader};
use agrisim_error::Result;
use agrisim_msgs::agrisim::FmuStatus;
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::geometry_msgs::{Point, Pose, PoseWithCovariance, Quaternion, Vector3};
use agrisim_msgs::sensor_msgs::{CameraInfo, Image};
use agrisim_msgs::std_msgs::Header;
use agrisim_msgs::tf2_msgs::TFMessage;
use agrisim_msgs::vision_msgs::{
    BoundingBox3D, Detection3D, Detection3DArray, ObjectHypothesis, ObjectHypothesisWithPose,
};
use nalgebra::{Isometry3, Point3, Vector3 as Vec3};
use std::collections::VecDeque;

pub const IMAGE: &str = "/camera/color/image_raw";
pub const DEPTH: &str = "/camera/aligned_depth_to_color/image_raw";
pub const CAMERA_INFO: &str = "/camera/color/camera_info";
pub const TF: &str = "/tf";
pub const TF_STATIC: &str = "/tf_static";
/// Detections of each frame in the camera's optical frame.
pub const DETECTIONS: &str = "/perception/detections";
/// The same detections in the world frame (the first of `world_frames` TF reaches), with
/// the fruit map's track ids.
pub const DETECTIONS_WORLD: &str = "/perception/detections_world";
/// The fruit map: every track, merged over frames, in the world frame.
pub const FRUIT_MAP: &str = "/perception/fruit_map";
pub const STATUS: &str = "/agrisim/status";

#[derive(Clone, Debug)]
pub struct PerceptionConfig {
    pub detector: DetectorConfig,
    /// World frames to publish in, first that TF reaches wins (REP 105: map, then odom).
    pub world_frames: Vec<String>,
    /// The cameras read, by namespace: `/<ns>/color/image_raw`,
    /// `/<ns>/aligned_depth_to_color/image_raw`, `/<ns>/color/camera_info` (the RealSense
    /// driver's names). Every camera's detections go into one fruit map.
    pub cameras: Vec<String>,
    /// Tracks in the published fruit map have merged at least this many observations (a
    /// fruit seen once may be a false detection).
    pub confirm: u32,
    /// The fruit map is published at most this often [s] (0: after every frame); it holds
    /// every fruit seen so far, so it grows along the row.
    pub map_period: f64,
    /// TF frames of the robot's hands (the grasp point between the fingers). A fruit seen
    /// within [`PerceptionConfig::hand_radius`] of one, where the hand was about when the
    /// frame was taken, is in or at the hand (grasped, carried, handed over): it goes into
    /// no track, as the mapper leaves the robot's own links out of its map. Without this a
    /// carried fruit leaves a track where no fruit hangs, and a row's next pick closes on
    /// nothing there.
    pub hands: Vec<String>,
    /// [m]: the largest fruit's radius (45 mm) and the fit's error.
    pub hand_radius: f64,
}

/// The hand TCP frames of agrisim's robot (models/robot/agrisim_robot.urdf).
pub const HANDS: [&str; 2] = ["left_hand_tcp", "right_hand_tcp"];
/// Hand positions this close in time to a frame's stamp are where the hand may have been
/// when it was taken [ns]: the TF the node holds is the newest, and a frame may wait for the
/// node (its compute is charged), while a hand moves at up to about 0.5 m/s.
const HAND_WINDOW_NS: i64 = 300_000_000;

impl Default for PerceptionConfig {
    fn default() -> Self {
        PerceptionConfig {
            detector: DetectorConfig::default(),
            world_frames: vec!["map".into(), "odom".into()],
            cameras: vec!["camera".into()],
            confirm: 1,
            map_period: 0.0,
            hands: HANDS.iter().map(|h| h.to_string()).collect(),
            hand_radius: 0.06,
        }
    }
}

impl PerceptionConfig {
    /// The default detector on the cameras `namespaces`, publishing tracks seen at least twice.
    pub fn for_cameras(namespaces: &[&str]) -> PerceptionConfig {
        PerceptionConfig {
            cameras: namespaces.iter().map(|n| n.to_string()).collect(),
            confirm: 2,
            ..PerceptionConfig::default()
        }
    }
}

/// One camera's topics and what arrived of its current frame.
struct CameraInput {
    image_topic: String,
    depth_topic: String,
    info_topic: String,
    info: Option<(CameraInfo, Intrinsics)>,
    seen: [u64; 3],
    image: Option<Image>,
    depth: Option<Image>,
    last_stamp: Option<i64>,
    /// The newest paired frame not yet taken up, and the step it arrived at [ns].
    waiting: Option<(Image, Image, i64)>,
}

impl CameraInput {
    fn new(ns: &str) -> CameraInput {
        let ns = ns.trim_matches('/');
        CameraInput {
            image_topic: format!("/{ns}/color/image_raw"),
            depth_topic: format!("/{ns}/aligned_depth_to_color/image_raw"),
            info_topic: format!("/{ns}/color/camera_info"),
            info: None,
            seen: [0; 3],
            image: None,
            depth: None,
            last_stamp: None,
            waiting: None,
        }
    }
}

/// An output of a frame, held until the frame's compute is done.
enum Out {
    Array(&'static str, Detection3DArray),
    Status(FmuStatus),
}

pub struct Perception {
    config: PerceptionConfig,
    cost: CostModel,
    /// When the node is free for the next frame [ns] (simulated).
    free_at: i64,
    /// Outputs of frames taken up, with when they may go out [ns], in that order.
    pending: VecDeque<(i64, Vec<Out>)>,
    /// The outputs of the frame being processed.
    out: Vec<Out>,
    charged: Charged,
    /// The work of every frame taken up so far.
    pub work: DetectWork,
    /// Frames replaced by a newer one of their camera while the node was busy.
    pub dropped: u64,
    detector: Detector,
    tf: TfBuffer,
    tf_reader: Reader,
    tf_static_reader: Reader,
    cameras: Vec<CameraInput>,
    map: FruitMap,
    /// Where the hands were in each world frame, by step [ns], over the last
    /// [`HAND_WINDOW_NS`] and more (oldest first).
    hand_trail: VecDeque<(i64, String, Vec<[f64; 3]>)>,
    last_map_ns: Option<i64>,
    last_status: String,
    /// Frames processed and skipped so far.
    pub frames: u64,
    pub skipped: u64,
}

impl Perception {
    pub fn new(config: PerceptionConfig) -> Perception {
        Perception {
            detector: Detector::new(config.detector.clone()),
            cameras: config.cameras.iter().map(|ns| CameraInput::new(ns)).collect(),
            config,
            cost: CostModel::FREE,
            free_at: i64::MIN,
            pending: VecDeque::new(),
            out: Vec::new(),
            charged: Charged::default(),
            work: DetectWork::default(),
            dropped: 0,
            tf: TfBuffer::default(),
            tf_reader: Reader::new(TF),
            tf_static_reader: Reader::new(TF_STATIC),
            map: FruitMap::default(),
            hand_trail: VecDeque::new(),
            last_map_ns: None,
            last_status: String::new(),
            frames: 0,
            skipped: 0,
        }
    }

    /// Charges compute with `cost` (default [`CostModel::FREE`]; the harvest-by-sight
    /// benchmark uses [`CostModel::CALIBRATED`]).
    pub fn with_cost(mut self, cost: CostModel) -> Perception {
        self.cost = cost;
        self
    }

    /// The simulated compute time charged so far, readable after the node is boxed.
    pub fn charged(&self) -> Charged {
        self.charged.clone()
    }

    /// A skip reported on /agrisim/status with the frame's outputs (once per change of reason).
    fn status(&mut self, t_ns: i64, message: String) {
        self.skipped += 1;
        self.warn(t_ns, message);
    }

    fn warn(&mut self, t_ns: i64, message: String) {
        if message != self.last_status {
            let msg = FmuStatus {
                header: Header { stamp: Time::from_nanos(t_ns), frame_id: String::new() },
                instance: "perception".into(),
                status: "warning".into(),
                message: message.clone(),
            };
            self.out.push(Out::Status(msg));
            self.last_status = message;
        }
    }

    fn ok(&mut self) {
        self.last_status.clear();
    }

    /// Notes where the hands are now in each world frame TF reaches them in.
    fn record_hands(&mut self, t_ns: i64) {
        if self.config.hands.is_empty() {
            return;
        }
        for f in &self.config.world_frames {
            let at: Vec<[f64; 3]> = (self.config.hands.iter())
                .filter_map(|h| self.tf.lookup(f, h))
                .map(|p| [p.translation.x, p.translation.y, p.translation.z])
                .collect();
            if !at.is_empty() {
                self.hand_trail.push_back((t_ns, f.clone(), at));
            }
        }
        while self.hand_trail.front().is_some_and(|(t, _, _)| *t < t_ns - 2 * HAND_WINDOW_NS) {
            self.hand_trail.pop_front();
        }
    }

    /// Where the hands were (in world frame `frame`) about the time `stamp` [ns].
    fn hands_about(&self, frame: &str, stamp: i64) -> Vec<[f64; 3]> {
        (self.hand_trail.iter())
            .filter(|(t, f, _)| f == frame && (t - stamp).abs() <= HAND_WINDOW_NS)
            .flat_map(|(_, _, at)| at.iter().copied())
            .collect()
    }

    /// Publishes `out` at `t_ns`.
    fn release(bus: &mut Bus, t_ns: i64, out: Vec<Out>) {
        for o in out {
            match o {
                Out::Array(topic, msg) => bus.publish(topic, t_ns, &msg),
                Out::Status(msg) => bus.publish(STATUS, t_ns, &msg),
            }
        }
    }

    /// The frame's pixels and depth as the detector reads them, or why not.
    fn frame_data(image: &Image, depth: &Image) -> std::result::Result<(Vec<f32>, usize, usize), String> {
        let (w, h) = (image.width as usize, image.height as usize);
        if image.encoding != "rgb8" {
            return Err(format!("colour image encoding {:?}, expected rgb8", image.encoding));
        }
        if (image.step as usize) != w * 3 || image.data.len() < w * h * 3 {
            return Err(format!("colour image {w}x{h} with step {} and {} bytes", image.step, image.data.len()));
        }
        if depth.width as usize != w || depth.height as usize != h {
            return Err(format!("depth {}x{} does not match the colour image {w}x{h}", depth.width, depth.height));
        }
        let n = w * h;
        let z: Vec<f32> = match depth.encoding.as_str() {
            "32FC1" if depth.data.len() >= n * 4 && depth.step as usize == w * 4 => (0..n)
                .map(|i| {
                    let b = [depth.data[4 * i], depth.data[4 * i + 1], depth.data[4 * i + 2], depth.data[4 * i + 3]];
                    if depth.is_bigendian != 0 {
                        f32::from_be_bytes(b)
                    } else {
                        f32::from_le_bytes(b)
                    }
                })
                .collect(),
            "16UC1" if depth.data.len() >= n * 2 && depth.step as usize == w * 2 => (0..n)
                .map(|i| {
                    let b = [depth.data[2 * i], depth.data[2 * i + 1]];
                    let mm = if depth.is_bigendian != 0 { u16::from_be_bytes(b) } else { u16::from_le_bytes(b) };
                    mm as f32 / 1000.0
                })
                .collect(),
            e => return Err(format!("depth encoding {e:?} with {} bytes, expected 32FC1 or 16UC1", depth.data.len())),
        };
        Ok((z, w, h))
    }

    /// Processes one frame into `self.out`; the work it took.
    fn process(&mut self, t_ns: i64, cam: usize, image: &Image, depth: &Image) -> DetectWork {
        let stamp = image.header.stamp.to_nanos();
        let Some((info, k)) = self.cameras[cam].info.clone() else {
            self.status(t_ns, format!("frame at t={} s skipped: no CameraInfo yet", stamp as f64 / 1e9));
            return DetectWork::default();
        };
        if info.width != image.width || info.height != image.height {
            self.status(
                t_ns,
                format!(
                    "frame skipped: CameraInfo is {}x{}, the image {}x{}",
                    info.width, info.height, image.width, image.height
                ),
            );
            return DetectWork::default();
        }
        let (z, w, h) = match Self::frame_data(image, depth) {
            Ok(v) => v,
            Err(e) => {
                self.status(t_ns, format!("frame skipped: {e}"));
                return DetectWork::default();
            }
        };
        let camera =
            if image.header.frame_id.is_empty() { info.header.frame_id.clone() } else { image.header.frame_id.clone() };
        let world = self.config.world_frames.iter().find_map(|f| self.tf.lookup(f, &camera).map(|p| (f.clone(), p)));
        // The world's up in the camera frame: ripeness is read along it (REP 103: z up).
        let up = world.as_ref().map(|(_, p)| {
            let u = p.rotation.inverse() * Vec3::z();
            [u.x, u.y, u.z]
        });
        let result = self.detector.detect(&Frame { width: w, height: h, rgb: &image.data, depth: &z, k, up });
        let work = result.work;
        if result.valid_depth == 0 {
            self.status(t_ns, format!("frame at t={} s skipped: no valid depth", stamp as f64 / 1e9));
            return work;
        }
        self.frames += 1;
        let header = Header { stamp: image.header.stamp, frame_id: camera.clone() };
        let dets: Vec<Detection3D> =
            result.detections.iter().map(|d| detection(&header, d, &Isometry3::identity(), String::new())).collect();
        self.out.push(Out::Array(DETECTIONS, Detection3DArray { header: header.clone(), detections: dets }));
        let Some((frame, pose)) = world else {
            self.status(
                t_ns,
                format!(
                    "frame's world update skipped: no TF from {camera} to any of {:?} yet",
                    self.config.world_frames
                ),
            );
            return work;
        };
        // The fruit at a hand are the robot's business, not the crop's: no track. Nor is a
        // track there seen through while the hand is at it (a neighbour the fingers push
        // aside swings back).
        let (hands, reach) = (self.hands_about(&frame, stamp), self.config.hand_radius);
        let (kept, obs): (Vec<&Detection>, Vec<Observation>) = result
            .detections
            .iter()
            .filter_map(|d| {
                let c = pose * Point3::from(d.center);
                let c = [c.x, c.y, c.z];
                (!near(&hands, c, reach)).then_some((d, Observation { center: c, radius: d.radius, votes: d.votes }))
            })
            .unzip();
        let ids = self.map.update(&obs, stamp);
        let inverse = pose.inverse();
        self.map.forget_seen_through(&ids, |t| {
            if near(&hands, t.center, reach) {
                Look::Unseen
            } else {
                look(t, &inverse, &k, &z, w, h)
            }
        });
        let wh = Header { stamp: image.header.stamp, frame_id: frame.clone() };
        let dets: Vec<Detection3D> =
            kept.iter().zip(&ids).map(|(d, id)| detection(&wh, d, &pose, id.to_string())).collect();
        self.out.push(Out::Array(DETECTIONS_WORLD, Detection3DArray { header: wh.clone(), detections: dets }));
        let period_ns = (self.config.map_period * 1e9) as i64;
        if self.last_map_ns.is_some_and(|last| t_ns - last < period_ns) {
            self.ok();
            return work;
        }
        self.last_map_ns = Some(t_ns);
        let confirm = self.config.confirm;
        let tracks: Vec<Detection3D> = self
            .map
            .tracks
            .iter()
            .filter(|t| t.merged >= confirm)
            .map(|t| {
                let total: f64 = t.votes.iter().sum::<f64>().max(1e-12);
                let votes = t.votes.map(|v| v / total);
                let d = Detection {
                    center: t.center,
                    radius: t.radius,
                    stage: 0,
                    score: 0.0,
                    votes,
                    ripeness: None,
                    rms: t.spread(),
                    pixels: 0,
                    bbox: [0; 4],
                };
                detection(&wh, &d, &Isometry3::identity(), t.id.to_string())
            })
            .collect();
        self.out.push(Out::Array(FRUIT_MAP, Detection3DArray { header: wh, detections: tracks }));
        self.ok();
        work
    }
}

/// Whether `c` lies within `r` of any of `hands`.
fn near(hands: &[[f64; 3]], c: [f64; 3], r: f64) -> bool {
    hands.iter().any(|h| (0..3).map(|i| (h[i] - c[i]).powi(2)).sum::<f64>() <= r * r)
}

/// Depth beyond a fruit's back by more than this says the camera saw through where it
/// should be [m]: 3 sigma of the D435i's stereo depth noise at 1.6 m, the farthest depth the
/// detector keeps (Intel's RMS = z^2 x subpixel / (fx x baseline), subpixel 0.08, fx 337 px at
/// 640x480, baseline 50 mm: 12.2 mm; the camera FMU's `fmus/camera/src/datasheet.rs`).
const SEE_THROUGH_MARGIN: f64 = 0.035;
/// Half the side of the pixel window whose median depth is read at a track's centre.
const LOOK_HALF: usize = 2;

/// What a frame (depth `z`, `w` x `h`, intrinsics `k`; `to_camera` from the map's frame into
/// the camera's) says of a track it did not observe: its centre projected, at least a
/// radius inside the image, the median of the valid depths in a small window there.
fn look(t: &Track, to_camera: &Isometry3<f64>, k: &Intrinsics, z: &[f32], w: usize, h: usize) -> Look {
    let c = to_camera * Point3::from(t.center);
    if c.z < 0.1 {
        return Look::Unseen;
    }
    let (u, v) = (k.fx * c.x / c.z + k.cx, k.fy * c.y / c.z + k.cy);
    let margin = (k.fx * t.radius / c.z).max(LOOK_HALF as f64 + 1.0);
    if !(u >= margin && v >= margin && u < w as f64 - margin && v < h as f64 - margin) {
        return Look::Unseen;
    }
    let (u, v) = (u as usize, v as usize);
    let mut d: Vec<f32> = (v - LOOK_HALF..=v + LOOK_HALF)
        .flat_map(|y| (u - LOOK_HALF..=u + LOOK_HALF).map(move |x| z[y * w + x]))
        .filter(|d| d.is_finite() && *d > 0.0)
        .collect();
    let side = 2 * LOOK_HALF + 1;
    if d.len() * 2 <= side * side {
        return Look::Unseen;
    }
    d.sort_by(f32::total_cmp);
    let m = d[d.len() / 2] as f64;
    if m > c.z + t.radius + SEE_THROUGH_MARGIN {
        Look::SeenThrough
    } else if m >= c.z - t.radius - SEE_THROUGH_MARGIN {
        Look::Occupied
    } else {
        Look::Unseen
    }
}

/// A detection as vision_msgs: one hypothesis per stage with a probability, best first (the
/// score that probability; none when the stage is unknown), the pose the sphere's centre in `pose`'s target frame, the box its cube.
fn detection(header: &Header, d: &Detection, pose: &Isometry3<f64>, id: String) -> Detection3D {
    let c = pose * Point3::from(d.center);
    let position = Point { x: c.x, y: c.y, z: c.z };
    let center = Pose { position, orientation: Quaternion::IDENTITY };
    let var = (d.rms * d.rms).max(1e-6);
    let mut covariance = [0.0; 36];
    for i in 0..3 {
        covariance[i * 7] = var;
    }
    let mut order: Vec<usize> = (0..6).filter(|&s| d.votes[s] > 0.0).collect();
    order.sort_by(|a, b| d.votes[*b].total_cmp(&d.votes[*a]).then(b.cmp(a)));
    let results = order
        .into_iter()
        .map(|s| ObjectHypothesisWithPose {
            hypothesis: ObjectHypothesis { class_id: STAGES[s].into(), score: d.votes[s] },
            pose: PoseWithCovariance { pose: center, covariance },
        })
        .collect();
    let side = 2.0 * d.radius;
    Detection3D {
        header: header.clone(),
        results,
        bbox: BoundingBox3D { center, size: Vector3 { x: side, y: side, z: side } },
        id,
    }
}

impl Node for Perception {
    fn name(&self) -> &str {
        "perception"
    }

    fn step(&mut self, t_ns: i64, bus: &mut Bus) -> Result<()> {
        for m in self.tf_static_reader.take::<TFMessage>(bus)? {
            self.tf.add(&m);
        }
        for m in self.tf_reader.take::<TFMessage>(bus)? {
            self.tf.add(&m);
        }
        self.record_hands(t_ns);
        for cam in 0..self.cameras.len() {
            let c = &mut self.cameras[cam];
            if let Some(info) = bus.take_new::<CameraInfo>(&c.info_topic, &mut c.seen[2])? {
                match Intrinsics::from_k(&info.k) {
                    Some(k) => c.info = Some((info, k)),
                    None => {
                        let why = format!("CameraInfo on {} with an unusable K {:?} ignored", c.info_topic, info.k);
                        self.status(t_ns, why);
                        Self::release(bus, t_ns, std::mem::take(&mut self.out));
                    }
                }
            }
            let c = &mut self.cameras[cam];
            if let Some(img) = bus.take_new::<Image>(&c.image_topic, &mut c.seen[0])? {
                c.image = Some(img);
            }
            if let Some(d) = bus.take_new::<Image>(&c.depth_topic, &mut c.seen[1])? {
                c.depth = Some(d);
            }
            let pair = match (&c.image, &c.depth) {
                (Some(i), Some(d)) if i.header.stamp == d.header.stamp => {
                    let s = i.header.stamp.to_nanos();
                    (c.last_stamp != Some(s)).then_some(s)
                }
                _ => None,
            };
            if let Some(stamp) = pair {
                c.last_stamp = Some(stamp);
                let (image, depth) = (c.image.take().expect("paired"), c.depth.take().expect("paired"));
                if c.waiting.replace((image, depth, t_ns)).is_some() {
                    self.dropped += 1;
                }
            }
        }
        // The waiting frames, oldest stamp first (ties by camera), while the node is free.
        while self.free_at <= t_ns {
            let next = (self.cameras.iter().enumerate())
                .filter_map(|(i, c)| c.waiting.as_ref().map(|w| (w.0.header.stamp.to_nanos(), i)))
                .min();
            let Some((_, cam)) = next else { break };
            let (image, depth, arrived) = self.cameras[cam].waiting.take().expect("found waiting");
            let start = self.free_at.max(arrived);
            let work = self.process(t_ns, cam, &image, &depth);
            let cost = self.cost.seconds(&work);
            self.work += work;
            self.charged.add(cost);
            self.free_at = start + (cost * 1e9).ceil() as i64;
            let out = std::mem::take(&mut self.out);
            if !out.is_empty() {
                self.pending.push_back((self.free_at, out));
            }
        }
        while self.pending.front().is_some_and(|(at, _)| *at <= t_ns) {
            let (_, out) = self.pending.pop_front().expect("front");
            Self::release(bus, t_ns, out);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 40x30 depth image, 1 m everywhere but `patch` (depth) over a 9x9 square at the
    /// centre, seen by a camera at the map's origin looking along +z.
    fn frame(patch: f32) -> (Intrinsics, Vec<f32>) {
        let (w, h) = (40, 30);
        let mut z = vec![1.0f32; w * h];
        for y in 11..20 {
            for x in 16..25 {
                z[y * w + x] = patch;
            }
        }
        (Intrinsics { fx: 40.0, fy: 40.0, cx: 20.0, cy: 15.0 }, z)
    }

    fn track(center: [f64; 3]) -> Track {
        let mut map = FruitMap::default();
        map.update(&[Observation { center, radius: 0.03, votes: [0.0; 6] }], 0);
        map.tracks.remove(0)
    }

    /// The frame's word on a fruit at 0.6 m on the axis: there (depth at its front), seen
    /// through (the 1 m background), hidden (a leaf at 0.3 m), no depth, behind the camera,
    /// out of view.
    #[test]
    fn a_frame_says_whether_it_saw_through_a_track() {
        let id = Isometry3::identity();
        let fruit = track([0.0, 0.0, 0.6]);
        let look_at = |patch: f32, t: &Track| {
            let (k, z) = frame(patch);
            look(t, &id, &k, &z, 40, 30)
        };
        assert_eq!(look_at(0.57, &fruit), Look::Occupied);
        assert_eq!(look_at(1.0, &fruit), Look::SeenThrough);
        assert_eq!(look_at(0.3, &fruit), Look::Unseen);
        assert_eq!(look_at(f32::NAN, &fruit), Look::Unseen);
        assert_eq!(look_at(0.0, &fruit), Look::Unseen);
        // Just beyond its back and the noise margin, and just within.
        assert_eq!(look_at(0.6 + 0.03 + 0.036, &fruit), Look::SeenThrough);
        assert_eq!(look_at(0.6 + 0.03 + 0.034, &fruit), Look::Occupied);
        assert_eq!(look_at(1.0, &track([0.0, 0.0, -0.6])), Look::Unseen);
        assert_eq!(look_at(1.0, &track([0.6, 0.0, 0.6])), Look::Unseen);
        // Through the camera's pose: the map frame's fruit at 0.6 m ahead of a shifted camera.
        let cam = Isometry3::translation(0.5, 0.0, 0.0);
        let (k, z) = frame(1.0);
        assert_eq!(look(&track([0.5, 0.0, 0.6]), &cam.inverse(), &k, &z, 40, 30), Look::SeenThrough);
    }

    /// A fruit at a hand is one where the hand was (in that world frame) within the window
    /// about the frame's stamp: a carried fruit seen just before or after the TF moved on.
    /// Whether `c` (in world frame `frame`) lies at a hand of `node`, as the hands were
    /// about the time `stamp` [ns].
    fn at_hand(node: &Perception, frame: &str, stamp: i64, c: [f64; 3]) -> bool {
        near(&node.hands_about(frame, stamp), c, node.config.hand_radius)
    }

    #[test]
    fn a_fruit_at_a_hand_is_where_the_hand_was_about_the_frame() {
        use agrisim_msgs::geometry_msgs::{Quaternion, Transform, TransformStamped, Vector3};
        let mut node = Perception::new(PerceptionConfig::default());
        let hand_at = |x: f64| TFMessage {
            transforms: vec![TransformStamped {
                header: Header { stamp: Time::from_nanos(0), frame_id: "map".into() },
                child_frame_id: "left_hand_tcp".into(),
                transform: Transform { translation: Vector3 { x, y: 1.0, z: 1.0 }, rotation: Quaternion::IDENTITY },
            }],
        };
        // The hand carries a fruit from x = 0 to x = 0.3 m over a second, in steps of 0.1 s.
        for k in 0..=10 {
            node.tf.add(&hand_at(0.03 * k as f64));
            node.record_hands(k * 100_000_000);
        }
        let s = 1_000_000_000;
        assert!(at_hand(&node, "map", s, [0.3, 1.0, 1.05]), "at the hand now");
        assert!(at_hand(&node, "map", s - 200_000_000, [0.24, 1.02, 1.0]), "where it was 0.2 s before");
        assert!(!at_hand(&node, "map", s, [0.1, 1.0, 1.0]), "where it was 0.7 s before: a fruit hanging there");
        assert!(!at_hand(&node, "map", s, [0.3, 1.0, 1.0 + 0.061]), "beyond the radius");
        assert!(!at_hand(&node, "odom", s, [0.3, 1.0, 1.0]), "no TF from odom to the hand");
        // Without hands configured nothing is at a hand.
        let mut none = Perception::new(PerceptionConfig { hands: vec![], ..PerceptionConfig::default() });
        none.tf.add(&hand_at(0.3));
        none.record_hands(s);
        assert!(!at_hand(&none, "map", s, [0.3, 1.0, 1.0]));
    }
}
