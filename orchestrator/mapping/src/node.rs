//! The depth mapper node: aligned depth, CameraInfo and TF of one or more cameras in; the
//! occupied space of one map as a planning scene in the map frame out, the shape the harvest
//! planner reads on `/planning_scene` (the lead decides when it replaces the ground truth
//! there).
//!
//! Every depth frame of every camera is integrated, oldest stamp first; the scene is published
//! at most once per step, after that step's frames, stamped with the newest integrated frame.
//!
//! Self-filter as MoveIt's robot self filter: the URDF on [`ROBOT_DESCRIPTION`] (latched) gives
//! each link's collision primitives; each step's frames filter them out at the links' poses
//! from TF ([`MapConfig::self_padding`] grows them). A link without TF is skipped and said
//! once on /agrisim/status. [`DepthMapper::set_robot_links`] adds primitives of the owner's.
//!
//! The allowed objects (the fruit being grasped) come from [`ALLOWED`]: each detection's box
//! centre and half its largest side are a sphere; the latest message holds, an empty one
//! clears. [`DepthMapper::set_allowed`] sets them from Rust until the next message.
//!
//! Compute is charged in simulated time ([`CostModel`], as the harvest node charges its
//! planning): a frame's integration occupies the node for the frame's cost, and a scene that
//! holds it goes out only once the simulated time has passed that (stamped, as before, with
//! the newest frame in it). While the node is busy, newer frames wait; of each camera only
//! the frames of its latest message instant are kept (older waiting ones are dropped, as a
//! node that cannot keep up drops them). Resolution: nodes step at the bus's message
//! instants (every 1 / `timing.message_rate`, 0.1 s in the scenarios), so a scene appears at
//! the first message instant at or after its frames' finish: the delay is the cost rounded
//! up to that period, while the busy time itself is not rounded (the next frame starts when
//! the last finished, or when it arrived if later). [`CostModel::FREE`] (the default) puts
//! every frame in the scene of the step it arrives at.
//!
//! The node reads no world output. A frame it cannot use (no CameraInfo yet, no TF from the
//! camera to the map frame, a malformed image) is skipped and reported on /agrisim/status,
//! never an error of the run.

use crate::cost::{CostModel, MapWork};
use crate::depth::{DepthFrame, Intrinsics};
use crate::map::{MapConfig, OccupancyMap, ScanStats};
use crate::robot::RobotShapes;
use crate::shape::{Primitive, Shape, Sphere};
use agrisim_bus::{Bus, Charged, Node, Reader};
use agrisim_error::Result;
use agrisim_msgs::agrisim::{FmuStatus, PlanningScene};
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::geometry_msgs::TransformStamped;
use agrisim_msgs::sensor_msgs::{CameraInfo, Image};
use agrisim_msgs::std_msgs::Header;
use agrisim_msgs::tf2_msgs::TFMessage;
use agrisim_msgs::vision_msgs::Detection3DArray;
use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion};
use std::collections::BTreeMap;
use std::collections::BTreeSet;
use std::collections::VecDeque;

/// The default camera's topics (namespace `/camera`).
pub const DEPTH: &str = "/camera/aligned_depth_to_color/image_raw";
pub const CAMERA_INFO: &str = "/camera/color/camera_info";
pub const TF: &str = "/tf";
pub const TF_STATIC: &str = "/tf_static";
/// The sensed planning scene.
pub const SCENE: &str = "/mapping/planning_scene";
pub const STATUS: &str = "/agrisim/status";
/// The URDF (std_msgs/String, latched), for the self-filter.
pub const ROBOT_DESCRIPTION: &str = "/robot_description";
/// The objects left out of the scene (vision_msgs/Detection3DArray): the fruit being grasped.
pub const ALLOWED: &str = "/harvest/allowed";

/// One camera's topics: aligned depth (sensor_msgs/Image) and its CameraInfo.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CameraTopics {
    pub depth: String,
    pub camera_info: String,
}

impl CameraTopics {
    /// The topics of the camera in namespace `/<name>` (RealSense layout):
    /// `/<name>/aligned_depth_to_color/image_raw` and `/<name>/color/camera_info`.
    pub fn named(name: &str) -> CameraTopics {
        let ns = name.trim_matches('/');
        CameraTopics {
            depth: format!("/{ns}/aligned_depth_to_color/image_raw"),
            camera_info: format!("/{ns}/color/camera_info"),
        }
    }
}

impl Default for CameraTopics {
    /// The single camera `/camera` ([`DEPTH`], [`CAMERA_INFO`]).
    fn default() -> Self {
        CameraTopics { depth: DEPTH.into(), camera_info: CAMERA_INFO.into() }
    }
}

#[derive(Debug, Clone, PartialEq)]
pub struct MapperConfig {
    /// The cameras integrated into the one map.
    pub cameras: Vec<CameraTopics>,
    pub scene_topic: String,
    /// The map frame (REP 105).
    pub map_frame: String,
    pub map: MapConfig,
    /// Exported boxes are grown by this on every side [m] (0: the planner pads).
    pub inflate: f64,
    /// Integrate every n-th pixel of every n-th row (1: all, OctoMap's result exactly).
    pub pixel_stride: usize,
    /// The scene is published at most this often [s] (0: after every step with a new frame
    /// or allowed set); a planner asks for a scene newer than some instant, not for each.
    pub scene_period: f64,
    /// Only the occupied space within this horizontal distance of this frame's origin is
    /// exported (e.g. base_link and the arms' reach; None: all of the map). The map keeps it all.
    pub scene_around: Option<(String, f64)>,
    /// TF frames of the robot's hands (the grasp point): a sphere of
    /// [`MapperConfig::hand_radius`] about each is the robot's too, as MoveIt's attached
    /// object is: a fruit in a hand leaves no voxels where it is carried. A frame TF does
    /// not reach is skipped silently (a robot without these hands).
    pub hands: Vec<String>,
    /// [m]: the largest fruit's radius (45 mm) and the fit's error.
    pub hand_radius: f64,
}

/// The hand TCP frames of agrisim's robot (models/robot/agrisim_robot.urdf).
pub const HANDS: [&str; 2] = ["left_hand_tcp", "right_hand_tcp"];

impl Default for MapperConfig {
    /// The single camera `/camera`.
    fn default() -> Self {
        MapperConfig {
            cameras: vec![CameraTopics::default()],
            scene_topic: SCENE.into(),
            map_frame: "map".into(),
            map: MapConfig::default(),
            inflate: 0.0,
            pixel_stride: 1,
            scene_period: 0.0,
            scene_around: None,
            hands: HANDS.iter().map(|h| h.to_string()).collect(),
            hand_radius: 0.06,
        }
    }
}

impl MapperConfig {
    /// The defaults with the cameras in namespaces `/<name>` ([`CameraTopics::named`]).
    pub fn for_cameras(names: &[&str]) -> MapperConfig {
        MapperConfig { cameras: names.iter().map(|n| CameraTopics::named(n)).collect(), ..MapperConfig::default() }
    }
}

/// The latest transform of each child frame, looked up along the tree (tf2's latest time).
#[derive(Default, Clone, Debug)]
struct TfTree {
    edges: BTreeMap<String, (String, Isometry3<f64>)>,
}

impl TfTree {
    fn add(&mut self, t: &TransformStamped) -> bool {
        let parent = t.header.frame_id.trim_start_matches('/');
        let child = t.child_frame_id.trim_start_matches('/');
        let (tr, q) = (&t.transform.translation, &t.transform.rotation);
        let Some(q) = UnitQuaternion::try_new(Quaternion::new(q.w, q.x, q.y, q.z), 1e-9) else { return false };
        if parent.is_empty() || child.is_empty() || parent == child || ![tr.x, tr.y, tr.z].iter().all(|v| v.is_finite())
        {
            return false;
        }
        self.edges.insert(child.into(), (parent.into(), Isometry3::from_parts(Translation3::new(tr.x, tr.y, tr.z), q)));
        true
    }

    fn to_root(&self, frame: &str) -> (String, Isometry3<f64>) {
        let (mut f, mut pose) = (frame.to_string(), Isometry3::identity());
        for _ in 0..64 {
            let Some((parent, p)) = self.edges.get(&f) else { break };
            pose = p * pose;
            f = parent.clone();
        }
        (f, pose)
    }

    /// Pose of `source` in `target`.
    fn lookup(&self, target: &str, source: &str) -> Option<Isometry3<f64>> {
        let ((rs, ps), (rt, pt)) = (self.to_root(source), self.to_root(target));
        (rs == rt
            && (self.edges.contains_key(source) || source == rs)
            && (self.edges.contains_key(target) || target == rt))
            .then(|| pt.inverse() * ps)
    }
}

/// One camera's readers and its latest usable CameraInfo (frame, width, height, K).
struct Camera {
    topics: CameraTopics,
    depth: Reader,
    info_seen: u64,
    info: Option<(String, u32, u32, Intrinsics)>,
    /// Frames not yet taken up, with the step they arrived at [ns].
    waiting: Vec<(Image, i64)>,
}

pub struct DepthMapper {
    config: MapperConfig,
    cost: CostModel,
    /// When the node is free for the next frame [ns] (simulated).
    free_at: i64,
    /// Scenes computed, with when they may go out [ns], in that order.
    pending: VecDeque<(i64, PlanningScene)>,
    charged: Charged,
    /// The work of every frame integrated so far.
    pub work: MapWork,
    /// Frames replaced by newer ones of their camera while the node was busy.
    pub dropped: u64,
    map: OccupancyMap,
    tf: TfTree,
    tf_reader: Reader,
    tf_static_reader: Reader,
    cameras: Vec<Camera>,
    /// Last sequence numbers taken of /robot_description and /harvest/allowed.
    seen: [u64; 2],
    /// The URDF's collision shapes (None: no description yet).
    description: Option<RobotShapes>,
    /// Links whose missing TF was reported (each once).
    missing_reported: BTreeSet<String>,
    /// Primitives added by the owner ([`DepthMapper::set_robot_links`]).
    extra_robot: Vec<Primitive>,
    /// The self-filter of the last integrated frames: URDF links placed by TF, then the extra.
    robot: Vec<Primitive>,
    last_status: String,
    /// Stamp of the newest frame integrated so far.
    newest: Option<Time>,
    /// Frames integrated and skipped so far, and the last frame's counts.
    pub frames: u64,
    pub skipped: u64,
    pub last: ScanStats,
    /// New frames or allowed objects not yet in a published scene, and when the last went out.
    scene_due: bool,
    last_scene_ns: Option<i64>,
}

impl DepthMapper {
    pub fn new(config: MapperConfig) -> std::result::Result<DepthMapper, String> {
        if config.cameras.is_empty() {
            return Err("depth mapper: no camera configured".into());
        }
        let cameras = config
            .cameras
            .iter()
            .map(|c| Camera {
                topics: c.clone(),
                depth: Reader::new(&c.depth),
                info_seen: 0,
                info: None,
                waiting: Vec::new(),
            })
            .collect();
        Ok(DepthMapper {
            map: OccupancyMap::new(config.map.clone())?,
            config,
            cost: CostModel::FREE,
            free_at: i64::MIN,
            pending: VecDeque::new(),
            charged: Charged::default(),
            work: MapWork::default(),
            dropped: 0,
            tf: TfTree::default(),
            tf_reader: Reader::new(TF),
            tf_static_reader: Reader::new(TF_STATIC),
            cameras,
            seen: [0; 2],
            description: None,
            missing_reported: BTreeSet::new(),
            extra_robot: Vec::new(),
            robot: Vec::new(),
            last_status: String::new(),
            newest: None,
            frames: 0,
            skipped: 0,
            last: ScanStats::default(),
            scene_due: false,
            last_scene_ns: None,
        })
    }

    /// Charges compute with `cost` (default [`CostModel::FREE`]; the harvest-by-sight
    /// benchmark uses [`CostModel::CALIBRATED`]).
    pub fn with_cost(mut self, cost: CostModel) -> DepthMapper {
        self.cost = cost;
        self
    }

    /// The simulated compute time charged so far, readable after the node is boxed.
    pub fn charged(&self) -> Charged {
        self.charged.clone()
    }

    /// Robot primitives in the map frame filtered out of the coming frames besides the links
    /// of /robot_description (all of the self-filter when no description is published).
    pub fn set_robot_links(&mut self, links: Vec<Primitive>) {
        self.extra_robot = links;
    }

    /// The objects left out of the exported scene (the fruit to grasp), until the next
    /// message on [`ALLOWED`].
    pub fn set_allowed(&mut self, allowed: Vec<Sphere>) {
        self.map.set_allowed(allowed);
    }

    pub fn map(&self) -> &OccupancyMap {
        &self.map
    }

    /// The self-filter primitives used for the last integrated frames (map frame).
    pub fn robot_links(&self) -> &[Primitive] {
        &self.robot
    }

    /// Links of the description whose TF has been missing at some frame, by name.
    pub fn missing_links(&self) -> impl Iterator<Item = &str> {
        self.missing_reported.iter().map(String::as_str)
    }

    /// The map's occupied space as a planning scene, stamped `stamp`.
    pub fn planning_scene(&self, stamp: Time) -> PlanningScene {
        self.map.planning_scene(Header { stamp, frame_id: self.config.map_frame.clone() }, self.config.inflate)
    }

    fn status(&mut self, bus: &mut Bus, t_ns: i64, message: String) {
        if message != self.last_status {
            let msg = FmuStatus {
                header: Header { stamp: Time::from_nanos(t_ns), frame_id: String::new() },
                instance: "mapping".into(),
                status: "warning".into(),
                message: message.clone(),
            };
            bus.publish(STATUS, t_ns, &msg);
            self.last_status = message;
        }
    }

    fn skip(&mut self, bus: &mut Bus, t_ns: i64, message: String) {
        self.skipped += 1;
        self.status(bus, t_ns, message);
    }

    /// Places the description's links at their TF poses, with the extra primitives after
    /// them; the links without TF not reported yet.
    fn place_robot(&mut self) -> Vec<String> {
        self.robot.clear();
        let mut fresh = Vec::new();
        if let Some(d) = &self.description {
            let (tf, map_frame) = (&self.tf, &self.config.map_frame);
            let (placed, missing) = d.place(|link| tf.lookup(map_frame, link));
            self.robot = placed;
            for l in missing {
                if self.missing_reported.insert(l.to_string()) {
                    fresh.push(l.to_string());
                }
            }
        }
        self.robot.extend_from_slice(&self.extra_robot);
        let sphere = Shape::Sphere { radius: self.config.hand_radius };
        for hand in &self.config.hands {
            if let Some(pose) = self.tf.lookup(&self.config.map_frame, hand) {
                self.robot.push(Primitive::new(sphere, pose));
            }
        }
        fresh
    }

    /// Integrates one depth image of camera `camera` (index in [`MapperConfig::cameras`])
    /// with the current self-filter; the reason when it cannot.
    pub fn integrate(&mut self, camera: usize, depth: &Image) -> std::result::Result<ScanStats, String> {
        let cam = self.cameras.get(camera).ok_or_else(|| format!("no camera {camera} configured"))?;
        let topic = &cam.topics.depth;
        let Some((info_frame, w, h, k)) = cam.info.clone() else {
            return Err(format!("depth frame on {topic} skipped: no CameraInfo yet on {}", cam.topics.camera_info));
        };
        if (depth.width, depth.height) != (w, h) {
            return Err(format!("depth frame on {topic} is {}x{}, CameraInfo {w}x{h}", depth.width, depth.height));
        }
        let frame = DepthFrame::from_image(depth).map_err(|e| format!("depth frame on {topic} skipped: {e}"))?;
        let camera_frame = if depth.header.frame_id.is_empty() { info_frame } else { depth.header.frame_id.clone() };
        let pose = self.tf.lookup(&self.config.map_frame, &camera_frame).ok_or_else(|| {
            format!("depth frame on {topic} skipped: no TF from {camera_frame} to {}", self.config.map_frame)
        })?;
        let reach = (self.config.map.max_range, self.config.map.self_padding);
        let robot: Vec<Primitive> =
            self.robot.iter().filter(|p| in_view(p, &pose, &k, (w, h), reach)).copied().collect();
        let stats = self.map.insert_depth_every(&frame, &k, &pose, &robot, self.config.pixel_stride);
        self.work += MapWork::of_scan(w as u64 * h as u64, &stats);
        self.frames += 1;
        self.last = stats;
        self.newest = self.newest.max(Some(depth.header.stamp));
        Ok(stats)
    }

    /// The allowed spheres of a message, in the map frame; the detections it cannot place.
    fn allowed_of(&self, msg: &Detection3DArray) -> (Vec<Sphere>, Vec<String>) {
        let (mut out, mut bad) = (Vec::new(), Vec::new());
        for (i, d) in msg.detections.iter().enumerate() {
            let frame = if d.header.frame_id.is_empty() { &msg.header.frame_id } else { &d.header.frame_id };
            let frame = frame.trim_start_matches('/');
            let pose = if frame.is_empty() || frame == self.config.map_frame {
                Some(Isometry3::identity())
            } else {
                self.tf.lookup(&self.config.map_frame, frame)
            };
            let (c, s) = (&d.bbox.center.position, &d.bbox.size);
            let radius = 0.5 * s.x.max(s.y).max(s.z);
            let center = Point3::new(c.x, c.y, c.z);
            match pose {
                None => bad.push(format!("detection {i}: no TF from {frame} to {}", self.config.map_frame)),
                Some(_) if !(radius.is_finite() && radius > 0.0 && center.coords.iter().all(|v| v.is_finite())) => {
                    bad.push(format!("detection {i}: unusable box (centre {c:?}, size {s:?})"))
                }
                Some(p) => out.push(Sphere { center: p * center, radius }),
            }
        }
        (out, bad)
    }
}

/// Whether primitive `p` grown by `reach.1` may hold a point of a `size` image from a camera
/// at `camera` (optical frame in the map) within range `reach.0`: its bounding sphere meets
/// the view frustum (the four side planes through the pixels' outer edges) within range.
/// Conservative (a sphere test): the self-filter tests only these links per point.
fn in_view(p: &Primitive, camera: &Isometry3<f64>, k: &Intrinsics, size: (u32, u32), reach: (f64, f64)) -> bool {
    let c = camera.inverse_transform_point(&Point3::from(p.pose.translation.vector));
    // 1 mm for the points' single precision.
    let r = p.bounding_radius() + reach.1 + 1e-3;
    let (w, h) = (size.0 as f64, size.1 as f64);
    let sides = [[k.fx, 0.0, k.cx], [-k.fx, 0.0, w - k.cx], [0.0, k.fy, k.cy], [0.0, -k.fy, h - k.cy]];
    c.coords.norm() <= reach.0 + r
        && c.z >= -r
        && sides
            .iter()
            .all(|n| n[0] * c.x + n[1] * c.y + n[2] * c.z >= -r * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt())
}

impl Node for DepthMapper {
    fn name(&self) -> &str {
        "mapping"
    }

    fn step(&mut self, t_ns: i64, bus: &mut Bus) -> Result<()> {
        for m in self.tf_static_reader.take::<TFMessage>(bus)? {
            m.transforms.iter().for_each(|t| {
                self.tf.add(t);
            });
        }
        for m in self.tf_reader.take::<TFMessage>(bus)? {
            m.transforms.iter().for_each(|t| {
                self.tf.add(t);
            });
        }
        if let Some(urdf) = bus.take_new::<agrisim_msgs::std_msgs::String>(ROBOT_DESCRIPTION, &mut self.seen[0])? {
            match RobotShapes::from_urdf(&urdf.data) {
                Ok(d) => {
                    if !d.ignored.is_empty() {
                        let msg = format!("{ROBOT_DESCRIPTION}: self-filter leaves out {}", d.ignored.join("; "));
                        self.status(bus, t_ns, msg);
                    }
                    self.description = Some(d);
                    self.missing_reported.clear();
                }
                Err(e) => self.status(bus, t_ns, format!("{ROBOT_DESCRIPTION} ignored: {e}")),
            }
        }
        let mut allowed_changed = false;
        if let Some(msg) = bus.take_new::<Detection3DArray>(ALLOWED, &mut self.seen[1])? {
            let (spheres, bad) = self.allowed_of(&msg);
            if !bad.is_empty() {
                self.status(bus, t_ns, format!("{ALLOWED}: {} left out", bad.join("; ")));
            }
            self.map.set_allowed(spheres);
            allowed_changed = true;
        }
        for i in 0..self.cameras.len() {
            let info_topic = self.cameras[i].topics.camera_info.clone();
            let mut seen = self.cameras[i].info_seen;
            let info = bus.take_new::<CameraInfo>(&info_topic, &mut seen)?;
            self.cameras[i].info_seen = seen;
            if let Some(info) = info {
                match Intrinsics::from_camera_info(&info) {
                    Some(k) => self.cameras[i].info = Some((info.header.frame_id.clone(), info.width, info.height, k)),
                    None => self.status(
                        bus,
                        t_ns,
                        format!("CameraInfo on {info_topic} with an unusable K {:?} ignored", info.k),
                    ),
                }
            }
            let images = self.cameras[i].depth.take::<Image>(bus)?;
            if !images.is_empty() {
                let c = &mut self.cameras[i];
                self.dropped += c.waiting.len() as u64;
                c.waiting = images.into_iter().map(|d| (d, t_ns)).collect();
            }
        }
        // Oldest first (ties by camera, then arrival): the later view clears over the earlier;
        // while the node is free.
        let mut integrated = 0;
        let mut placed = false;
        while self.free_at <= t_ns {
            let next = (self.cameras.iter().enumerate())
                .flat_map(|(i, c)| c.waiting.iter().enumerate().map(move |(j, (d, _))| (d.header.stamp, i, j)))
                .min();
            let Some((_, i, j)) = next else { break };
            let (depth, arrived) = self.cameras[i].waiting.remove(j);
            if !placed {
                placed = true;
                let fresh = self.place_robot();
                if !fresh.is_empty() {
                    let msg = format!(
                        "self-filter: no TF from {} to {}; left out until it appears",
                        fresh.join(", "),
                        self.config.map_frame
                    );
                    self.status(bus, t_ns, msg);
                }
            }
            let before = self.work;
            match self.integrate(i, &depth) {
                Ok(_) => integrated += 1,
                Err(e) => self.skip(bus, t_ns, e),
            }
            let cost = self.cost.seconds(&(self.work - before));
            self.charged.add(cost);
            self.free_at = self.free_at.max(arrived) + (cost * 1e9).ceil() as i64;
        }
        if integrated > 0 {
            self.last_status.clear();
        }
        self.scene_due |= integrated > 0 || allowed_changed;
        self.export(bus, t_ns);
        while self.pending.front().is_some_and(|(at, _)| *at <= t_ns) {
            let (_, scene) = self.pending.pop_front().expect("front");
            let topic = self.config.scene_topic.clone();
            bus.publish(&topic, t_ns, &scene);
        }
        Ok(())
    }
}

impl DepthMapper {
    /// The scene, when due and the period allows, queued to go out once the frames in it are
    /// done.
    fn export(&mut self, bus: &mut Bus, t_ns: i64) {
        let period_ns = (self.config.scene_period * 1e9) as i64;
        let ready = self.last_scene_ns.is_none_or(|last| t_ns - last >= period_ns);
        if let Some(stamp) = self.newest.filter(|_| self.scene_due && ready) {
            let mut scene = self.planning_scene(stamp);
            if let Some((frame, radius)) = &self.config.scene_around {
                match self.tf.lookup(&self.config.map_frame, frame) {
                    Some(p) => {
                        let c = p.translation.vector;
                        scene.objects.retain(|o| {
                            let q = &o.pose.position;
                            (q.x - c.x).hypot(q.y - c.y) <= *radius
                        });
                    }
                    None => {
                        let why = format!("scene not exported: no TF from {frame} to {}", self.config.map_frame);
                        self.status(bus, t_ns, why);
                        return;
                    }
                }
            }
            self.pending.push_back((self.free_at.max(t_ns), scene));
            (self.scene_due, self.last_scene_ns) = (false, Some(t_ns));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::Shape;

    /// Against brute force: every sphere that holds a point of some pixel's ray within range
    /// is in view; spheres behind, beside and beyond range are not.
    #[test]
    fn view_culling_keeps_every_link_a_ray_can_meet() {
        let k = Intrinsics { fx: 20.0, fy: 20.0, cx: 8.0, cy: 6.0 };
        let (w, h, range, pad) = (16u32, 12u32, 2.0, 0.03);
        let camera =
            Isometry3::from_parts(Translation3::new(0.3, -0.2, 1.0), UnitQuaternion::from_euler_angles(0.4, -0.3, 1.1));
        let mut seed = 7u64;
        let mut rnd = move || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut seen, mut culled) = (0, 0);
        for _ in 0..400 {
            // Half about the view (and its edges), half anywhere about the camera.
            let local = if rnd() < 0.5 {
                let z = 2.4 * rnd() - 0.2;
                Point3::new(z * (1.2 * rnd() - 0.6), z * (1.0 * rnd() - 0.5), z)
            } else {
                Point3::new(6.0 * rnd() - 3.0, 6.0 * rnd() - 3.0, 6.0 * rnd() - 3.0)
            };
            let p = Primitive::new(Shape::Sphere { radius: 0.05 + 0.2 * rnd() }, Isometry3::translation(0.0, 0.0, 0.0));
            let p = Primitive::new(p.shape, Isometry3::from(Translation3::from((camera * local).coords)));
            let hit = (0..w).any(|u| {
                (0..h).any(|v| {
                    let d = Point3::new((u as f64 + 0.5 - k.cx) / k.fx, (v as f64 + 0.5 - k.cy) / k.fy, 1.0);
                    let n = d.coords.norm();
                    (1..=400).any(|i| {
                        let t = range * i as f64 / 400.0;
                        p.contains(&(camera * Point3::from(d.coords * (t / n))), pad)
                    })
                })
            });
            let view = in_view(&p, &camera, &k, (w, h), (range, pad));
            assert!(view || !hit, "{local:?}");
            seen += hit as usize;
            culled += !view as usize;
        }
        // Both kinds occur: the test sees links kept and links dropped.
        assert!(seen > 100 && culled > 150, "{seen} {culled}");
    }
}
