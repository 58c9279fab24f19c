//! Ray casting throughput on the LiDAR's own rays: the MID-360 pattern (20,000 points per
//! 0.1 s frame) from 8 spots along the aisles at the sensor's height, cast as the FMU casts
//! them (runs of `LIDAR_PACKET` consecutive points as packets) and as single rays, single thread.
//!
//! cargo run --release -p agrisim-fmu-lidar --example pattern_rays -- [--frames N] [--out DIR]
//!
//! With `--out DIR` it writes DIR/scene.glb, DIR/rays.npy, DIR/dist.npy and DIR/rust.json for
//! python/bench_raycast.py --lidar-pattern to cast the same rays with Open3D.

#[path = "../../lib/raycast/examples/common/mod.rs"]
mod common;

use agrisim_fmu_lidar::datasheet as ds;
use agrisim_fmu_lidar::lidar::LIDAR_PACKET;
use agrisim_fmu_lidar::pattern::ScanPattern;
use agrisim_raycast::RayCaster;
use agrisim_scene::{generate, GreenhouseConfig};

fn main() {
    let frames: usize = common::arg("--frames").map_or(12, |s| s.parse().expect("--frames N"));
    let cfg = GreenhouseConfig::default();
    let gh = generate(&cfg, cfg.seed);
    let rc = RayCaster::new(&gh.objects);
    let none = RayCaster::new(&[]);
    let p = ScanPattern::mid360(
        ds::POINT_RATE,
        ds::FOV_ELEVATION_MIN_DEG.to_radians(),
        ds::FOV_ELEVATION_MAX_DEG.to_radians(),
    );
    let per_frame = (ds::POINT_RATE / ds::FRAME_RATE) as i64;
    // Spots along the aisles, the sensor 0.5 m up (as the random-ray bench), one after another
    // with `frames` frames each.
    let spots: Vec<[f64; 3]> = (0..8)
        .map(|k| {
            let a = &gh.layout.aisles[k % gh.layout.aisles.len()];
            [a.x_start + (a.x_end - a.x_start) * (k as f64 + 0.5) / 8.0, a.y, 0.5]
        })
        .collect();
    let mut rays: Vec<[f64; 6]> = Vec::new();
    for (s, o) in spots.iter().enumerate() {
        for f in 0..frames {
            let n0 = (s * frames + f) as i64 * per_frame;
            for n in n0..n0 + per_frame {
                let d = p.direction(n);
                rays.push([o[0], o[1], o[2], d[0], d[1], d[2]]);
            }
        }
    }
    let (lo, hi) = (ds::RANGE_MIN, ds::RANGE_MAX);
    let single = || -> Vec<f64> {
        rays.iter()
            .map(|r| rc.cast([r[0], r[1], r[2]], [r[3], r[4], r[5]], lo, hi, &[]).map_or(f64::INFINITY, |h| h.distance))
            .collect()
    };
    let packets = || -> Vec<f64> {
        let mut dist = Vec::with_capacity(rays.len());
        // Buffers reused from packet to packet, as the FMU's `cast_run` keeps them (the
        // vectors this allocated per packet cost about 5 % of the timed work).
        let mut hits = [None; LIDAR_PACKET];
        let mut origins = [[0.0; 3]; LIDAR_PACKET];
        let mut dirs = [[0.0; 3]; LIDAR_PACKET];
        let poses = [agrisim_raycast::RigidPose::yawed(0.0, 0.0, 0.0, 0.0); LIDAR_PACKET];
        for chunk in rays.chunks(LIDAR_PACKET) {
            // Packets as the FMU casts them. A chunk may straddle two spots (a frame's 20,000
            // rays are not a multiple of the packet): it just gets a wider origin interval;
            // hits are exact either way.
            let k = chunk.len();
            for (i, r) in chunk.iter().enumerate() {
                (origins[i], dirs[i]) = ([r[0], r[1], r[2]], [r[3], r[4], r[5]]);
            }
            rc.cast_packet_posed(&origins[..k], &dirs[..k], lo, hi, &none, &none, &poses[..k], &mut hits[..k]);
            dist.extend(hits[..k].iter().map(|h| h.map_or(f64::INFINITY, |h| h.distance)));
        }
        dist
    };
    let (dist, secs, secs_single) = common::time_packets_and_single(&single, &packets);
    let n = rays.len();
    let hits = dist.iter().filter(|d| d.is_finite()).count();
    println!(
        "LiDAR pattern rays {n} ({frames} frames x {} spots), hits {:.1} %",
        spots.len(),
        100.0 * hits as f64 / n as f64
    );
    println!("rays/s             {:.3e} in packets of {LIDAR_PACKET}, {:.3e} as single rays (single thread, best of 3; identical hits)", n as f64 / secs, n as f64 / secs_single);
    if let Some(dir) = common::arg("--out") {
        let dir = std::path::PathBuf::from(dir);
        std::fs::create_dir_all(&dir).expect("out dir");
        agrisim_gltf::write_glb(&gh.objects, &dir.join("scene.glb")).expect("glb");
        let rb: Vec<u8> = rays.iter().flat_map(|r| r.iter().flat_map(|&v| (v as f32).to_le_bytes())).collect();
        common::write_npy(&dir.join("rays.npy"), "<f4", &[n, 6], &rb).expect("npy");
        let db: Vec<u8> = dist.iter().flat_map(|v| v.to_le_bytes()).collect();
        common::write_npy(&dir.join("dist.npy"), "<f8", &[n], &db).expect("npy");
        std::fs::write(
            dir.join("rust.json"),
            format!(
                "{{\"rays\": {n}, \"seconds\": {secs}, \"rays_per_s\": {}, \"single_ray_rays_per_s\": {}, \"objects\": {}, \"min_range\": {lo}, \"max_range\": {hi}}}\n",
                n as f64 / secs,
                n as f64 / secs_single,
                gh.objects.len()
            ),
        )
        .expect("json");
        println!("wrote              {}/{{scene.glb,rays.npy,dist.npy,rust.json}}", dir.display());
    }
}
