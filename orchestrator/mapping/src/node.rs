//! The depth mapper node: aligned depth, CameraInfo and TF in; the occupied space as a
//! planning scene in the map frame out, the shape the harvest planner reads on
//! `/planning_scene` (the lead decides when it replaces the ground truth there).
//!
//! The robot's links (self-filter) and the allowed objects are handed in by the owner
//! ([`DepthMapper::set_robot_links`], [`DepthMapper::set_allowed`]), computed from the URDF
//! and the joint states; the node reads no world output. A frame it cannot use (no
//! CameraInfo yet, no TF from the camera to the map frame, a malformed image) is skipped and
//! reported on /agrisim/status, never an error of the run.

use crate::depth::{DepthFrame, Intrinsics};
use crate::map::{MapConfig, OccupancyMap, ScanStats};
use crate::shape::{Primitive, Sphere};
use agrisim_bus::{Bus, Node, Reader};
use agrisim_error::Result;
use agrisim_msgs::agrisim::{FmuStatus, PlanningScene};
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::geometry_msgs::TransformStamped;
use agrisim_msgs::sensor_msgs::{CameraInfo, Image};
use agrisim_msgs::std_msgs::Header;
use agrisim_msgs::tf2_msgs::TFMessage;
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};
use std::collections::BTreeMap;

pub const DEPTH: &str = "/camera/aligned_depth_to_color/image_raw";
pub const CAMERA_INFO: &str = "/camera/color/camera_info";
pub const TF: &str = "/tf";
pub const TF_STATIC: &str = "/tf_static";
/// The sensed planning scene.
pub const SCENE: &str = "/mapping/planning_scene";
pub const STATUS: &str = "/agrisim/status";

#[derive(Debug, Clone, PartialEq)]
pub struct MapperConfig {
    pub depth_topic: String,
    pub camera_info_topic: String,
    pub scene_topic: String,
    /// The map frame (REP 105).
    pub map_frame: String,
    pub map: MapConfig,
    /// Exported boxes are grown by this on every side [m] (0: the planner pads).
    pub inflate: f64,
}

impl Default for MapperConfig {
    fn default() -> Self {
        MapperConfig {
            depth_topic: DEPTH.into(),
            camera_info_topic: CAMERA_INFO.into(),
            scene_topic: SCENE.into(),
            map_frame: "map".into(),
            map: MapConfig::default(),
            inflate: 0.0,
        }
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

pub struct DepthMapper {
    config: MapperConfig,
    map: OccupancyMap,
    tf: TfTree,
    tf_reader: Reader,
    tf_static_reader: Reader,
    seen: [u64; 2],
    info: Option<(String, u32, u32, Intrinsics)>,
    robot: Vec<Primitive>,
    last_status: String,
    /// Frames integrated and skipped so far, and the last frame's counts.
    pub frames: u64,
    pub skipped: u64,
    pub last: ScanStats,
}

impl DepthMapper {
    pub fn new(config: MapperConfig) -> std::result::Result<DepthMapper, String> {
        Ok(DepthMapper {
            map: OccupancyMap::new(config.map.clone())?,
            config,
            tf: TfTree::default(),
            tf_reader: Reader::new(TF),
            tf_static_reader: Reader::new(TF_STATIC),
            seen: [0; 2],
            info: None,
            robot: Vec::new(),
            last_status: String::new(),
            frames: 0,
            skipped: 0,
            last: ScanStats::default(),
        })
    }

    /// The robot's links in the map frame at the time of the coming frames.
    pub fn set_robot_links(&mut self, links: Vec<Primitive>) {
        self.robot = links;
    }

    /// The objects left out of the exported scene (the fruit to grasp).
    pub fn set_allowed(&mut self, allowed: Vec<Sphere>) {
        self.map.set_allowed(allowed);
    }

    pub fn map(&self) -> &OccupancyMap {
        &self.map
    }

    /// The map's occupied space as a planning scene, stamped `stamp`.
    pub fn planning_scene(&self, stamp: Time) -> PlanningScene {
        self.map.planning_scene(Header { stamp, frame_id: self.config.map_frame.clone() }, self.config.inflate)
    }

    fn skip(&mut self, bus: &mut Bus, t_ns: i64, message: String) {
        self.skipped += 1;
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

    /// Integrates one depth image; the reason when it cannot.
    pub fn integrate(&mut self, depth: &Image) -> std::result::Result<ScanStats, String> {
        let topic = &self.config.depth_topic;
        let Some((info_frame, w, h, k)) = self.info.clone() else {
            return Err(format!("depth frame on {topic} skipped: no CameraInfo yet"));
        };
        if (depth.width, depth.height) != (w, h) {
            return Err(format!("depth frame on {topic} is {}x{}, CameraInfo {w}x{h}", depth.width, depth.height));
        }
        let frame = DepthFrame::from_image(depth).map_err(|e| format!("depth frame on {topic} skipped: {e}"))?;
        let camera = if depth.header.frame_id.is_empty() { info_frame } else { depth.header.frame_id.clone() };
        let pose = self.tf.lookup(&self.config.map_frame, &camera).ok_or_else(|| {
            format!("depth frame on {topic} skipped: no TF from {camera} to {}", self.config.map_frame)
        })?;
        let stats = self.map.insert_depth(&frame, &k, &pose, &self.robot);
        self.frames += 1;
        self.last = stats;
        Ok(stats)
    }
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
        let info_topic = self.config.camera_info_topic.clone();
        if let Some(info) = bus.take_new::<CameraInfo>(&info_topic, &mut self.seen[1])? {
            match Intrinsics::from_camera_info(&info) {
                Some(k) => self.info = Some((info.header.frame_id.clone(), info.width, info.height, k)),
                None => {
                    self.skip(bus, t_ns, format!("CameraInfo on {info_topic} with an unusable K {:?} ignored", info.k))
                }
            }
        }
        let depth_topic = self.config.depth_topic.clone();
        if let Some(depth) = bus.take_new::<Image>(&depth_topic, &mut self.seen[0])? {
            match self.integrate(&depth) {
                Ok(_) => {
                    self.last_status.clear();
                    let scene = self.planning_scene(depth.header.stamp);
                    let topic = self.config.scene_topic.clone();
                    bus.publish(&topic, t_ns, &scene);
                }
                Err(e) => self.skip(bus, t_ns, e),
            }
        }
        Ok(())
    }
}
