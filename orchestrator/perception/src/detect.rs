//! One frame: fruit-coloured pixels with depth, grouped into depth-connected components,
//! each fitted with a sphere and classified by its hue votes.

use crate::colour::{classify, stage_votes, FruitColour, Linearize};
use crate::sphere::{fit_sphere, SphereBounds};

/// Pinhole intrinsics (CameraInfo's K).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Intrinsics {
    pub fx: f64,
    pub fy: f64,
    pub cx: f64,
    pub cy: f64,
}

impl Intrinsics {
    /// From a row-major K; `None` unless the focal lengths are positive and finite.
    pub fn from_k(k: &[f64; 9]) -> Option<Intrinsics> {
        let i = Intrinsics { fx: k[0], fy: k[4], cx: k[2], cy: k[5] };
        (i.fx > 0.0 && i.fy > 0.0 && i.fx.is_finite() && i.fy.is_finite() && i.cx.is_finite() && i.cy.is_finite())
            .then_some(i)
    }
    /// The point at pixel (u, v) (centre of the pixel) with depth z.
    pub fn unproject(&self, u: usize, v: usize, z: f64) -> [f64; 3] {
        [(u as f64 + 0.5 - self.cx) / self.fx * z, (v as f64 + 0.5 - self.cy) / self.fy * z, z]
    }
    pub fn project(&self, p: [f64; 3]) -> [f64; 2] {
        [self.fx * p[0] / p[2] + self.cx, self.fy * p[1] / p[2] + self.cy]
    }
}

/// A colour frame with its aligned depth (z in metres, 0 or non-finite = none).
pub struct Frame<'a> {
    pub width: usize,
    pub height: usize,
    /// rgb8, `width * height * 3` bytes, rows without padding.
    pub rgb: &'a [u8],
    pub depth: &'a [f32],
    pub k: Intrinsics,
}

#[derive(Clone, Debug, PartialEq)]
pub struct DetectorConfig {
    pub colour: FruitColour,
    pub sphere: SphereBounds,
    /// Least pixels of a segment.
    pub min_pixels: usize,
    /// Depth range considered [m].
    pub min_depth: f64,
    pub max_depth: f64,
    /// Neighbours join when their depths differ by less than this fraction of the depth
    /// (and at least `join_abs`).
    pub join_rel: f64,
    pub join_abs: f64,
    /// Largest RMS distance of a fit's inliers to its surface [m].
    pub max_rms: f64,
    /// Least share of a segment's points the fit keeps.
    pub min_inliers: f64,
}

impl Default for DetectorConfig {
    fn default() -> Self {
        DetectorConfig {
            colour: FruitColour::default(),
            sphere: SphereBounds::default(),
            min_pixels: 30,
            min_depth: 0.15,
            max_depth: 1.6,
            join_rel: 0.02,
            join_abs: 0.008,
            max_rms: 0.006,
            min_inliers: 0.6,
        }
    }
}

/// One fruit found in a frame, in the camera's optical frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Detection {
    pub center: [f64; 3],
    pub radius: f64,
    /// USDA stage 1..=6 with the most votes, and its share.
    pub stage: u8,
    pub score: f64,
    pub votes: [f64; 6],
    pub rms: f64,
    pub pixels: usize,
    /// Image box (u_min, v_min, u_max, v_max) of the segment.
    pub bbox: [usize; 4],
}

/// Everything a frame gave, for the node's status and the benchmarks.
#[derive(Default, Debug)]
pub struct FrameResult {
    pub detections: Vec<Detection>,
    /// Pixels with valid depth in the frame.
    pub valid_depth: usize,
    /// Segments refused by the fit (too flat, too big, too few inliers).
    pub rejected: usize,
}

/// The detector with its tables, reused across frames.
pub struct Detector {
    pub config: DetectorConfig,
    lin: Linearize,
    mask: Vec<u8>,
    label: Vec<u32>,
    stack: Vec<usize>,
}

impl Detector {
    pub fn new(config: DetectorConfig) -> Detector {
        Detector { config, lin: Linearize::default(), mask: vec![], label: vec![], stack: vec![] }
    }

    /// Finds the fruit of one frame. Buffers of the wrong size give an empty result.
    pub fn detect(&mut self, f: &Frame) -> FrameResult {
        let n = f.width * f.height;
        let mut out = FrameResult::default();
        if f.rgb.len() < n * 3 || f.depth.len() < n || n == 0 {
            return out;
        }
        let c = self.config.clone();
        self.mask.clear();
        self.mask.resize(n, 0);
        for i in 0..n {
            let z = f.depth[i] as f64;
            if !(z.is_finite() && z > 0.0) {
                continue;
            }
            out.valid_depth += 1;
            if z < c.min_depth || z > c.max_depth {
                continue;
            }
            let px = [f.rgb[3 * i], f.rgb[3 * i + 1], f.rgb[3 * i + 2]];
            if c.colour.accepts(self.lin.lab(px)) {
                self.mask[i] = 1;
            }
        }
        self.label.clear();
        self.label.resize(n, 0);
        let mut next = 0u32;
        for seed in 0..n {
            if self.mask[seed] == 0 || self.label[seed] != 0 {
                continue;
            }
            next += 1;
            let members = self.flood(f, seed, next);
            if members.len() < c.min_pixels {
                continue;
            }
            self.fit_segment(f, &members, &mut out, 0);
        }
        out
    }

    /// The depth-connected component of `seed` among masked pixels, labelled `id`.
    fn flood(&mut self, f: &Frame, seed: usize, id: u32) -> Vec<usize> {
        let (w, h) = (f.width, f.height);
        let mut members = vec![];
        self.stack.clear();
        self.stack.push(seed);
        self.label[seed] = id;
        while let Some(i) = self.stack.pop() {
            members.push(i);
            let (u, v) = (i % w, i / w);
            let z = f.depth[i] as f64;
            let tol = (self.config.join_rel * z).max(self.config.join_abs);
            let visit = |j: usize, label: &mut [u32], stack: &mut Vec<usize>| {
                if self.mask[j] != 0 && label[j] == 0 && (f.depth[j] as f64 - z).abs() <= tol {
                    label[j] = id;
                    stack.push(j);
                }
            };
            if u > 0 {
                visit(i - 1, &mut self.label, &mut self.stack);
            }
            if u + 1 < w {
                visit(i + 1, &mut self.label, &mut self.stack);
            }
            if v > 0 {
                visit(i - w, &mut self.label, &mut self.stack);
            }
            if v + 1 < h {
                visit(i + w, &mut self.label, &mut self.stack);
            }
        }
        members
    }

    /// Fits one segment; a segment too big for one fruit is split in two (twice at most).
    fn fit_segment(&self, f: &Frame, members: &[usize], out: &mut FrameResult, depth: u32) {
        let c = &self.config;
        let pts: Vec<[f64; 3]> =
            members.iter().map(|&i| f.k.unproject(i % f.width, i / f.width, f.depth[i] as f64)).collect();
        let Some(s) = fit_sphere(&pts, &c.sphere) else {
            out.rejected += 1;
            return;
        };
        let good = s.rms <= c.max_rms && s.inlier_fraction >= c.min_inliers && !s.at_bound;
        if !good {
            if depth < 2 && members.len() >= 2 * c.min_pixels {
                let (a, b) = split_two(members, &pts);
                if a.len() >= c.min_pixels / 2 && b.len() >= c.min_pixels / 2 {
                    self.fit_segment(f, &a, out, depth + 1);
                    self.fit_segment(f, &b, out, depth + 1);
                    return;
                }
            }
            out.rejected += 1;
            return;
        }
        let votes = stage_votes(members.iter().map(|&i| [f.rgb[3 * i], f.rgb[3 * i + 1], f.rgb[3 * i + 2]]));
        let (stage, share) = classify(&votes);
        // Score: the vote share, lowered by a poor fit.
        let score = share * (1.0 - 0.5 * (s.rms / c.max_rms)).clamp(0.0, 1.0);
        let mut bbox = [usize::MAX, usize::MAX, 0, 0];
        for &i in members {
            let (u, v) = (i % f.width, i / f.width);
            bbox = [bbox[0].min(u), bbox[1].min(v), bbox[2].max(u), bbox[3].max(v)];
        }
        out.detections.push(Detection {
            center: s.center,
            radius: s.radius,
            stage,
            score,
            votes,
            rms: s.rms,
            pixels: members.len(),
            bbox,
        });
    }
}

/// Two-means of a segment's points (seeded by its two most distant points along the main
/// lateral direction), as pixel index lists.
fn split_two(members: &[usize], pts: &[[f64; 3]]) -> (Vec<usize>, Vec<usize>) {
    let n = pts.len() as f64;
    let mean = pts.iter().fold([0.0; 3], |a, p| [a[0] + p[0] / n, a[1] + p[1] / n, a[2] + p[2] / n]);
    let far = |from: [f64; 3]| pts.iter().copied().max_by(|a, b| d2(*a, from).total_cmp(&d2(*b, from))).unwrap_or(from);
    let mut ca = far(mean);
    let mut cb = far(ca);
    let mut assign = vec![false; pts.len()];
    for _ in 0..10 {
        for (k, p) in pts.iter().enumerate() {
            assign[k] = d2(*p, cb) < d2(*p, ca);
        }
        let centroid = |side: bool| {
            let sel: Vec<&[f64; 3]> = pts.iter().zip(&assign).filter(|(_, a)| **a == side).map(|(p, _)| p).collect();
            let m = sel.len().max(1) as f64;
            sel.iter().fold([0.0; 3], |a, p| [a[0] + p[0] / m, a[1] + p[1] / m, a[2] + p[2] / m])
        };
        ca = centroid(false);
        cb = centroid(true);
    }
    let mut a = vec![];
    let mut b = vec![];
    for (i, side) in members.iter().zip(&assign) {
        if *side {
            b.push(*i)
        } else {
            a.push(*i)
        }
    }
    (a, b)
}

fn d2(a: [f64; 3], b: [f64; 3]) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A synthetic frame: a grey wall at 1.2 m, green leaves, and two tomatoes (a red one and
    /// a turning one) rendered by ray casting: both found, with their stage and centre.
    #[test]
    fn finds_two_rendered_tomatoes() {
        let (w, h) = (160usize, 120usize);
        let k = Intrinsics { fx: 120.0, fy: 120.0, cx: 80.0, cy: 60.0 };
        let fruit = [([-0.12, 0.0, 0.7], 0.03, [190u8, 26, 20]), ([0.1, 0.05, 0.6], 0.035, [205, 150, 66])];
        let mut rgb = vec![0u8; w * h * 3];
        let mut depth = vec![0f32; w * h];
        for v in 0..h {
            for u in 0..w {
                let d = [(u as f64 + 0.5 - k.cx) / k.fx, (v as f64 + 0.5 - k.cy) / k.fy, 1.0];
                let mut best = (1.2, if u < 30 { [58u8, 112, 38] } else { [150, 145, 135] });
                for (c, r, col) in fruit {
                    let dd = d[0] * d[0] + d[1] * d[1] + 1.0;
                    let b = d[0] * c[0] + d[1] * c[1] + c[2];
                    let disc = b * b - dd * (c[0] * c[0] + c[1] * c[1] + c[2] * c[2] - r * r);
                    if disc >= 0.0 {
                        let t = (b - disc.sqrt()) / dd;
                        if t < best.0 {
                            best = (t, col);
                        }
                    }
                }
                let i = v * w + u;
                depth[i] = best.0 as f32;
                rgb[3 * i..3 * i + 3].copy_from_slice(&best.1);
            }
        }
        let mut det = Detector::new(DetectorConfig::default());
        let r = det.detect(&Frame { width: w, height: h, rgb: &rgb, depth: &depth, k });
        assert_eq!(r.detections.len(), 2, "{:?}", r.detections);
        assert_eq!(r.valid_depth, w * h);
        for (c, rad, col) in fruit {
            let d = r.detections.iter().min_by(|a, b| d2(a.center, c).total_cmp(&d2(b.center, c))).unwrap();
            assert!(d2(d.center, c).sqrt() < 0.004, "{d:?} vs {c:?}");
            assert!((d.radius - rad).abs() < 0.004, "{d:?}");
            let want = if col[1] < 50 { 6 } else { 3 };
            assert_eq!(d.stage, want);
        }
        // No depth: nothing found, and the frame says so.
        let none = vec![0f32; w * h];
        let r = det.detect(&Frame { width: w, height: h, rgb: &rgb, depth: &none, k });
        assert!(r.detections.is_empty() && r.valid_depth == 0);
    }
}
