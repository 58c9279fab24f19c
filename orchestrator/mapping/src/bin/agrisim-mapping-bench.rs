//! The map update per depth frame, timed, for `python/bench_mapping.py` (which runs OctoMap on
//! the same points and compares). Input: a file of depth frames (below); outputs: timings as
//! JSON on stdout, the points each frame gave (map frame, single precision, for OctoMap) and
//! the final map's known voxels.
//!
//! Frames file (little endian): u32 frame count; per frame u32 width, u32 height, f64 fx, fy,
//! cx, cy, f64[12] the optical frame's pose in the map (3x4 row-major), then width x height
//! u16 depth in mm (0: no return).
//! Clouds file: per frame f32[3] origin, u32 n, n x f32[3].
//! Map file: u64 n, n x (i32 x, i32 y, i32 z, f32 log-odds), sorted by key.

use agrisim_mapping::{Intrinsics, MapConfig, OccupancyMap};
use agrisim_msgs::sensor_msgs::Image;
use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion};
use std::io::Write;
use std::time::Instant;

struct Frame {
    image: Image,
    k: Intrinsics,
    pose: Isometry3<f64>,
}

fn usage() -> ! {
    eprintln!(
        "usage: agrisim-mapping-bench --frames FILE [--resolution M] [--max-range M] [--repeat N] [--clouds FILE] [--map FILE]"
    );
    std::process::exit(2)
}

struct Cursor<'a>(&'a [u8], usize, &'a str);

impl Cursor<'_> {
    fn take(&mut self, n: usize) -> Result<&[u8], String> {
        let s = self.0.get(self.1..self.1 + n).ok_or_else(|| format!("{}: truncated at byte {}", self.2, self.1))?;
        self.1 += n;
        Ok(s)
    }
    fn u32(&mut self) -> Result<u32, String> {
        Ok(u32::from_le_bytes(self.take(4)?.try_into().expect("4")))
    }
    fn f64(&mut self) -> Result<f64, String> {
        Ok(f64::from_le_bytes(self.take(8)?.try_into().expect("8")))
    }
}

fn read_frames(path: &str) -> Result<Vec<Frame>, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{path}: {e}"))?;
    let mut c = Cursor(&bytes, 0, path);
    let n = c.u32()?;
    let mut out = Vec::new();
    for i in 0..n {
        let (w, h) = (c.u32()?, c.u32()?);
        let kk = [c.f64()?, c.f64()?, c.f64()?, c.f64()?];
        let k = Intrinsics::from_k(&[kk[0], 0.0, kk[2], 0.0, kk[1], kk[3], 0.0, 0.0, 1.0])
            .ok_or_else(|| format!("{path}: frame {i} has unusable intrinsics {kk:?}"))?;
        let mut m = [0.0; 12];
        for v in &mut m {
            *v = c.f64()?;
        }
        let r = Matrix3::new(m[0], m[1], m[2], m[4], m[5], m[6], m[8], m[9], m[10]);
        let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix(&r));
        let pose = Isometry3::from_parts(Translation3::new(m[3], m[7], m[11]), q);
        let data = c.take(w as usize * h as usize * 2)?.to_vec();
        let image = Image { width: w, height: h, encoding: "16UC1".into(), step: w * 2, data, ..Default::default() };
        out.push(Frame { image, k, pose });
    }
    Ok(out)
}

fn run() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (mut frames, mut clouds, mut map_out, mut repeat) = (None, None, None, 1usize);
    let mut config = MapConfig::default();
    let mut i = 0;
    while i < args.len() {
        let v = args.get(i + 1).cloned().unwrap_or_else(|| usage());
        let num = |s: &str| s.parse::<f64>().map_err(|e| format!("{}: {s:?}: {e}", args[i]));
        match args[i].as_str() {
            "--frames" => frames = Some(v),
            "--clouds" => clouds = Some(v),
            "--map" => map_out = Some(v),
            "--resolution" => config.resolution = num(&v)?,
            "--max-range" => config.max_range = num(&v)?,
            "--repeat" => repeat = num(&v)?.max(1.0) as usize,
            _ => usage(),
        }
        i += 2;
    }
    let path = frames.unwrap_or_else(|| usage());
    let input = read_frames(&path)?;
    // Best of `repeat` runs of the whole sequence on a fresh map, per frame.
    let mut best = vec![f64::INFINITY; input.len()];
    let mut map = OccupancyMap::new(config.clone())?;
    let mut points = 0;
    for _ in 0..repeat {
        map = OccupancyMap::new(config.clone())?;
        points = 0;
        for (f, b) in input.iter().zip(&mut best) {
            let t = Instant::now();
            let depth = agrisim_mapping::DepthFrame::from_image(&f.image)?;
            let s = map.insert_depth(&depth, &f.k, &f.pose, &[]);
            *b = b.min(t.elapsed().as_secs_f64() * 1e3);
            points += s.points;
        }
    }
    if let Some(p) = clouds {
        let mut out = Vec::new();
        for f in &input {
            let depth = agrisim_mapping::DepthFrame::from_image(&f.image)?;
            let (o, pts) = depth.points(&f.k, &f.pose);
            o.iter().for_each(|v| out.extend(v.to_le_bytes()));
            out.extend((pts.len() as u32).to_le_bytes());
            pts.iter().flatten().for_each(|v| out.extend(v.to_le_bytes()));
        }
        std::fs::write(&p, out).map_err(|e| format!("{p}: {e}"))?;
    }
    let known = map.known();
    if let Some(p) = map_out {
        let mut out = (known.len() as u64).to_le_bytes().to_vec();
        for (k, l) in &known {
            k.iter().for_each(|v| out.extend(v.to_le_bytes()));
            out.extend(l.to_le_bytes());
        }
        std::fs::write(&p, out).map_err(|e| format!("{p}: {e}"))?;
    }
    let ms: Vec<String> = best.iter().map(|v| format!("{v:.3}")).collect();
    let total: f64 = best.iter().sum();
    let mut stdout = std::io::stdout();
    writeln!(
        stdout,
        "{{\"frames\": {}, \"points\": {points}, \"resolution\": {}, \"max_range\": {}, \"repeat\": {repeat}, \"ms_per_frame\": [{}], \"mean_ms\": {:.3}, \"known\": {}, \"occupied\": {}}}",
        input.len(),
        config.resolution,
        config.max_range,
        ms.join(", "),
        total / input.len().max(1) as f64,
        known.len(),
        map.occupied().len()
    )
    .map_err(|e| e.to_string())
}

fn main() {
    if let Err(e) = run() {
        eprintln!("agrisim-mapping-bench: {e}");
        std::process::exit(1);
    }
}
