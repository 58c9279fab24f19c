//! The camera's primary (depth) rays on the default greenhouse, timed on one thread, and
//! written for python/bench_raycast.py --camera to cast the same rays with Open3D.
//!
//! `cargo run --release -p agrisim-fmu-camera --example depth_rays -- [--out DIR] [--poses N]`
//!
//! Rays: one per pixel centre of a 1280x720 D435i frame (87 x 58 deg) from N poses along the
//! middle aisle (alternately looking along the aisle and at a row), as the camera casts them.
//! With --out: DIR/scene.glb, DIR/rays.npy (float32 origin + direction), DIR/dist.npy (float64
//! hit distance, inf = none) and DIR/rust.json, the files bench_raycast.py reads.

use agrisim_fmu_camera::optics::{CameraPose, Intrinsics, Mount};
use agrisim_math::vec3::mat_vec;
use agrisim_raycast::RayCaster;
use agrisim_scene::{generate, GreenhouseConfig};
#[path = "../../lib/raycast/examples/common/mod.rs"]
mod common;

const FAR: f64 = 1000.0;

fn main() {
    let poses: usize = common::arg("--poses").map_or(2, |s| s.parse().expect("--poses N"));
    let cfg = GreenhouseConfig::default();
    let gh = generate(&cfg, cfg.seed);
    let rc = RayCaster::new(&gh.objects);
    let k = Intrinsics::from_fov(1280, 720, 87.0, 58.0);
    let mount = Mount { translation: [0.32, 0.0, 0.8], roll: 0.0, pitch: 0.0, yaw: 0.0 };
    let a = &gh.layout.aisles[gh.layout.aisles.len() / 2];
    let mut rays: Vec<[f32; 6]> = Vec::with_capacity(poses * 1280 * 720);
    for p in 0..poses {
        let x = a.x_start + 1.5 + (a.x_end - a.x_start - 3.0) * p as f64 / poses.max(2) as f64;
        let yaw = if p % 2 == 0 { 0.0 } else { std::f64::consts::FRAC_PI_2 };
        let pose = CameraPose::new(&mount, x, a.y, yaw);
        for v in 0..720 {
            for u in 0..1280 {
                let d = mat_vec(&pose.rotation, k.ray(u as f64, v as f64));
                let o = pose.origin;
                rays.push([o[0], o[1], o[2], d[0], d[1], d[2]].map(|c| c as f32));
            }
        }
    }
    let ray = |r: &[f32; 6]| ([r[0] as f64, r[1] as f64, r[2] as f64], [r[3] as f64, r[4] as f64, r[5] as f64]);
    let none = RayCaster::new(&[]);
    // Single rays, in pixel order.
    let single = |rays: &[[f32; 6]]| -> Vec<f64> {
        rays.iter()
            .map(|r| {
                let (o, d) = ray(r);
                rc.cast(o, d, 0.0, FAR, &[]).map_or(f64::INFINITY, |h| h.distance)
            })
            .collect()
    };
    // Packets as the camera casts them: tiles of 8 rows x 8 columns from the frame's origin.
    let packets = |rays: &[[f32; 6]]| -> Vec<f64> {
        let mut dist = vec![f64::INFINITY; rays.len()];
        let (w, h) = (1280usize, 720usize);
        let mut dirs = Vec::with_capacity(64);
        let mut idx = Vec::with_capacity(64);
        let mut hits = [None; 64];
        for f in 0..rays.len() / (w * h) {
            for v0 in (0..h).step_by(8) {
                for u0 in (0..w).step_by(8) {
                    dirs.clear();
                    idx.clear();
                    for v in v0..(v0 + 8).min(h) {
                        for u in u0..(u0 + 8).min(w) {
                            let i = f * w * h + v * w + u;
                            dirs.push(ray(&rays[i]).1);
                            idx.push(i);
                        }
                    }
                    let o = ray(&rays[idx[0]]).0;
                    rc.cast_packet(o, &dirs, 0.0, FAR, &none, &mut hits[..dirs.len()]);
                    for (k, &i) in idx.iter().enumerate() {
                        dist[i] = hits[k].map_or(f64::INFINITY, |h| h.distance);
                    }
                }
            }
        }
        dist
    };
    let (dist, secs, secs_single) = common::time_packets_and_single(&|| single(&rays), &|| packets(&rays));
    let n = rays.len();
    let hits = dist.iter().filter(|d| d.is_finite()).count();
    println!("camera depth rays  {n} ({poses} frames of 1280x720), hits {:.1} %", 100.0 * hits as f64 / n as f64);
    println!(
        "rays/s             {:.3e} in 8x8 packets, {:.3e} as single rays (single thread, best of 3; identical hits)",
        n as f64 / secs,
        n as f64 / secs_single
    );
    if let Some(dir) = common::arg("--out") {
        let dir = std::path::PathBuf::from(dir);
        std::fs::create_dir_all(&dir).expect("out dir");
        agrisim_gltf::write_glb(&gh.objects, &dir.join("scene.glb")).expect("glb");
        let rb: Vec<u8> = rays.iter().flat_map(|r| r.iter().flat_map(|v| v.to_le_bytes())).collect();
        common::write_npy(&dir.join("rays.npy"), "<f4", &[n, 6], &rb).expect("npy");
        let db: Vec<u8> = dist.iter().flat_map(|v| v.to_le_bytes()).collect();
        common::write_npy(&dir.join("dist.npy"), "<f8", &[n], &db).expect("npy");
        std::fs::write(
            dir.join("rust.json"),
            format!("{{\"rays\": {n}, \"seconds\": {secs}, \"rays_per_s\": {}, \"single_ray_rays_per_s\": {}, \"objects\": {}, \"min_range\": 0.0, \"max_range\": {FAR}}}\n", n as f64 / secs, n as f64 / secs_single, gh.objects.len()),
        )
        .expect("json");
        println!("wrote              {}/{{scene.glb,rays.npy,dist.npy,rust.json}}", dir.display());
    }
}
