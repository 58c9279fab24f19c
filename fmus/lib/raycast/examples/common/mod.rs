//! Shared by the examples: LiDAR-like ray sets, .npy output, peak memory.
#![allow(dead_code)]

use agrisim_math::Rng;
use agrisim_scene::Layout;
use std::io::Write;

/// `n` rays from LiDAR-like origins 0.5 m above the floor on aisle centre lines (8 spots
/// spread over the aisles), directions uniform over the Livox MID-360 field of view
/// (360 deg x -7..+52 deg), incoherent like its non-repetitive pattern. Rounded to f32 so a
/// float32 peer casts exactly the same rays: (origin, direction) per ray.
pub fn lidar_rays(layout: &Layout, n: usize, seed: u64) -> Vec<[f32; 6]> {
    let spots: Vec<[f64; 3]> = (0..8)
        .map(|k| {
            let (y, x0, x1) = match layout.aisles.get(k % layout.aisles.len().max(1)) {
                Some(a) => (a.y, a.x_start, a.x_end),
                None => (layout.start_pose[1], layout.start_pose[0], layout.start_pose[0]),
            };
            [x0 + (x1 - x0) * (k as f64 + 0.5) / 8.0, y, 0.5]
        })
        .collect();
    let mut rng = Rng::scene(seed);
    let (s0, s1) = ((-7f64).to_radians().sin(), 52f64.to_radians().sin());
    (0..n)
        .map(|i| {
            let o = spots[i * spots.len() / n.max(1)];
            let az = rng.range(0.0, std::f64::consts::TAU);
            let el = rng.range(s0, s1).asin();
            let d = [el.cos() * az.cos(), el.cos() * az.sin(), el.sin()];
            [o[0] as f32, o[1] as f32, o[2] as f32, d[0] as f32, d[1] as f32, d[2] as f32]
        })
        .collect()
}

/// Writes a little-endian .npy (NumPy format version 1.0) of `shape` with dtype `descr`.
pub fn write_npy(path: &std::path::Path, descr: &str, shape: &[usize], data: &[u8]) -> std::io::Result<()> {
    let dims: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
    let shape_s = if dims.len() == 1 { format!("({},)", dims[0]) } else { format!("({})", dims.join(", ")) };
    let mut header = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape_s}, }}");
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    f.write_all(b"\x93NUMPY\x01\x00")?;
    f.write_all(&(header.len() as u16).to_le_bytes())?;
    f.write_all(header.as_bytes())?;
    f.write_all(data)?;
    f.flush()
}

/// Peak resident set size so far [MiB] (Linux /proc/self/status VmHWM).
pub fn peak_rss_mib() -> f64 {
    rss_field("VmHWM:")
}

/// Current resident set size [MiB].
pub fn rss_mib() -> f64 {
    rss_field("VmRSS:")
}

fn rss_field(key: &str) -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines().find(|l| l.starts_with(key)).and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok())
        })
        .map_or(f64::NAN, |kib| kib / 1024.0)
}

/// `--key value` from the command line.
pub fn arg(key: &str) -> Option<String> {
    let args: Vec<String> = std::env::args().collect();
    args.iter().position(|a| a == key).and_then(|i| args.get(i + 1).cloned())
}

/// Times `single` and `packets` (best of three passes each: the machine is shared), checks
/// they give the same distances, and returns (distances, seconds per pass of packets, of
/// single rays).
pub fn time_packets_and_single(single: &dyn Fn() -> Vec<f64>, packets: &dyn Fn() -> Vec<f64>) -> (Vec<f64>, f64, f64) {
    let time = |f: &dyn Fn() -> Vec<f64>| {
        let mut out = (Vec::new(), f64::INFINITY);
        for _ in 0..3 {
            let t = std::time::Instant::now();
            let d = f();
            out = (d, out.1.min(t.elapsed().as_secs_f64()));
        }
        out
    };
    let (dist_single, secs_single) = time(single);
    let (dist, secs) = time(packets);
    assert!(dist.iter().zip(&dist_single).all(|(a, b)| a == b), "packets and single rays disagree");
    (dist, secs, secs_single)
}
