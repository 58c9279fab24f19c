//! Ray casting throughput on a greenhouse from LiDAR-like origins, single thread.
//!
//! cargo run --release -p agrisim-raycast --example raycast_bench -- [--rays N] [--config FILE] [--out DIR]
//!
//! With `--out DIR` it also writes DIR/scene.glb, DIR/rays.npy (N x 6 float32: origin,
//! direction) and DIR/dist.npy (N float64, inf = no hit within 0.1..40 m) for
//! python/bench_raycast.py to cast the same rays with Open3D.

#[path = "common/mod.rs"]
mod common;

use agrisim_raycast::RayCaster;
use agrisim_scene::{generate, GreenhouseConfig};
use std::time::Instant;

const MIN_RANGE: f64 = 0.1;
const MAX_RANGE: f64 = 40.0;

fn main() {
    let n: usize = common::arg("--rays").map_or(2_000_000, |s| s.parse().expect("--rays N"));
    let cfg = match common::arg("--config") {
        Some(p) => GreenhouseConfig::from_toml_str(&std::fs::read_to_string(&p).expect("read --config"))
            .unwrap_or_else(|e| panic!("{e}")),
        None => GreenhouseConfig::default(),
    };
    let t = Instant::now();
    let gh = generate(&cfg, cfg.seed);
    let gen_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let rc = RayCaster::new(&gh.objects);
    let build_s = t.elapsed().as_secs_f64();
    let rays = common::lidar_rays(&gh.layout, n, 1);

    // Warm-up, then the timed pass.
    for r in rays.iter().take(10_000) {
        std::hint::black_box(rc.cast(o(r), d(r), MIN_RANGE, MAX_RANGE, &[]));
    }
    // Best of three passes: the machine is shared, the minimum is the least disturbed.
    let mut dist = Vec::with_capacity(n);
    let mut cast_s = f64::INFINITY;
    for _ in 0..3 {
        dist.clear();
        let t = Instant::now();
        for r in &rays {
            dist.push(rc.cast(o(r), d(r), MIN_RANGE, MAX_RANGE, &[]).map_or(f64::INFINITY, |h| h.distance));
        }
        cast_s = cast_s.min(t.elapsed().as_secs_f64());
    }
    let hits = dist.iter().filter(|d| d.is_finite()).count();
    let (mut nodes, mut prims) = (0, 0);
    for r in rays.iter().take(100_000) {
        let (a, b) = rc.traversal_stats(o(r), d(r), MIN_RANGE, MAX_RANGE);
        nodes += a;
        prims += b;
    }
    let k = rays.len().clamp(1, 100_000) as f64;
    println!("objects            {}", gh.objects.len());
    println!("generate           {:.3} s", gen_s);
    println!("bvh build          {:.3} s ({} nodes)", build_s, rc.node_count());
    println!("rays               {n} (hits {:.1} %)", 100.0 * hits as f64 / n as f64);
    println!("cast               {:.3} s (best of 3)", cast_s);
    println!("per ray            {:.1} nodes, {:.1} primitive tests", nodes as f64 / k, prims as f64 / k);
    println!("rays/s             {:.3e} (single thread; LiDAR needs 2.0e5)", n as f64 / cast_s);
    let digest = dist.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, v| (h ^ v.to_bits()).wrapping_mul(0x0100_0000_01b3));
    println!("distance digest    {digest:016x} (FNV-1a of the hit distances: equal digests = identical answers)");

    if let Some(dir) = common::arg("--out") {
        let dir = std::path::PathBuf::from(dir);
        std::fs::create_dir_all(&dir).unwrap();
        agrisim_gltf::write_glb(&gh.objects, &dir.join("scene.glb")).unwrap();
        let rb: Vec<u8> = rays.iter().flat_map(|r| r.iter().flat_map(|v| v.to_le_bytes())).collect();
        common::write_npy(&dir.join("rays.npy"), "<f4", &[n, 6], &rb).unwrap();
        let db: Vec<u8> = dist.iter().flat_map(|v| v.to_le_bytes()).collect();
        common::write_npy(&dir.join("dist.npy"), "<f8", &[n], &db).unwrap();
        std::fs::write(
            dir.join("rust.json"),
            format!(
                "{{\"rays\": {n}, \"seconds\": {cast_s}, \"rays_per_s\": {}, \"objects\": {}, \"min_range\": {MIN_RANGE}, \"max_range\": {MAX_RANGE}}}\n",
                n as f64 / cast_s,
                gh.objects.len()
            ),
        )
        .unwrap();
        println!("wrote              {}/{{scene.glb,rays.npy,dist.npy,rust.json}}", dir.display());
    }
}

fn o(r: &[f32; 6]) -> [f64; 3] {
    [r[0] as f64, r[1] as f64, r[2] as f64]
}

fn d(r: &[f32; 6]) -> [f64; 3] {
    [r[3] as f64, r[4] as f64, r[5] as f64]
}
