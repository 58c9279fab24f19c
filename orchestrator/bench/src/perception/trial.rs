//! One perception trial: the sensor system started with the base standing at a seeded pose
//! in an aisle, facing a row, the lift at a seeded height; the perception node runs on the
//! camera's frames; each frame is judged from the node's /perception/detections, the camera's
//! /camera/labels and the world's /fruits (ground truth read only by the judge).

use super::judge::{judge_frame, CameraPose, FrameJudgement};
use super::png::encode_rgb;
use super::setup::PerceptionSetup;
use super::ENVIRONMENTS;
use crate::framework::Trial;
use agrisim_bus::{Node, Reader};
use agrisim_error::Result;
use agrisim_math::Rng;
use agrisim_msgs::geometry_msgs::PoseArray;
use agrisim_msgs::sensor_msgs::{CameraInfo, Image};
use agrisim_msgs::vision_msgs::Detection3DArray;
use agrisim_nodes::{CommandScript, LiftCommand, OdomTf, RobotStatePublisher};
use agrisim_perception::{Perception, PerceptionConfig};
use agrisim_session::{prepare, RunOptions, Scenario};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

/// camera_link on base_link at lift 0 (sensors.ssd, agrisim_robot.urdf).
const MOUNT: [f64; 3] = [0.32, 0.0, 0.60];

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PerceptionLine {
    pub trial: u64,
    pub scene: u64,
    pub seed: u64,
    pub environment: String,
    /// Base x, y, yaw and lift position.
    pub pose: [f64; 4],
    pub frames: u64,
    pub fruit: u64,
    pub found: u64,
    pub false_positives: u64,
    /// Status warnings of the node (skipped frames).
    pub warnings: u64,
    /// Wall time of the node per frame [ms] (all frames of the trial).
    pub node_ms_per_frame: Option<f64>,
    pub wall_time: f64,
    pub error: Option<String>,
}

#[derive(Serialize, Deserialize)]
pub struct PerceptionRecord {
    pub line: PerceptionLine,
    pub frames: Vec<FrameJudgement>,
}

impl PerceptionRecord {
    pub fn line(&self) -> PerceptionLine {
        self.line.clone()
    }
}

/// Base pose (x, y, yaw) and lift height of trial `seed`: an aisle, a spot along it at least
/// 1.5 m from its ends, the base across the aisle facing one of its rows (yaw within 0.15 rad
/// of square), its centre up to 0.15 m off the aisle's middle, the lift anywhere in 0-0.8 m.
pub fn draw_pose(setup: &PerceptionSetup, seed: u64) -> ([f64; 3], f64) {
    let mut rng = Rng::new(seed ^ 0x5EE5_F401);
    let aisles = &setup.layout.aisles;
    let a = &aisles[(rng.uniform() * aisles.len() as f64) as usize % aisles.len()];
    let x = a.x_start + 1.5 + rng.uniform() * (a.x_end - a.x_start - 3.0).max(0.0);
    let side = if rng.uniform() < 0.5 { 1.0 } else { -1.0 };
    let y = a.y + side * rng.range(-0.15, 0.15);
    let yaw = side * std::f64::consts::FRAC_PI_2 + rng.range(-0.15, 0.15);
    let lift = rng.range(0.0, 0.8);
    ([x, y, yaw], lift)
}

/// The environments of `--environment` (1-4) as [environment] tables.
fn environment(which: usize, base: Option<&toml::Table>) -> Option<toml::Table> {
    let (time, weather, vis) = match ENVIRONMENTS[which] {
        "noon" => ("13:40", "clear", None),
        "dusk" => ("21:15", "clear", None),
        "overcast" => ("13:40", "overcast", None),
        "fog" => ("13:40", "fog", Some(15.0)),
        _ => return base.cloned(),
    };
    let mut t = toml::Table::new();
    t.insert("date".into(), "2025-06-21".into());
    t.insert("time".into(), time.into());
    t.insert("utc_offset".into(), 2.0.into());
    t.insert("latitude".into(), 52.0.into());
    t.insert("longitude".into(), 4.2.into());
    t.insert("weather".into(), weather.into());
    t.insert("humidity".into(), 70.0.into());
    t.insert("render_quality".into(), "medium".into());
    if let Some(v) = vis {
        t.insert("visibility".into(), toml::Value::Float(v));
    }
    Some(t)
}

fn scenario_for(t: &Trial<PerceptionSetup>, base: [f64; 3], lift: f64) -> Scenario {
    let mut s = t.scenario.clone();
    let set = |s: &mut Scenario, comp: &str, k: &str, v: toml::Value| {
        s.parameters.entry(comp.into()).or_default().insert(k.into(), v);
    };
    for (k, v) in ["x0", "y0", "yaw0"].iter().zip(base) {
        set(&mut s, "chassis", k, toml::Value::Float(v));
    }
    set(&mut s, "lift", "position0", toml::Value::Float(lift));
    set(&mut s, "camera", "width", toml::Value::Integer(640));
    set(&mut s, "camera", "height", toml::Value::Integer(480));
    s.environment = environment(t.options.u64("environment") as usize, t.scenario.environment.as_ref());
    s
}

pub fn failed(t: &Trial<PerceptionSetup>, reason: String) -> PerceptionRecord {
    let (base, lift) = draw_pose(t.setup, t.seed);
    PerceptionRecord {
        line: PerceptionLine {
            trial: t.index,
            scene: t.scene,
            seed: t.seed,
            environment: ENVIRONMENTS[t.options.u64("environment") as usize % ENVIRONMENTS.len()].into(),
            pose: [base[0], base[1], base[2], lift],
            frames: 0,
            fruit: 0,
            found: 0,
            false_positives: 0,
            warnings: 0,
            node_ms_per_frame: None,
            wall_time: 0.0,
            error: Some(reason),
        },
        frames: vec![],
    }
}

/// The perception node, timed (wall time of its steps that processed a frame).
struct Timed {
    node: Perception,
    spent: std::rc::Rc<std::cell::Cell<(f64, u64)>>,
}

impl Node for Timed {
    fn name(&self) -> &str {
        self.node.name()
    }
    fn step(&mut self, t_ns: i64, bus: &mut agrisim_bus::Bus) -> Result<()> {
        let before = self.node.frames;
        let w = Instant::now();
        let r = self.node.step(t_ns, bus);
        if self.node.frames > before {
            let (s, n) = self.spent.get();
            self.spent.set((s + w.elapsed().as_secs_f64(), n + 1));
        }
        r
    }
}

/// What arrived of one frame: the node's detections, the labels, the colour image.
type Pending = (Option<Detection3DArray>, Option<Image>, Option<Image>);

pub fn run(t: &Trial<PerceptionSetup>, mcap: &Path) -> Result<PerceptionRecord> {
    let wall = Instant::now();
    let (base, lift) = draw_pose(t.setup, t.seed);
    let s = scenario_for(t, base, lift);
    let spent = std::rc::Rc::new(std::cell::Cell::new((0.0, 0u64)));
    let nodes: Vec<Box<dyn Node>> = vec![
        Box::new(OdomTf::default()),
        Box::new(RobotStatePublisher::agrisim()),
        Box::new(CommandScript::new(vec![], vec![LiftCommand { t: 0.0, position: lift }])),
        Box::new(Timed { node: Perception::new(PerceptionConfig::default()), spent: spent.clone() }),
    ];
    let mut m = prepare(&s, &RunOptions { seed: Some(t.seed), ..t.run.clone() }, mcap, nodes)?;
    let chassis = m.component("chassis", "perception benchmark")?;
    let lift_c = m.component("lift", "perception benchmark")?;
    let mut dets = Reader::subscribe(&mut m.bus, "/perception/detections");
    let mut labels = Reader::subscribe(&mut m.bus, "/camera/labels");
    let mut images = Reader::subscribe(&mut m.bus, "/camera/color/image_raw");
    let mut statuses = Reader::subscribe(&mut m.bus, "/agrisim/status");
    let (mut fruit_seen, mut info_seen) = (0u64, 0u64);
    let mut centers: Vec<[f64; 3]> = t.setup.fruit.iter().map(|f| f.center).collect();
    // Frames are judged once the world's fruit were seen to be the setup's.
    let mut fruit_ok = false;
    let mut k = None;
    let want = t.options.u64("frames") as usize;
    let mut by_stamp: BTreeMap<i64, Pending> = BTreeMap::new();
    let mut judged: Vec<FrameJudgement> = vec![];
    let mut overlay: Option<(Image, FrameJudgement)> = None;
    let mut warnings = 0u64;
    let step = s.timing.step;
    let max_ticks = ((want as f64 + 3.0) * 0.1 / step).ceil() as u64 + 10;
    let result: Result<()> = (|| {
        for _ in 0..max_ticks {
            m.advance()?;
            if let Some(p) = m.bus.take_new::<PoseArray>("/fruits", &mut fruit_seen)? {
                let world: Vec<[f64; 3]> = p.poses.iter().map(|q| [q.position.x, q.position.y, q.position.z]).collect();
                // The labels name the setup's fruit only in the setup's scene.
                t.setup.check_world(&world)?;
                centers = world;
                fruit_ok = true;
            }
            if let Some(info) = m.bus.take_new::<CameraInfo>("/camera/color/camera_info", &mut info_seen)? {
                k = Some([info.k[0], info.k[4], info.k[2], info.k[5]]);
            }
            for d in dets.take::<Detection3DArray>(&mut m.bus)? {
                let stamp = d.header.stamp.to_nanos();
                by_stamp.entry(stamp).or_default().0 = Some(d);
            }
            for l in labels.take::<Image>(&mut m.bus)? {
                let stamp = l.header.stamp.to_nanos();
                by_stamp.entry(stamp).or_default().1 = Some(l);
            }
            for i in images.take::<Image>(&mut m.bus)? {
                let stamp = i.header.stamp.to_nanos();
                by_stamp.entry(stamp).or_default().2 = Some(i);
            }
            warnings += statuses.take_samples(&mut m.bus).len() as u64;
            let ready: Vec<i64> =
                by_stamp.iter().filter(|(_, v)| v.0.is_some() && v.1.is_some()).map(|(s, _)| *s).collect();
            for stamp in ready {
                let (d, l, img) = by_stamp.remove(&stamp).expect("listed");
                let (Some(d), Some(l), Some(k), true) = (d, l, k, fruit_ok) else { continue };
                let cam = CameraPose::new(
                    [m.number(chassis, "x")?, m.number(chassis, "y")?, m.number(chassis, "yaw")?],
                    [MOUNT[0], MOUNT[1], MOUNT[2] + m.number(lift_c, "position")?],
                    0.0,
                );
                let j = judge_frame(t.setup, &centers, &cam, k, &l, &d);
                if let Some(img) = img {
                    overlay = Some((img, j.clone()));
                }
                judged.push(j);
            }
            if judged.len() >= want {
                break;
            }
        }
        Ok(())
    })();
    if let Err(e) = &result {
        m.record_failure(e);
    }
    m.recorder_finish()?;
    let (spent_s, n) = spent.get();
    if t.index < t.options.u64("overlays") {
        if let Some((img, j)) = &overlay {
            let png = mcap.with_extension("png");
            let _ = std::fs::write(&png, encode_rgb(img.width, img.height, &draw_overlay(img, j)));
        }
    }
    let fruit = judged.iter().map(|j| j.fruit.len() as u64).sum();
    let found = judged.iter().flat_map(|j| &j.fruit).filter(|f| f.detected).count() as u64;
    let fps = judged.iter().map(|j| j.false_positives.len() as u64).sum();
    let env = ENVIRONMENTS[t.options.u64("environment") as usize].to_string();
    Ok(PerceptionRecord {
        line: PerceptionLine {
            trial: t.index,
            scene: t.scene,
            seed: t.seed,
            environment: if env == "scenario" { s.name.clone() } else { env },
            pose: [base[0], base[1], base[2], lift],
            frames: judged.len() as u64,
            fruit,
            found,
            false_positives: fps,
            warnings,
            node_ms_per_frame: (n > 0).then(|| 1000.0 * spent_s / n as f64),
            wall_time: wall.elapsed().as_secs_f64(),
            error: result.err().map(|e| e.to_string()),
        },
        frames: judged,
    })
}

/// The frame with the judge's marks: found fruit in green, missed in magenta (circles of
/// the true projected size), false detections as red crosses.
pub fn draw_overlay(img: &Image, j: &FrameJudgement) -> Vec<u8> {
    let (w, h) = (img.width as i64, img.height as i64);
    let mut px = img.data.clone();
    px.resize((w * h * 3) as usize, 0);
    let mut put = |x: i64, y: i64, c: [u8; 3]| {
        if (0..w).contains(&x) && (0..h).contains(&y) {
            let i = ((y * w + x) * 3) as usize;
            px[i..i + 3].copy_from_slice(&c);
        }
    };
    for f in &j.fruit {
        let c = if f.detected { [40, 255, 40] } else { [255, 0, 255] };
        let r = f.radius_px.max(3.0);
        let n = (r * 8.0).ceil() as i64;
        for k in 0..n {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            for dr in [0.0, 1.0] {
                put((f.uv[0] + (r + dr) * a.cos()) as i64, (f.uv[1] + (r + dr) * a.sin()) as i64, c);
            }
        }
    }
    for fp in &j.false_positives {
        let uv = fp.uv;
        for d in -6..=6 {
            put(uv[0] as i64 + d, uv[1] as i64 + d, [255, 0, 0]);
            put(uv[0] as i64 + d, uv[1] as i64 - d, [255, 0, 0]);
        }
    }
    px
}
