//! The paper's complete layout: 160 rows (the paper never ran it). Measures generation time,
//! object count, memory (peak RSS, Linux VmHWM), RayCaster build, occupancy map and ray rate.
//!
//! cargo run --release -p agrisim-raycast --example scale -- [--rows 160] [--glb FILE]

#[path = "common/mod.rs"]
mod common;

use agrisim_raycast::RayCaster;
use agrisim_scene::occupancy::OccupancyMap;
use agrisim_scene::{generate, GreenhouseConfig, Object};
use std::time::Instant;

fn main() {
    let rows: usize = common::arg("--rows").map_or(160, |s| s.parse().expect("--rows N"));
    let base_rss = common::rss_mib();
    let mut cfg = GreenhouseConfig { rows, ..GreenhouseConfig::default() };
    // 160 rows at a 2.6 m pitch (0.6 m rows + 2 m aisles) need 416 m across: the paper's
    // 70 x 55 m hall cannot hold them with 2 m aisles, so the hall widens to fit.
    cfg.width = cfg.width.max(rows as f64 * cfg.row_pitch() + 2.0);
    cfg.first_active_row = rows / 2 - 3;
    cfg.validate().unwrap();

    let t = Instant::now();
    let gh = generate(&cfg, cfg.seed);
    let gen_s = t.elapsed().as_secs_f64();
    let rss_gen = common::rss_mib();
    let names: usize = gh.objects.iter().map(|o| o.name.capacity()).sum();
    let obj_bytes = gh.objects.capacity() * std::mem::size_of::<Object>() + names;

    let t = Instant::now();
    let rc = RayCaster::new(&gh.objects);
    let build_s = t.elapsed().as_secs_f64();
    let rss_rc = common::rss_mib();

    let t = Instant::now();
    let map = OccupancyMap::from_objects(&gh.objects, 0.05, (0.02, 2.0), gh.layout.bounds);
    let map_s = t.elapsed().as_secs_f64();

    let rays = common::lidar_rays(&gh.layout, 500_000, 2);
    let t = Instant::now();
    let mut hits = 0usize;
    for r in &rays {
        let o = [r[0] as f64, r[1] as f64, r[2] as f64];
        let d = [r[3] as f64, r[4] as f64, r[5] as f64];
        hits += rc.cast(o, d, 0.1, 40.0, &[]).is_some() as usize;
    }
    let cast_s = t.elapsed().as_secs_f64();

    println!("rows               {rows} ({} active, hall {} x {} m)", cfg.active_rows, cfg.length, cfg.width);
    println!("objects            {}", gh.objects.len());
    println!("generate           {gen_s:.3} s");
    println!(
        "objects in memory  {:.1} MiB ({} B per object incl. name)",
        obj_bytes as f64 / 1048576.0,
        obj_bytes / gh.objects.len()
    );
    println!("RSS after generate {:.1} MiB (+{:.1})", rss_gen, rss_gen - base_rss);
    println!(
        "RayCaster build    {build_s:.3} s ({} nodes), RSS {:.1} MiB (+{:.1})",
        rc.node_count(),
        rss_rc,
        rss_rc - rss_gen
    );
    println!(
        "occupancy map      {map_s:.3} s ({} x {} cells at 5 cm, {} occupied)",
        map.width,
        map.height,
        map.occupied_count()
    );
    println!(
        "rays/s             {:.3e} (1 thread, {} rays, {:.1} % hit)",
        rays.len() as f64 / cast_s,
        rays.len(),
        100.0 * hits as f64 / rays.len() as f64
    );
    if let Some(p) = common::arg("--glb") {
        let t = Instant::now();
        agrisim_gltf::write_glb(&gh.objects, std::path::Path::new(&p)).unwrap();
        let size = std::fs::metadata(&p).map(|m| m.len()).unwrap_or(0);
        println!("glb                {:.3} s, {:.0} MiB", t.elapsed().as_secs_f64(), size as f64 / 1048576.0);
    }
    println!("peak RSS (VmHWM)   {:.1} MiB", common::peak_rss_mib());
}
