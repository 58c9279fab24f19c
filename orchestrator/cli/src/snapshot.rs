//! `agrisim snapshot`: pictures for people. It loads the Camera and Lidar FMUs like any FMI
//! importer would, places the robot in an aisle of the scenario's greenhouse, and writes the
//! RGB image, a colour-mapped depth image and a top-down view of one second of LiDAR points.
//! The scenario's `[environment]` (sun, weather) and `[parameters.camera]` / `[parameters.lidar]`
//! apply as in a run. The robot poses as at work: lift raised, both arms reaching forward
//! and down (the sensors see its links); the scenario's parameters can set those inputs too.

use crate::png::{colormap, encode_rgb};
use agrisim_cosim::archive::FmuArchive;
use agrisim_cosim::fmi3::Instance;
use agrisim_cosim::value::{self, Value};
use agrisim_error::{Context, Result};
use agrisim_msgs::sensor_msgs::{Image, PointCloud2};
use agrisim_msgs::Message;
use agrisim_session::RunOptions;
use agrisim_session::Scenario;
use std::path::{Path, PathBuf};

const STEP: f64 = 0.02;

/// The robot's pose in the pictures: lift extension and both arms' joints (hands 0.9 m ahead
/// of base_link, 0.25 m to each side, 0.76 m above the lift's lowest position).
const LIFT: f64 = 0.3;
const ARMS: [f64; 7] = [0.0, 0.6, 0.0, -1.6, 0.0, 2.2, 0.785];

/// Instantiates `file` as component `name`: the scenario's scene and environment, the robot's
/// working pose (and the camera on the lift) where the scenario does not set them, its
/// `[parameters.<name>]` overrides (e.g. the camera's resolution), then the base pose.
fn open(s: &Scenario, o: &RunOptions, file: &str, name: &str, pose: [f64; 3]) -> Result<(FmuArchive, Instance)> {
    let a = FmuArchive::open(&o.fmu_dir.join(file), &o.cache_dir)?;
    let mut inst = Instance::instantiate(&a, name, false)?;
    let var =
        |n: &str| a.md.variable(n).cloned().ok_or_else(|| agrisim_error::err!("FMU {file} has no variable '{n}'"));
    value::set(&mut inst, &var("scene")?, &Value::Str(s.scene_toml()))?;
    let environment = s.environment_toml();
    if !environment.is_empty() {
        value::set(&mut inst, &var("environment")?, &Value::Str(environment))?;
    }
    let given = s.parameters.get(name);
    // The camera's default mount is the robot's camera_link on the lift carriage (URDF).
    let mut robot = vec![("lift_position".to_string(), LIFT)];
    for side in ["left", "right"] {
        robot.extend(ARMS.iter().enumerate().map(|(i, &q)| (format!("{side}_q{}", i + 1), q)));
    }
    for (n, v) in robot {
        if let (Some(var), false) = (a.md.variable(&n), given.is_some_and(|p| p.contains_key(&n))) {
            value::set(&mut inst, &var.clone(), &Value::F64(v))?;
        }
    }
    for (n, v) in given.into_iter().flatten() {
        let var = var(n)?;
        let val = value::from_toml(&var, v).map_err(|e| agrisim_error::err!("scenario parameter {name}.{n}: {e}"))?;
        value::set(&mut inst, &var, &val)?;
    }
    for (n, v) in ["base_x", "base_y", "base_yaw"].iter().zip(pose) {
        value::set(&mut inst, &var(n)?, &Value::F64(v))?;
    }
    inst.enter_initialization_mode(0.0, None)?;
    inst.exit_initialization_mode()?;
    Ok((a, inst))
}

/// The newest message in message port `name` (a frame list).
fn get_bin(a: &FmuArchive, inst: &mut Instance, name: &str) -> Result<Vec<u8>> {
    let v =
        a.md.variable(name)
            .cloned()
            .ok_or_else(|| agrisim_error::err!("FMU '{}' has no variable '{name}'", inst.name()))?;
    match value::get(inst, &v)? {
        Value::Bin(b) => {
            let frames =
                agrisim_frames::decode(&b).map_err(|e| agrisim_error::err!("FMU '{}': {name}: {e}", inst.name()))?;
            frames
                .last()
                .map(|f| f.payload.to_vec())
                .ok_or_else(|| agrisim_error::err!("FMU '{}': no message in {name}", inst.name()))
        }
        other => Err(agrisim_error::err!("FMU '{}': {name} is {other:?}, expected Binary", inst.name())),
    }
}

fn get_seq(a: &FmuArchive, inst: &mut Instance, name: &str) -> Result<i64> {
    let v =
        a.md.variable(name)
            .cloned()
            .ok_or_else(|| agrisim_error::err!("FMU '{}' has no variable '{name}'", inst.name()))?;
    match value::get(inst, &v)? {
        Value::I64(n) => Ok(n),
        other => Err(agrisim_error::err!("FMU '{}': {name} is {other:?}, expected Int64", inst.name())),
    }
}

fn write(path: PathBuf, w: u32, h: u32, rgb: &[u8], written: &mut Vec<PathBuf>) -> Result<()> {
    std::fs::write(&path, encode_rgb(w, h, rgb)).context(|| format!("cannot write {}", path.display()))?;
    written.push(path);
    Ok(())
}

/// Writes rgb.png, depth.png, lidar_top.png and lidar_near.png into `out`; returns their paths.
pub fn snapshot(s: &Scenario, o: &RunOptions, out: &Path) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(out).context(|| format!("cannot create {}", out.display()))?;
    let g = agrisim_session::scene::generate_scene(s)?;
    let aisle = g
        .layout
        .aisles
        .get(g.layout.aisles.len() / 2)
        .ok_or_else(|| agrisim_error::err!("scenario {}: the greenhouse has no aisle", s.path.display()))?;
    let pose = [aisle.x_start + 1.5, aisle.y, 0.0];
    let mut written = vec![];

    let (ca, mut cam) = open(s, o, "Camera.fmu", "camera", pose)?;
    let mut t = 0.0;
    while get_seq(&ca, &mut cam, "image_seq")? == 0 && t < 1.0 {
        cam.do_step(t, STEP)?;
        t += STEP;
    }
    let img =
        Image::from_cdr(&get_bin(&ca, &mut cam, "image")?).map_err(|e| agrisim_error::err!("Camera image: {e}"))?;
    write(out.join("rgb.png"), img.width, img.height, &img.data, &mut written)?;
    let depth =
        Image::from_cdr(&get_bin(&ca, &mut cam, "depth")?).map_err(|e| agrisim_error::err!("Camera depth: {e}"))?;
    let mut rgb = Vec::with_capacity(depth.data.len() / 4 * 3);
    for px in depth.data.chunks_exact(4) {
        let z = f32::from_le_bytes(px.try_into().expect("4 bytes")) as f64;
        rgb.extend_from_slice(&if z > 0.0 { colormap(z / 10.0) } else { [0, 0, 0] });
    }
    write(out.join("depth.png"), depth.width, depth.height, &rgb, &mut written)?;

    // One second of LiDAR frames, top-down, coloured by height (points above 2.5 m left
    // out): 20 m x 20 m around the robot, and 4 m x 4 m (the robot's own links).
    let (la, mut lidar) = open(s, o, "Lidar.fmu", "lidar", pose)?;
    let mount_z = la.md.variable("mount_z").and_then(|v| v.start.as_deref()?.parse::<f64>().ok()).unwrap_or(1.0);
    let px = 800usize;
    let mut views = [(20.0, vec![245u8; px * px * 3]), (4.0, vec![245u8; px * px * 3])];
    let mut seen = 0;
    let mut t = 0.0;
    for _ in 0..50 {
        lidar.do_step(t, STEP)?;
        t += STEP;
        let n = get_seq(&la, &mut lidar, "points_seq")?;
        if n == seen {
            continue;
        }
        seen = n;
        let pc = PointCloud2::from_cdr(&get_bin(&la, &mut lidar, "points")?)
            .map_err(|e| agrisim_error::err!("Lidar points: {e}"))?;
        for p in pc.data.chunks_exact(pc.point_step as usize) {
            let f = |i: usize| f32::from_le_bytes(p[4 * i..4 * i + 4].try_into().expect("4 bytes")) as f64;
            let (x, y, z) = (f(0), f(1), f(2) + mount_z);
            if (f(0) == 0.0 && f(1) == 0.0 && f(2) == 0.0) || z > 2.5 {
                continue; // no return, or roof and gutters (they would hide the rows)
            }
            for (size, top) in views.iter_mut() {
                let (i, j) =
                    (((x + *size / 2.0) / *size * px as f64) as i64, ((*size / 2.0 - y) / *size * px as f64) as i64);
                if (0..px as i64).contains(&i) && (0..px as i64).contains(&j) {
                    let k = (j as usize * px + i as usize) * 3;
                    top[k..k + 3].copy_from_slice(&colormap(z / 2.5));
                }
            }
        }
    }
    let [(_, top), (_, near)] = views;
    write(out.join("lidar_top.png"), px as u32, px as u32, &top, &mut written)?;
    write(out.join("lidar_near.png"), px as u32, px as u32, &near, &mut written)?;
    Ok(written)
}
