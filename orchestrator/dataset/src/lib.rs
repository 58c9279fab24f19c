//! `agrisim dataset`: a synthetic perception dataset, in the manner of Isaac Sim Replicator's
//! writers. The Camera FMU renders each frame (RGB, depth, CameraInfo and its instance-label
//! image) of a scenario's greenhouse from a randomized robot pose, sun, weather and crop
//! ([`draw`]); the writer turns the labels into COCO instance segmentation with the fruit's
//! ripeness stage (the scene's ground truth) as the category, and records the camera's
//! intrinsics and pose and the fruit's 3-D poses per frame.
//!
//! Layout of `DIR` (docs/reference/formats.md):
//! `dataset.json` (settings and scenes), `annotations.json` (COCO), per frame `NNNNNN`:
//! `rgb/NNNNNN.png`, `depth/NNNNNN.png` (16-bit, mm), `instances/NNNNNN.png` (16-bit, the
//! frame's annotation index + 1) and `frames/NNNNNN.json` (everything else; written last, so
//! a frame is complete when it exists).
//!
//! Deterministic: a frame depends on (seed, index) alone, files carry no time stamps or
//! paths, and the COCO file is built from the frame files in index order; so `--resume`
//! after an interruption ends with the same bytes as an uninterrupted run. Every file is
//! written as `NAME.part` and renamed: an interruption leaves complete files only.

mod camera;
pub mod draw;
mod pngio;
pub mod pose;
pub mod post;
pub mod rle;

use agrisim_cosim::value::{self, Value};
use agrisim_error::{Context, Result};
use agrisim_robot::model::{Coords, RobotModel};
use agrisim_scene::{Greenhouse, GreenhouseConfig, Kind, Shape};
use agrisim_session::{interrupt, RunOptions, Scenario};
use camera::{CameraFmu, Shot};
use draw::{FrameDraw, SceneDraw};
use pose::{Extrinsics, Mount};
use serde::Serialize;
use serde_json::json;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Version of the layout, in `dataset.json`.
pub const FORMAT: &str = "agrisim-dataset 1";

/// COCO categories: the six USDA ripeness stages, id = stage (1 green .. 6 red).
pub const CATEGORIES: [&str; 6] = ["green", "breakers", "turning", "pink", "light_red", "red"];

const MOUNT_PARAMETERS: [&str; 6] = ["mount_x", "mount_y", "mount_z", "mount_roll", "mount_pitch", "mount_yaw"];

/// What to write.
#[derive(Clone, Debug)]
pub struct Options {
    pub frames: u64,
    pub seed: u64,
    /// Frames are spread over this many scenes, in contiguous blocks.
    pub scenes: u64,
    /// Image size (default: the scenario's `[parameters.camera]`, else the camera's).
    pub width: Option<u32>,
    pub height: Option<u32>,
    /// Keep the complete frames of an earlier run into the same directory.
    pub resume: bool,
    /// Rewrite annotations.json after every this many new frames (and at the end).
    pub coco_every: u64,
    pub out: PathBuf,
}

/// What a call wrote.
#[derive(Clone, Debug)]
pub struct Summary {
    pub frames: u64,
    /// Frames rendered by this call (the others were complete already).
    pub rendered: u64,
    pub annotations: usize,
    pub coco: PathBuf,
}

/// Writes `bytes` as `path.part`, then renames it to `path`.
fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let mut part = path.as_os_str().to_owned();
    part.push(".part");
    let part = PathBuf::from(part);
    std::fs::write(&part, bytes).context(|| format!("cannot write {}", part.display()))?;
    std::fs::rename(&part, path).context(|| format!("cannot rename {} to {}", part.display(), path.display()))
}

/// Scene of frame `i` of `n` over `k` scenes: contiguous blocks (one scene built at a time).
pub fn scene_of(i: u64, n: u64, k: u64) -> u64 {
    (i as u128 * k as u128 / n as u128) as u64
}

fn name(i: u64) -> String {
    format!("{i:06}")
}

#[derive(Serialize)]
struct Manifest<'a> {
    format: &'a str,
    scenario: &'a str,
    /// FNV-1a 64 of the scenario file's bytes (hex).
    scenario_fnv1a64: String,
    seed: u64,
    frames: u64,
    width: Option<u32>,
    height: Option<u32>,
    categories: &'a [&'a str],
    post_processing: &'a str,
    scenes: &'a [SceneDraw],
}

#[derive(Serialize)]
struct Annotation {
    category_id: u8,
    segmentation: Rle,
    area: u64,
    bbox: [u32; 4],
    iscrowd: u8,
    /// Scene object id (the camera's label value - 1) and name.
    object_id: u32,
    name: String,
    /// The value of this annotation's pixels in instances/NNNNNN.png.
    instance: u16,
}

#[derive(Serialize)]
struct Rle {
    size: [u32; 2],
    counts: String,
}

#[derive(Serialize)]
struct Fruit {
    object_id: u32,
    name: String,
    ripeness: u8,
    category: &'static str,
    radius: f64,
    /// Centre and orientation (x, y, z, w) in the map frame.
    position: [f64; 3],
    orientation: [f64; 4],
    /// Centre in the camera's optical frame.
    position_camera: [f64; 3],
    /// Pixels of the fruit in the labels image (0: in the field of view but hidden).
    visible_pixels: u64,
    /// The fruit's annotation in this frame (index into `annotations`), if visible.
    annotation: Option<usize>,
}

/// Per instance of a frame: pixel count, bounds (u0, v0, u1, v1) and column-major runs.
struct Instance {
    object: u32,
    area: u64,
    bounds: [u32; 4],
    runs: Vec<u64>,
}

/// The fruit instances of a labels image (label = object id + 1): one pass in column-major
/// order, runs as COCO counts them. Sorted by object id.
fn fruit_instances(labels: &[i32], w: usize, h: usize, g: &Greenhouse) -> Vec<Instance> {
    let mut by_object: BTreeMap<u32, (Instance, usize)> = BTreeMap::new();
    for u in 0..w {
        for v in 0..h {
            let l = labels[v * w + u];
            let Some(object) = (l > 0).then(|| (l - 1) as u32) else { continue };
            if !matches!(g.object(object).map(|o| o.kind), Some(Kind::Fruit { .. })) {
                continue;
            }
            let k = u * h + v;
            let (inst, end) = by_object.entry(object).or_insert_with(|| {
                (Instance { object, area: 0, bounds: [u as u32, v as u32, u as u32, v as u32], runs: vec![] }, 0)
            });
            if inst.runs.is_empty() || *end != k {
                inst.runs.push((k - *end) as u64); // zeros since the last run
                inst.runs.push(0);
            }
            *inst.runs.last_mut().expect("pushed") += 1;
            *end = k + 1;
            inst.area += 1;
            let b = &mut inst.bounds;
            *b = [b[0].min(u as u32), b[1].min(v as u32), b[2].max(u as u32), b[3].max(v as u32)];
        }
    }
    by_object
        .into_values()
        .map(|(mut inst, end)| {
            // The closing zeros, if any (COCO's encoder writes no empty last run).
            if end < w * h {
                inst.runs.push((w * h - end) as u64);
            }
            inst
        })
        .collect()
}

/// The per-frame values given to the Camera FMU: scene, environment, the scenario's camera
/// parameters, size, noise seed, the jittered mount, then the robot's inputs.
fn camera_values(
    cam: &CameraFmu,
    s: &Scenario,
    o: &Options,
    scene: &SceneDraw,
    f: &FrameDraw,
    mount: &Mount,
) -> Result<Vec<(String, Value)>> {
    let mut v: Vec<(String, Value)> = vec![
        ("scene".into(), Value::Str(scene.greenhouse.clone())),
        ("environment".into(), Value::Str(f.environment(s.environment.as_ref()))),
    ];
    for (n, x) in s.parameters.get("camera").into_iter().flatten() {
        // The scene, its seed and the mount are this writer's (the ground truth must be the
        // scene the camera renders); the rest (e.g. depth noise) as the scenario says.
        if MOUNT_PARAMETERS.contains(&n.as_str())
            || ["scene", "scene_seed", "environment", "seed"].contains(&n.as_str())
        {
            continue;
        }
        let val = value::from_toml(&cam.variable(n)?, x)
            .map_err(|e| agrisim_error::err!("scenario parameter camera.{n}: {e}"))?;
        v.push((n.clone(), val));
    }
    if let Some(w) = o.width {
        v.push(("width".into(), Value::I32(w as i32)));
    }
    if let Some(h) = o.height {
        v.push(("height".into(), Value::I32(h as i32)));
    }
    v.push(("seed".into(), Value::I32(f.noise_seed)));
    let m = [mount.x, mount.y, mount.z, mount.roll, mount.pitch, mount.yaw];
    for (n, x) in MOUNT_PARAMETERS.iter().zip(m) {
        v.push((n.to_string(), Value::F64(x)));
    }
    v.push(("lift_position".into(), Value::F64(f.lift)));
    for (n, x) in ["base_x", "base_y", "base_yaw"].iter().zip(f.base) {
        v.push((n.to_string(), Value::F64(x)));
    }
    Ok(v)
}

fn json_of(v: &Value) -> serde_json::Value {
    match v {
        Value::F64(x) => json!(x),
        Value::I32(x) => json!(x),
        Value::I64(x) => json!(x),
        Value::Bool(x) => json!(x),
        Value::Str(x) => json!(x),
        Value::Bin(x) => json!(x),
    }
}

/// Where the camera is: the scenario's `[parameters.camera]` mount_parent and mount_*, else
/// the Camera FMU's own (their start values); the parent's name (None: the FMU has no
/// mount_parent, its mount is on base_link).
fn base_mount(s: &Scenario, cam: &CameraFmu) -> (Mount, Option<String>) {
    let p = s.parameters.get("camera");
    let get = |n: &str| {
        let given = p.and_then(|p| p.get(n)).and_then(|v| v.as_float().or(v.as_integer().map(|i| i as f64)));
        given.or_else(|| cam.variable(n).ok()?.start.as_deref()?.parse().ok()).unwrap_or(0.0)
    };
    let parent = match p.and_then(|p| p.get("mount_parent")).and_then(|v| v.as_str()) {
        Some(name) => Some(name.to_string()),
        None => cam.variable("mount_parent").ok().and_then(|v| v.start.clone()),
    };
    let mount = Mount {
        x: get("mount_x"),
        y: get("mount_y"),
        z: get("mount_z"),
        roll: get("mount_roll"),
        pitch: get("mount_pitch"),
        yaw: get("mount_yaw"),
    };
    (mount, parent)
}

/// The mount's parent link in base_link with the lift at `lift` (arms in the ready pose, the
/// Camera FMU's input defaults): the URDF's forward kinematics, as the camera places itself.
fn parent_in_base(robot: &RobotModel, parent: Option<&str>, lift: f64) -> Result<(pose::Mat3, [f64; 3])> {
    let Some(name) = parent else { return Ok(([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], [0.0; 3])) };
    let i = robot
        .link_index(name)
        .ok_or_else(|| agrisim_error::err!("camera mount_parent {name:?} is not a link of the robot"))?;
    let mut fk = Vec::new();
    robot.fk(&Coords { lift, ..Coords::default() }, &mut fk);
    Ok((fk[i].rot, fk[i].trans))
}

fn ext_of(mount: &Mount, parent: (pose::Mat3, [f64; 3]), f: &FrameDraw) -> Extrinsics {
    Extrinsics::new(mount, parent, f.base[0], f.base[1], f.base[2])
}

fn depth_m(data: &[u8]) -> Vec<f32> {
    data.chunks_exact(4).map(|b| f32::from_le_bytes(b.try_into().expect("4 bytes"))).collect()
}

/// Largest median distance [m] of a fruit's depth pixels from its sphere in a scene that
/// agrees with the camera's (generous: stereo noise at a few metres in small images).
const AGREEMENT_TOLERANCE: f64 = 0.25;

/// Checks that the fruit the labels name are where this build's scene generator put them:
/// each instance's depth pixels, reprojected with K and the camera pose, must lie near its
/// sphere (median over the pixels). A Camera FMU built from another version of the scene
/// generator labels other objects; its masks would get wrong categories and poses.
fn check_scene_agreement(
    instances: &[Instance],
    labels: &[i32],
    depth: &[f32],
    k: &[f64; 9],
    ext: &Extrinsics,
    w: usize,
    g: &Greenhouse,
) -> std::result::Result<(), String> {
    let h = depth.len() / w;
    let (mut tried, mut failed) = (0, 0);
    for inst in instances {
        let o = g.object(inst.object).expect("a fruit of the scene");
        let Shape::Sphere { radius } = o.shape else { continue };
        let c = ext.to_camera(o.placement.translation);
        let mut errors: Vec<f64> = vec![];
        let [u0, v0, u1, v1] = inst.bounds.map(|b| b as usize);
        for v in v0..=v1.min(h - 1) {
            for u in u0..=u1 {
                let z = depth[v * w + u] as f64;
                if z <= 0.0 || labels[v * w + u] != inst.object as i32 + 1 {
                    continue;
                }
                let p = [(u as f64 - k[2]) / k[0] * z, (v as f64 - k[5]) / k[4] * z, z];
                let d = ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2) + (p[2] - c[2]).powi(2)).sqrt();
                errors.push((d - radius).abs());
            }
        }
        if errors.len() < 5 {
            continue;
        }
        errors.sort_by(f64::total_cmp);
        tried += 1;
        if errors[errors.len() / 2] > AGREEMENT_TOLERANCE {
            failed += 1;
        }
    }
    if tried >= 3 && 2 * failed > tried {
        return Err(format!(
            "{failed} of {tried} labelled fruit are not where this build's scene generator and camera pose put \
             them: the Camera FMU was built from another version of the scene or the camera mounting \
             (rebuild, then `agrisim fmu pack`)"
        ));
    }
    Ok(())
}

/// Renders and writes frame `i`; returns its record (frames/NNNNNN.json) as JSON text.
#[allow(clippy::too_many_arguments)]
fn frame(
    cam: &CameraFmu,
    s: &Scenario,
    o: &Options,
    i: u64,
    scene: &SceneDraw,
    g: &Greenhouse,
    placement: &(Mount, Option<String>, RobotModel),
) -> Result<String> {
    let (mount0, parent, robot) = placement;
    let f = draw::frame(o.seed, i, &g.layout.aisles);
    let parent = parent_in_base(robot, parent.as_deref(), f.lift)?;
    let j = f.mount_jitter;
    let mount = Mount {
        x: mount0.x + j[0],
        y: mount0.y + j[1],
        z: mount0.z + j[2],
        roll: mount0.roll + j[3],
        pitch: mount0.pitch + j[4],
        yaw: mount0.yaw + j[5],
    };
    let values = camera_values(cam, s, o, scene, &f, &mount)?;
    let Shot { mut rgb, depth, labels, info, solar_zenith, solar_azimuth, visibility, range_max } =
        cam.shoot(&values)?;
    let (w, h) = (info.width as usize, info.height as usize);
    let labels: Vec<i32> =
        labels.data.chunks_exact(4).map(|b| i32::from_le_bytes(b.try_into().expect("4 bytes"))).collect();
    let instances = fruit_instances(&labels, w, h, g);
    if instances.len() > u16::MAX as usize {
        return Err(agrisim_error::err!("frame {i}: {} fruit instances exceed 16-bit instance ids", instances.len()));
    }

    check_scene_agreement(&instances, &labels, &depth_m(&depth.data), &info.k, &ext_of(&mount, parent, &f), w, g)
        .map_err(|e| agrisim_error::err!("frame {i}: {e}"))?;

    // Post-processing: each fruit's hue, then exposure and white balance.
    let hues: BTreeMap<u32, f64> =
        instances.iter().map(|inst| (inst.object, draw::fruit_hue(o.seed, scene.index, inst.object))).collect();
    let mut index = vec![0u16; w * h];
    let slot: BTreeMap<u32, u16> = instances.iter().enumerate().map(|(k, inst)| (inst.object, k as u16 + 1)).collect();
    for (p, &l) in labels.iter().enumerate() {
        if let Some(&k) = (l > 0).then(|| slot.get(&((l - 1) as u32))).flatten() {
            index[p] = k;
            post::rotate_hue(&mut rgb.data[3 * p..3 * p + 3], hues[&((l - 1) as u32)]);
        }
    }
    post::exposure_white_balance(&mut rgb.data, f.exposure_ev, f.white_balance);

    let mm: Vec<u16> = depth
        .data
        .chunks_exact(4)
        .map(|b| {
            let z = f32::from_le_bytes(b.try_into().expect("4 bytes")) as f64;
            if z > 0.0 && z.is_finite() {
                (z * 1000.0).round().min(u16::MAX as f64) as u16
            } else {
                0
            }
        })
        .collect();

    let n = name(i);
    let (rgb_file, depth_file, inst_file, frame_file) =
        (format!("rgb/{n}.png"), format!("depth/{n}.png"), format!("instances/{n}.png"), format!("frames/{n}.json"));
    write_atomic(&o.out.join(&rgb_file), &pngio::rgb8(w as u32, h as u32, &rgb.data))?;
    write_atomic(&o.out.join(&depth_file), &pngio::grey16(w as u32, h as u32, &mm))?;
    write_atomic(&o.out.join(&inst_file), &pngio::grey16(w as u32, h as u32, &index))?;

    let annotations: Vec<Annotation> = instances
        .iter()
        .enumerate()
        .map(|(k, inst)| {
            let o = g.object(inst.object).expect("a fruit of the scene");
            let Kind::Fruit { ripeness } = o.kind else { unreachable!("fruit instances only") };
            let [u0, v0, u1, v1] = inst.bounds;
            Annotation {
                category_id: ripeness,
                segmentation: Rle { size: [h as u32, w as u32], counts: rle::to_string(&inst.runs) },
                area: inst.area,
                bbox: [u0, v0, u1 - u0 + 1, v1 - v0 + 1],
                iscrowd: 0,
                object_id: inst.object,
                name: o.name.clone(),
                instance: k as u16 + 1,
            }
        })
        .collect();

    // Fruit whose centre is in the field of view and depth range, and every visible one.
    let ext = ext_of(&mount, parent, &f);
    let k = info.k;
    let visible: BTreeMap<u32, (u64, usize)> =
        instances.iter().enumerate().map(|(a, inst)| (inst.object, (inst.area, a))).collect();
    let fruits: Vec<Fruit> = g
        .objects
        .iter()
        .filter_map(|o| {
            let Kind::Fruit { ripeness } = o.kind else { return None };
            let c = ext.to_camera(o.placement.translation);
            let (u, v) = (k[0] * c[0] / c[2] + k[2], k[4] * c[1] / c[2] + k[5]);
            let in_view = c[2] > 0.0
                && c[2] <= range_max
                && (-0.5..w as f64 - 0.5).contains(&u)
                && (-0.5..h as f64 - 0.5).contains(&v);
            let seen = visible.get(&o.id);
            (in_view || seen.is_some()).then(|| Fruit {
                object_id: o.id,
                name: o.name.clone(),
                ripeness,
                category: CATEGORIES[(ripeness.clamp(1, 6) - 1) as usize],
                radius: match o.shape {
                    Shape::Sphere { radius } => radius,
                    _ => 0.0,
                },
                position: o.placement.translation,
                orientation: o.placement.rotation,
                position_camera: c,
                visible_pixels: seen.map_or(0, |s| s.0),
                annotation: seen.map(|s| s.1),
            })
        })
        .collect();

    let record = json!({
        "frame": i,
        "scene": scene.index,
        "image": {
            "id": i + 1,
            "file_name": rgb_file,
            "width": w,
            "height": h,
            "depth_file": depth_file,
            "instances_file": inst_file,
            "frame_file": frame_file,
            "scene": scene.index,
        },
        "camera_info": {
            "frame_id": info.header.frame_id,
            "width": info.width,
            "height": info.height,
            "distortion_model": info.distortion_model,
            "d": info.d,
            "k": info.k,
            "r": info.r,
            "p": info.p,
        },
        "extrinsics": {
            "parent_frame": "map",
            "child_frame": info.header.frame_id,
            "translation": ext.translation,
            "rotation_xyzw": ext.quaternion(),
            "matrix": ext.matrix(),
        },
        "robot": {
            "base_x": f.base[0], "base_y": f.base[1], "base_yaw": f.base[2], "lift": f.lift,
            "mount_parent": placement.1, "mount": mount,
        },
        "sun": { "solar_zenith_deg": solar_zenith, "solar_azimuth_deg": solar_azimuth, "visibility_m": visibility },
        "randomization": f,
        "camera_parameters": values.iter().map(|(n, v)| (n.clone(), json_of(v))).collect::<BTreeMap<_, _>>(),
        "annotations": annotations,
        "fruits": fruits,
    });
    let text = serde_json::to_string(&record).expect("JSON values serialize") + "\n";
    write_atomic(&o.out.join(&frame_file), text.as_bytes())?;
    Ok(text)
}

/// The part of a frame record the COCO file takes: its image and annotations.
fn coco_part(mut record: serde_json::Value) -> serde_json::Value {
    json!({"image": record["image"].take(), "annotations": record["annotations"].take()})
}

/// The COCO file of the complete frames (records in index order; ids in that order).
fn coco(records: &[Option<serde_json::Value>]) -> (String, usize) {
    let mut images = vec![];
    let mut annotations = vec![];
    for r in records.iter().flatten() {
        let image = r["image"].clone();
        let id = image["id"].clone();
        images.push(image);
        for a in r["annotations"].as_array().into_iter().flatten() {
            let mut a = a.clone();
            if let Some(m) = a.as_object_mut() {
                m.insert("id".into(), json!(annotations.len() + 1));
                m.insert("image_id".into(), id.clone());
            }
            annotations.push(a);
        }
    }
    let n = annotations.len();
    let categories: Vec<_> = CATEGORIES
        .iter()
        .enumerate()
        .map(|(k, c)| json!({"id": k + 1, "name": c, "supercategory": "tomato"}))
        .collect();
    let doc = json!({
        "info": {"description": "agrisim synthetic greenhouse dataset", "version": FORMAT},
        "licenses": [],
        "categories": categories,
        "images": images,
        "annotations": annotations,
    });
    (serde_json::to_string(&doc).expect("JSON values serialize") + "\n", n)
}

/// Writes (or, with `resume`, completes) the dataset; `progress(k, n)` after every frame.
pub fn write(s: &Scenario, run: &RunOptions, o: &Options, progress: &mut dyn FnMut(u64, u64)) -> Result<Summary> {
    if o.frames == 0 || o.scenes == 0 || o.scenes > o.frames {
        return Err(agrisim_error::err!(
            "need frames >= 1 and 1 <= scenes <= frames (got {} and {})",
            o.frames,
            o.scenes
        ));
    }
    let text = std::fs::read(&s.path).context(|| format!("cannot read scenario {}", s.path.display()))?;
    let table: toml::Table = toml::from_str(&s.scene_toml()).expect("the scenario's own greenhouse table");
    let scenes = (0..o.scenes)
        .map(|k| draw::scene(o.seed, k, &table))
        .collect::<std::result::Result<Vec<_>, _>>()
        .map_err(|e| agrisim_error::err!("scenario {}: [greenhouse]: {e}", s.path.display()))?;
    let manifest = Manifest {
        format: FORMAT,
        scenario: &s.name,
        scenario_fnv1a64: format!("{:016x}", agrisim_cosim::archive::fnv1a64(&text)),
        seed: o.seed,
        frames: o.frames,
        width: o.width,
        height: o.height,
        categories: &CATEGORIES,
        post_processing:
            "fruit hue (YIQ rotation of each fruit's pixels), then exposure and white balance (gains on linear sRGB)",
        scenes: &scenes,
    };
    let manifest = serde_json::to_string_pretty(&manifest).expect("plain struct serializes") + "\n";
    let manifest_path = o.out.join("dataset.json");
    match std::fs::read_to_string(&manifest_path) {
        Ok(_) if !o.resume => {
            return Err(agrisim_error::err!(
                "{} already holds a dataset: --resume to complete it, or another --out",
                o.out.display()
            ));
        }
        Ok(old) if old != manifest => {
            return Err(agrisim_error::err!(
                "--resume: {} was written with other settings (scenario, seed, frames, scenes or size)",
                manifest_path.display()
            ));
        }
        _ => {}
    }
    for d in ["rgb", "depth", "instances", "frames"] {
        std::fs::create_dir_all(o.out.join(d)).context(|| format!("cannot create {}", o.out.join(d).display()))?;
    }
    write_atomic(&manifest_path, manifest.as_bytes())?;

    // Complete frames of an earlier run (their frame file is written last).
    let mut records: Vec<Option<serde_json::Value>> = vec![None; o.frames as usize];
    if o.resume {
        for (i, r) in records.iter_mut().enumerate() {
            let p = o.out.join(format!("frames/{}.json", name(i as u64)));
            if let Ok(t) = std::fs::read_to_string(&p) {
                let record = serde_json::from_str(&t).context(|| format!("--resume: {} is not JSON", p.display()))?;
                *r = Some(coco_part(record));
            }
        }
    }
    let coco_path = o.out.join("annotations.json");
    let write_coco = |records: &[Option<serde_json::Value>]| -> Result<usize> {
        let (text, n) = coco(records);
        write_atomic(&coco_path, text.as_bytes())?;
        Ok(n)
    };
    let done = records.iter().filter(|r| r.is_some()).count() as u64;
    progress(done, o.frames);
    write_coco(&records)?;

    let cam = CameraFmu::open(&run.fmu_dir, &run.cache_dir)?;
    let (mount, parent) = base_mount(s, &cam);
    let robot = RobotModel::load().map_err(|e| agrisim_error::err!("the robot model: {e}"))?;
    let placement = (mount, parent, robot);
    let mut scene: Option<(u64, Greenhouse)> = None;
    let (mut rendered, mut since) = (0, 0);
    for i in 0..o.frames {
        if records[i as usize].is_some() {
            continue;
        }
        if interrupt::requested() {
            let n = write_coco(&records)?;
            return Err(agrisim_error::err!(
                "{}: {} of {} frames complete ({n} annotations) in {}; --resume completes it",
                interrupt::INTERRUPTED,
                records.iter().filter(|r| r.is_some()).count(),
                o.frames,
                o.out.display()
            ));
        }
        let k = scene_of(i, o.frames, o.scenes);
        if scene.as_ref().map(|(j, _)| *j) != Some(k) {
            let cfg = GreenhouseConfig::from_toml_str(&scenes[k as usize].greenhouse)
                .map_err(|e| agrisim_error::err!("scene {k}: {e}"))?;
            let g = agrisim_scene::generate(&cfg, cfg.seed);
            if g.layout.aisles.is_empty() {
                return Err(agrisim_error::err!("scenario {}: the greenhouse has no aisle", s.path.display()));
            }
            scene = Some((k, g));
        }
        let g = &scene.as_ref().expect("set above").1;
        let text = frame(&cam, s, o, i, &scenes[k as usize], g, &placement)?;
        records[i as usize] = Some(coco_part(serde_json::from_str(&text).expect("written by this program")));
        rendered += 1;
        since += 1;
        if since >= o.coco_every.max(1) {
            write_coco(&records)?;
            since = 0;
        }
        progress(records.iter().filter(|r| r.is_some()).count() as u64, o.frames);
    }
    let annotations = write_coco(&records)?;
    Ok(Summary { frames: o.frames, rendered, annotations, coco: coco_path })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scenes_are_contiguous_blocks() {
        let s: Vec<u64> = (0..7).map(|i| scene_of(i, 7, 3)).collect();
        assert_eq!(s, vec![0, 0, 0, 1, 1, 2, 2]);
        assert_eq!((0..5).map(|i| scene_of(i, 5, 5)).collect::<Vec<_>>(), vec![0, 1, 2, 3, 4]);
    }

    #[test]
    fn instances_give_the_runs_of_each_fruit_mask() {
        let cfg = GreenhouseConfig::from_toml_str("rows = 2\nactive_rows = 2\nrow_length = 2.0").unwrap();
        let g = agrisim_scene::generate(&cfg, 1);
        let fruit: Vec<u32> =
            g.objects.iter().filter(|o| matches!(o.kind, Kind::Fruit { .. })).map(|o| o.id).take(3).collect();
        let other = g.objects.iter().find(|o| o.kind == Kind::Leaf).unwrap().id;
        let (w, h) = (9, 7);
        let mut state = 99u64;
        let labels: Vec<i32> = (0..w * h)
            .map(|_| {
                state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                match (state >> 40) % 6 {
                    0 => 0,
                    1 => other as i32 + 1,
                    r => fruit[(r as usize - 2).min(2)] as i32 + 1,
                }
            })
            .collect();
        let inst = fruit_instances(&labels, w, h, &g);
        assert_eq!(inst.iter().map(|i| i.object).collect::<Vec<_>>(), {
            let mut f = fruit.clone();
            f.sort();
            f
        });
        for i in &inst {
            let mask = |p: usize| labels[p] == i.object as i32 + 1;
            assert_eq!(i.runs, rle::runs(mask, w, h));
            assert_eq!(i.area, (0..w * h).filter(|&p| mask(p)).count() as u64);
            let us: Vec<u32> = (0..w * h).filter(|&p| mask(p)).map(|p| (p % w) as u32).collect();
            let vs: Vec<u32> = (0..w * h).filter(|&p| mask(p)).map(|p| (p / w) as u32).collect();
            let b = [
                *us.iter().min().unwrap(),
                *vs.iter().min().unwrap(),
                *us.iter().max().unwrap(),
                *vs.iter().max().unwrap(),
            ];
            assert_eq!(i.bounds, b);
        }
    }
}
