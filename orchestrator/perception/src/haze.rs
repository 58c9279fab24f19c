//! Fog and haze, estimated from the frame itself and cleared before detection.
//!
//! Koschmieder's law: a surface of linear radiance J seen through fog at range r shows
//! I = J t + A (1 - t), with transmission t = exp(-beta r) and A the airlight (the fog's own
//! radiance). Fog lifts every colour toward A's grey, so ripe fruit a metre away lose the
//! chroma the colour test needs (the perception benchmark in fog of 15 m visibility found
//! 42 % of the free ripe fruit). The frame tells both unknowns:
//! - A: the mean colour of the 0.1 % of pixels whose dark channel (least of R, G, B) is
//!   highest (He, Sun and Tang 2009, "Single image haze removal using the dark channel
//!   prior", CVPR): in fog, the far field where t is nearly 0.
//! - beta: most surfaces of a crop have a dark channel near 0 (leaves: red and blue; red
//!   fruit: green and blue; shadows: all), so min_c I_c / A_c is at least 1 - t(r), and equal
//!   for them. With the depth camera's range, each pixel bounds beta from above by
//!   -ln(1 - min_c I_c / A_c) / r, and a low quantile of the bounds is the estimate (single
//!   image dehazing must guess r; here it is measured).
//!
//! A surface brighter than the fog in view (a sunlit white sheet) would be taken for the
//! airlight, as in He et al.'s method; the greenhouse's fog fills the far field.
//!
//! Then J = A + (I - A) / t per pixel with depth. Below [`MIN_BETA`] (visibility beyond
//! 78 m: clear air, dusk and overcast measured 0.000-0.005 per metre; fog of 15 m
//! visibility 0.261 against a true 0.261) the frame is left as it is.

use crate::colour::Linearize;
use crate::frame::{Frame, Intrinsics};

/// Least extinction coefficient cleared [1/m] (Koschmieder: visibility 3.912 / beta = 78 m).
pub const MIN_BETA: f64 = 0.05;
/// Samples are taken on every `SAMPLE_STRIDE`-th row and column (1/16 of a frame's pixels:
/// 25 000 of an 848x480 frame, 250 in the quantile).
pub const SAMPLE_STRIDE: usize = 4;
/// Share of the samples whose dark channel sets the airlight (He et al.'s 0.1 %).
const AIRLIGHT_SHARE: f64 = 0.001;
/// Quantile of the per-pixel bounds taken for beta.
const BETA_QUANTILE: f64 = 0.01;
/// Ranges used for beta [m]: nearer, a bound divides noise by a small range; farther, the
/// depth camera's own error grows.
const BETA_RANGE: (f64, f64) = (0.5, 5.0);
/// Least transmission divided by (He et al. keep 0.1 of the haze; the detector reads to
/// 1.6 m, t = 0.66 at 15 m visibility).
const MIN_T: f64 = 0.2;

/// The fog of a frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Haze {
    /// Linear RGB of the airlight.
    pub airlight: [f64; 3],
    /// Extinction coefficient [1/m].
    pub beta: f64,
}

/// The work of estimating and clearing one frame (pixels), for the cost model.
#[derive(Default, Debug, Clone, Copy, PartialEq, Eq)]
pub struct HazeWork {
    pub samples: u64,
    pub cleared: u64,
}

/// sRGB <-> linear by table (the linear side in 4096 steps).
pub struct Srgb {
    lin: Linearize,
    encode: Vec<u8>,
}

const ENCODE_STEPS: usize = 4096;

impl Default for Srgb {
    fn default() -> Self {
        let encode = (0..ENCODE_STEPS)
            .map(|i| {
                let v = i as f64 / (ENCODE_STEPS - 1) as f64;
                let s = if v <= 0.003_130_8 { 12.92 * v } else { 1.055 * v.powf(1.0 / 2.4) - 0.055 };
                (s * 255.0).round().clamp(0.0, 255.0) as u8
            })
            .collect();
        Srgb { lin: Linearize::default(), encode }
    }
}

impl Srgb {
    fn linear(&self, c: u8) -> f64 {
        self.lin.channel(c) as f64
    }

    fn encode(&self, v: f64) -> u8 {
        self.encode[(v.clamp(0.0, 1.0) * (ENCODE_STEPS - 1) as f64).round() as usize]
    }
}

/// Range along the ray over depth (z), per pixel: sqrt(1 + x^2 + y^2) of its normalized
/// image coordinates.
fn ray_scale(k: &Intrinsics, u: usize, v: usize) -> f64 {
    let x = (u as f64 + 0.5 - k.cx) / k.fx;
    let y = (v as f64 + 0.5 - k.cy) / k.fy;
    (1.0 + x * x + y * y).sqrt()
}

/// The fog of a frame; None in clear air (or a frame too small to tell).
pub fn estimate(t: &Srgb, f: &Frame, work: &mut HazeWork) -> Option<Haze> {
    let (width, height, rgb, depth, k) = (f.width, f.height, f.rgb, f.depth, &f.k);
    let n = width * height;
    if rgb.len() < 3 * n || depth.len() < n {
        return None;
    }
    let samples: Vec<usize> = (0..height)
        .step_by(SAMPLE_STRIDE)
        .flat_map(|v| (0..width).step_by(SAMPLE_STRIDE).map(move |u| v * width + u))
        .collect();
    work.samples += samples.len() as u64;
    // The airlight: the brightest dark channels (the least sRGB byte orders as the least
    // linear channel).
    let dark = |i: usize| rgb[3 * i].min(rgb[3 * i + 1]).min(rgb[3 * i + 2]);
    let mut histogram = [0usize; 256];
    for &i in &samples {
        histogram[dark(i) as usize] += 1;
    }
    let want = ((samples.len() as f64 * AIRLIGHT_SHARE).ceil() as usize).max(1);
    let (mut floor, mut above) = (255usize, 0usize);
    while above + histogram[floor] < want && floor > 0 {
        above += histogram[floor];
        floor -= 1;
    }
    let mut sum = [0.0f64; 3];
    let mut count = 0usize;
    for &i in samples.iter().filter(|&&i| dark(i) as usize >= floor) {
        for (c, s) in sum.iter_mut().enumerate() {
            *s += t.linear(rgb[3 * i + c]);
        }
        count += 1;
    }
    let airlight = sum.map(|s| s / count.max(1) as f64);
    if airlight.iter().any(|&a| !(a > 1e-3)) {
        return None;
    }
    // Beta: a low quantile of each pixel's upper bound.
    let mut bounds: Vec<f64> = samples
        .iter()
        .filter_map(|&i| {
            let z = depth[i] as f64;
            if !(z.is_finite() && z > 0.0) {
                return None;
            }
            let r = z * ray_scale(k, i % width, i / width);
            if !(BETA_RANGE.0..=BETA_RANGE.1).contains(&r) {
                return None;
            }
            let d = (0..3).map(|c| t.linear(rgb[3 * i + c]) / airlight[c]).fold(f64::INFINITY, f64::min);
            (d < 1.0).then(|| -(1.0 - d).ln() / r)
        })
        .collect();
    if bounds.len() < 100 {
        return None;
    }
    let q = ((bounds.len() as f64 * BETA_QUANTILE) as usize).min(bounds.len() - 1);
    let (_, &mut beta, _) = bounds.select_nth_unstable_by(q, f64::total_cmp);
    (beta >= MIN_BETA).then_some(Haze { airlight, beta })
}

impl Haze {
    /// The frame's colours cleared of the fog: J = A + (I - A) / t for pixels with depth
    /// whose z lies in `z_range`; the others as they were.
    pub fn clear(&self, t: &Srgb, f: &Frame, z_range: (f64, f64), work: &mut HazeWork) -> Vec<u8> {
        let (width, rgb, depth, k) = (f.width, f.rgb, f.depth, &f.k);
        let mut out = rgb.to_vec();
        for (i, &z) in depth.iter().enumerate().take(rgb.len() / 3) {
            let z = z as f64;
            if !(z.is_finite() && z >= z_range.0 && z <= z_range.1) {
                continue;
            }
            work.cleared += 1;
            let r = z * ray_scale(k, i % width, i / width);
            let tr = (-self.beta * r).exp().max(MIN_T);
            for c in 0..3 {
                let a = self.airlight[c];
                out[3 * i + c] = t.encode(a + (t.linear(rgb[3 * i + c]) - a) / tr);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A synthetic frame through Koschmieder fog: a row of surfaces at known ranges, some
    /// dark, some red, the far field without depth at the airlight.
    struct Foggy {
        rgb: Vec<u8>,
        depth: Vec<f32>,
        truth: Vec<[f64; 3]>,
        k: Intrinsics,
        w: usize,
        h: usize,
    }

    impl Foggy {
        fn new(beta: f64, airlight: f64) -> Foggy {
            let t = Srgb::default();
            let (w, h) = (160, 120);
            let k = Intrinsics { fx: 100.0, fy: 100.0, cx: 80.0, cy: 60.0 };
            let (mut rgb, mut depth, mut truth) = (vec![0u8; w * h * 3], vec![0f32; w * h], vec![[0.0; 3]; w * h]);
            for v in 0..h {
                for u in 0..w {
                    let i = v * w + u;
                    // Columns 0-119: surfaces at 0.6-2.4 m; the rest: the far field.
                    let j = if u < 120 {
                        let z = 0.6 + 0.015 * u as f64;
                        depth[i] = z as f32;
                        // Leaves (dark in red and blue), shadows, red fruit, grey structure.
                        match (u / 4 + v / 8) % 4 {
                            0 => [0.02, 0.12, 0.01],
                            1 => [0.001, 0.0015, 0.0008],
                            2 => [0.35, 0.03, 0.02],
                            _ => [0.1, 0.1, 0.1],
                        }
                    } else {
                        [airlight; 3]
                    };
                    let tr = if u < 120 { (-beta * depth[i] as f64 * ray_scale(&k, u, v)).exp() } else { 0.0 };
                    truth[i] = j;
                    for c in 0..3 {
                        rgb[3 * i + c] = t.encode(j[c] * tr + airlight * (1.0 - tr));
                    }
                }
            }
            Foggy { rgb, depth, truth, k, w, h }
        }

        fn frame(&self) -> Frame<'_> {
            Frame { width: self.w, height: self.h, rgb: &self.rgb, depth: &self.depth, k: self.k, up: None }
        }
    }

    #[test]
    fn fog_is_estimated_from_the_frame_and_cleared() {
        let t = Srgb::default();
        for (beta, a) in [(3.912 / 15.0, 0.27), (3.912 / 40.0, 0.3), (3.912 / 8.0, 0.4)] {
            let fog = Foggy::new(beta, a);
            let mut work = HazeWork::default();
            let haze = estimate(&t, &fog.frame(), &mut work).expect("fog found");
            assert!((haze.beta - beta).abs() < 0.05 * beta, "beta {} vs {beta}", haze.beta);
            assert!(haze.airlight.iter().all(|&v| (v - a).abs() < 0.01 * a), "{:?} vs {a}", haze.airlight);
            assert_eq!(work.samples, (fog.w / SAMPLE_STRIDE * fog.h / SAMPLE_STRIDE) as u64);
            let clear = haze.clear(&t, &fog.frame(), (0.15, 1.6), &mut work);
            // The red fruit within the detector's range come back to their colour (to the
            // 8-bit steps the fog left, divided by t).
            let red = |(i, j): &(usize, &[f64; 3])| j[0] == 0.35 && fog.depth[*i] <= 1.6;
            for (i, j) in fog.truth.iter().enumerate().filter(red) {
                let got: Vec<f64> = (0..3).map(|c| t.linear(clear[3 * i + c])).collect();
                assert!((got[0] - j[0]).abs() < 0.02 && got[1] < 0.05, "pixel {i}: {got:?} vs {j:?}");
            }
            // Beyond the range and without depth: untouched.
            for far in [119 + 60 * fog.w, 150 + 60 * fog.w] {
                assert_eq!(clear[3 * far..3 * far + 3], fog.rgb[3 * far..3 * far + 3]);
            }
        }
    }

    #[test]
    fn clear_air_is_left_alone() {
        let t = Srgb::default();
        let mut work = HazeWork::default();
        // No fog (t = 1 everywhere, a bright far field), and haze below the threshold
        // (visibility 200 m).
        for (beta, a) in [(0.0, 0.8), (3.912 / 200.0, 0.3)] {
            let fog = Foggy::new(beta, a);
            assert_eq!(estimate(&t, &fog.frame(), &mut work), None);
            // A frame without depth, or too small, tells nothing.
            let none = vec![0.0; fog.w * fog.h];
            assert_eq!(estimate(&t, &Frame { depth: &none, ..fog.frame() }, &mut work), None);
            assert_eq!(estimate(&t, &Frame { rgb: &fog.rgb[..10], ..fog.frame() }, &mut work), None);
        }
    }
}
