//! One frame: fruit-coloured pixels with depth, grouped into depth-connected components,
//! each fitted with a sphere in the space where the oblate fruit is round ([`crate::spheroid`]),
//! its ripeness from the coloured fraction of the skin on it.

use crate::colour::{classify, exposure_lightness, luma, FruitColour, Linearize, CHROMA_STEP};
use crate::haze::{self, Haze, HazeWork, Srgb};
use crate::ripeness::{ripeness, stage_shares, surface_below, Ripeness};
use crate::sphere::{fit_sphere, SphereBounds};
use crate::spheroid::Spheroid;
use std::cell::Cell;

pub use crate::frame::{Frame, Intrinsics};

#[derive(Clone, Debug, PartialEq)]
pub struct DetectorConfig {
    pub colour: FruitColour,
    /// Bounds of the fruit's equatorial radius.
    pub sphere: SphereBounds,
    /// The crop's fruit shape index (height / width; 1: spheres), see [`crate::spheroid`].
    pub shape_index: f64,
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

/// Round greenhouse cultivars are slightly flattened: a fruit shape index of 0.85-0.90 (the
/// range the simulated crop draws from, `fmus/camera/src/crop.rs`; not checked against a
/// published table of cultivars), its middle here. A user's own crop sets its own.
pub const SHAPE_INDEX: f64 = 0.875;

impl Default for DetectorConfig {
    fn default() -> Self {
        DetectorConfig {
            colour: FruitColour::default(),
            sphere: SphereBounds::default(),
            shape_index: SHAPE_INDEX,
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
    /// The equatorial radius (half the fruit's width; its height is `shape_index` times it).
    pub radius: f64,
    /// USDA stage 1..=6 most likely (0: unknown, too little skin seen), and its
    /// probability lowered by a poor fit.
    pub stage: u8,
    pub score: f64,
    /// Probability of each stage (index 0 = stage 1) from the coloured fraction of the skin
    /// ([`crate::ripeness`]); all 0 when unknown.
    pub votes: [f64; 6],
    /// The fronts fitted to the skin, if enough of it told its colour.
    pub ripeness: Option<Ripeness>,
    pub rms: f64,
    pub pixels: usize,
    /// Image box (u_min, v_min, u_max, v_max) of the segment.
    pub bbox: [usize; 4],
}

/// The work one frame took, counted (deterministic: the same frame to detectors with the
/// same history gives the same counts), so the node can charge its compute in simulated time
/// ([`crate::cost::CostModel`]) without reading a clock.
#[derive(Default, Debug, Clone, Copy, PartialEq, Eq)]
pub struct DetectWork {
    /// Pixels of the frame scanned (depth decoded, depth range and colour memo looked up).
    pub pixels: u64,
    /// Colours converted to CIELAB and tested (the memo's misses: many at a run's start).
    pub conversions: u64,
    /// Fruit-coloured pixels with depth, flooded into segments.
    pub candidates: u64,
    /// Points handed to sphere fits (first fits, joint fits of parts, refits after growing).
    pub fit_points: u64,
    /// Pixels tested against a fitted sphere's surface (growing and ripeness).
    pub surface_tests: u64,
    /// Pixels sampled to estimate fog ([`crate::haze`]), and pixels cleared of it.
    pub haze_samples: u64,
    pub cleared: u64,
}

impl std::ops::AddAssign for DetectWork {
    fn add_assign(&mut self, o: DetectWork) {
        self.pixels += o.pixels;
        self.conversions += o.conversions;
        self.candidates += o.candidates;
        self.fit_points += o.fit_points;
        self.surface_tests += o.surface_tests;
        self.haze_samples += o.haze_samples;
        self.cleared += o.cleared;
    }
}

/// Everything a frame gave, for the node's status and the benchmarks.
#[derive(Default, Debug)]
pub struct FrameResult {
    pub detections: Vec<Detection>,
    /// Pixels with valid depth in the frame.
    pub valid_depth: usize,
    /// Segments refused by the fit (too flat, too big, too few inliers).
    pub rejected: usize,
    /// The fog the frame was cleared of (None: clear air).
    pub haze: Option<Haze>,
    /// The work it took.
    pub work: DetectWork,
}

/// The detector with its tables, reused across frames.
pub struct Detector {
    pub config: DetectorConfig,
    lin: Linearize,
    srgb: Srgb,
    /// The colour test per sRGB colour, filled as colours appear: 0 not yet asked, 1 not
    /// tomato at any exposure, else 2 + its chroma in [`CHROMA_STEP`]s (capped at 253), so a
    /// frame's chroma floor ([`FruitColour::chroma_floor`]) compares exactly. A frame repeats
    /// most colours of the frames before it, so the CIELAB conversion (three cube roots) runs
    /// once per colour rather than once per pixel. Indexed in Morton order ([`colour_key`]).
    colour_memo: Vec<u8>,
    /// The colour test the memo answers for (`config` is public and may change).
    memo_for: Option<FruitColour>,
    mask: Vec<u8>,
    label: Vec<u32>,
    stack: Vec<usize>,
    /// Points fitted and surface pixels tested in the current frame (counted from `&self`).
    fit_points: Cell<u64>,
    surface_tests: Cell<u64>,
    /// The current frame's fruit shape (the world's up from its TF).
    shape: Spheroid,
}

impl Detector {
    pub fn new(config: DetectorConfig) -> Detector {
        Detector {
            config,
            lin: Linearize::default(),
            srgb: Srgb::default(),
            colour_memo: vec![],
            memo_for: None,
            mask: vec![],
            label: vec![],
            stack: vec![],
            fit_points: Cell::new(0),
            surface_tests: Cell::new(0),
            shape: Spheroid::new([0.0, -1.0, 0.0], 1.0),
        }
    }

    /// Finds the fruit of one frame, cleared first of any fog it shows ([`crate::haze`]).
    /// Buffers of the wrong size give an empty result.
    pub fn detect(&mut self, f: &Frame) -> FrameResult {
        let n = f.width * f.height;
        if f.rgb.len() < n * 3 || f.depth.len() < n || n == 0 {
            return FrameResult::default();
        }
        let mut work = HazeWork::default();
        let found = haze::estimate(&self.srgb, f, &mut work);
        let mut out = match found {
            Some(h) => {
                let z = (self.config.min_depth, self.config.max_depth);
                let rgb = h.clear(&self.srgb, f, z, &mut work);
                self.detect_clear(&Frame { rgb: &rgb, depth: f.depth, ..*f })
            }
            None => self.detect_clear(f),
        };
        out.haze = found;
        (out.work.haze_samples, out.work.cleared) = (work.samples, work.cleared);
        out
    }

    /// [`Self::detect`] of a frame in clear air.
    fn detect_clear(&mut self, f: &Frame) -> FrameResult {
        let n = f.width * f.height;
        let mut out = FrameResult::default();
        self.fit_points.set(0);
        self.surface_tests.set(0);
        out.work.pixels = n as u64;
        let c = self.config.clone();
        self.shape = Spheroid::new(f.up.unwrap_or([0.0, -1.0, 0.0]), c.shape_index);
        if self.memo_for != Some(c.colour) {
            self.colour_memo.clear();
            self.colour_memo.resize(1 << 24, 0);
            self.memo_for = Some(c.colour);
        }
        // One pass keeps each pixel's memo answer and the luma histogram of the pixels in
        // range; the frame's exposure then sets the chroma floor the answers are held to.
        let mut histogram = [0u32; 256];
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
            histogram[luma(px) as usize] += 1;
            let key = colour_key(px);
            let mut answer = self.colour_memo[key];
            if answer == 0 {
                out.work.conversions += 1;
                answer = match c.colour.chroma_if_hue(self.lin.lab(px)) {
                    Some(chroma) => 2 + ((chroma / CHROMA_STEP) as u32).min(253) as u8,
                    None => 1,
                };
                self.colour_memo[key] = answer;
            }
            self.mask[i] = answer;
        }
        let floor = c.colour.chroma_floor(exposure_lightness(&histogram));
        let least = 2 + ((floor / CHROMA_STEP) as u32).min(253) as u8;
        for m in self.mask.iter_mut() {
            *m = (*m >= least) as u8;
        }
        out.work.candidates = self.mask.iter().map(|&m| m as u64).sum();
        self.label.clear();
        self.label.resize(n, 0);
        let mut next = 0u32;
        let mut found = vec![];
        for seed in 0..n {
            if self.mask[seed] == 0 || self.label[seed] != 0 {
                continue;
            }
            next += 1;
            let members = self.flood(f, seed, next);
            if members.len() < c.min_pixels {
                continue;
            }
            self.fit_segment(f, members, &mut found, &mut out.rejected, 0);
        }
        self.merge_parts(f, &mut found);
        out.detections = found
            .into_iter()
            .map(|(mut d, members)| {
                // Each round reaches a little further round a partly coloured fruit.
                let (mut n, mut skin) = (members.len(), None);
                for _ in 0..3 {
                    let (grown, m, surface) = self.grow(f, d, n);
                    (d, skin) = (grown, surface);
                    if m <= n {
                        break;
                    }
                    n = m;
                }
                self.ripen(f, d, skin)
            })
            .collect();
        out.work.fit_points = self.fit_points.get();
        out.work.surface_tests = self.surface_tests.get();
        out
    }

    /// The whole visible surface of a found fruit. A breaker or turning fruit is coloured only
    /// from its blossom end, so its colour segment is a part of its cap, and a sphere through
    /// a part of a cap is poorly placed across the view. Every pixel near the fitted sphere's
    /// image whose point lies on its surface (within a few noise widths) is the same fruit,
    /// green or not; the sphere is fitted again to them all.
    /// (Growing over all depth-continuous pixels instead reached leaves and calyces: the
    /// perception benchmark's centre error p95 rose from 13 to 14 mm.) Returns the detection,
    /// the count of pixels it now rests on, and, when it is the detection given, its surface
    /// (which [`Self::ripen`] then need not find again).
    fn grow(&self, f: &Frame, d: Detection, members: usize) -> (Detection, usize, Option<Vec<usize>>) {
        let all = self.on_surface(f, &d);
        // A fit through a tenth more of the surface or less moves little.
        if all.len() * 10 <= members * 11 {
            return (d, members, Some(all));
        }
        let c = d.center;
        let fit = fit_sphere(&self.points(f, &all), &self.config.sphere).map(|s| (self.shape.unround(s.center), s));
        match fit {
            Some((center, s))
                if s.rms <= self.config.max_rms
                    && s.inlier_fraction >= self.config.min_inliers
                    && !s.at_bound
                    && d2(center, c).sqrt() < d.radius =>
            {
                (Detection { center, radius: s.radius, rms: s.rms, ..d }, all.len(), None)
            }
            _ => (d, members, Some(all)),
        }
    }

    /// The stage of a placed fruit from its skin (every pixel on its sphere, green or not):
    /// each pixel's fraction of the surface below it along the world's up, and its colour.
    /// `skin`: the detection's surface when already found ([`Self::on_surface`]).
    fn ripen(&self, f: &Frame, d: Detection, skin: Option<Vec<usize>>) -> Detection {
        let (up, rc) = (self.shape.up(), self.shape.round(d.center));
        let skin = skin.unwrap_or_else(|| self.on_surface(f, &d));
        let r = ripeness(skin.iter().map(|&i| {
            let p = self.shape.round(f.k.unproject(i % f.width, i / f.width, f.depth[i] as f64));
            (surface_below(p, rc, d.radius, up), [f.rgb[3 * i], f.rgb[3 * i + 1], f.rgb[3 * i + 2]])
        }));
        let votes = r.as_ref().map_or([0.0; 6], stage_shares);
        let (stage, p) = if r.is_some() { classify(&votes) } else { (0, 0.0) };
        // Score: the stage's probability, lowered by a poor fit.
        let score = p * (1.0 - 0.5 * (d.rms / self.config.max_rms)).clamp(0.0, 1.0);
        Detection { stage, score, votes, ripeness: r, ..d }
    }

    /// The pixels near a fruit's image whose points lie on its surface (within a few noise
    /// widths of its fit).
    fn on_surface(&self, f: &Frame, d: &Detection) -> Vec<usize> {
        let c = d.center;
        let rc = self.shape.round(c);
        if c[2] <= d.radius {
            return vec![];
        }
        let uv = f.k.project(c);
        let rpx = 1.15 * d.radius * f.k.fx.max(f.k.fy) / (c[2] - d.radius);
        let (u0, u1) = ((uv[0] - rpx).floor().max(0.0) as usize, ((uv[0] + rpx).ceil().max(0.0) as usize).min(f.width));
        let (v0, v1) =
            ((uv[1] - rpx).floor().max(0.0) as usize, ((uv[1] + rpx).ceil().max(0.0) as usize).min(f.height));
        let tol = (2.5 * d.rms).max(0.003);
        // A point whose depth alone puts it farther than the surface's band can be passed
        // over: its rounded distance is at least the least stretch times its depth gap.
        let (band, least) = ((d.radius + tol) * (1.0 + 1e-9) + 1e-12, self.shape.least_stretch());
        self.surface_tests.set(self.surface_tests.get() + (v1.saturating_sub(v0) * u1.saturating_sub(u0)) as u64);
        let mut all = vec![];
        for v in v0..v1 {
            for u in u0..u1 {
                let i = v * f.width + u;
                let z = f.depth[i] as f64;
                if !(z.is_finite() && z > 0.0) || least * (z - c[2]).abs() > band {
                    continue;
                }
                let p = self.shape.round(f.k.unproject(u, v, z));
                if (d2(p, rc).sqrt() - d.radius).abs() <= tol {
                    all.push(i);
                }
            }
        }
        all
    }

    /// One fruit seen in parts (a pedicel, leaf or highlight across it, or a split of a
    /// segment the fit refused) gives spheres whose centres lie closer than a radius; two
    /// fruit, however tightly packed, have centres a sum of radii apart. Such parts are fitted
    /// again as one segment, which also gives the fit more of the fruit's surface; when the
    /// joint fit fails, the part with more pixels stays.
    fn merge_parts(&self, f: &Frame, found: &mut Vec<(Detection, Vec<usize>)>) {
        loop {
            let mut pair = None;
            'search: for i in 0..found.len() {
                for j in i + 1..found.len() {
                    let (a, b) = (&found[i].0, &found[j].0);
                    if d2(a.center, b.center).sqrt() < a.radius.max(b.radius) {
                        pair = Some((i, j));
                        break 'search;
                    }
                }
            }
            let Some((i, j)) = pair else { return };
            let (dj, mj) = found.remove(j);
            let mut members = found[i].1.clone();
            members.extend_from_slice(&mj);
            members.sort_unstable();
            match self.fit_one(f, &members) {
                Ok(d) => found[i] = (d, members),
                Err(()) if dj.pixels > found[i].0.pixels => found[i] = (dj, mj),
                Err(()) => {}
            }
        }
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

    /// Fits one segment; a segment the fit refuses (too big for one fruit, too flat) is split
    /// in two (twice at most).
    fn fit_segment(
        &self,
        f: &Frame,
        members: Vec<usize>,
        found: &mut Vec<(Detection, Vec<usize>)>,
        rejected: &mut usize,
        depth: u32,
    ) {
        let c = &self.config;
        match self.fit_one(f, &members) {
            Ok(d) => found.push((d, members)),
            Err(()) => {
                if depth < 2 && members.len() >= 2 * c.min_pixels {
                    let pts = self.points(f, &members);
                    let (a, b) = split_two(&members, &pts);
                    if a.len() >= c.min_pixels / 2 && b.len() >= c.min_pixels / 2 {
                        self.fit_segment(f, a, found, rejected, depth + 1);
                        self.fit_segment(f, b, found, rejected, depth + 1);
                        return;
                    }
                }
                *rejected += 1;
            }
        }
    }

    /// The members' points in the rounded space (where a fruit is a sphere), counted as
    /// fitted (every caller fits or splits them).
    fn points(&self, f: &Frame, members: &[usize]) -> Vec<[f64; 3]> {
        self.fit_points.set(self.fit_points.get() + members.len() as u64);
        members.iter().map(|&i| self.shape.round(f.k.unproject(i % f.width, i / f.width, f.depth[i] as f64))).collect()
    }

    /// A sphere through one segment's points (its stage comes later, from its whole skin:
    /// [`Self::ripen`]); `Err` when the fit fails or is poor.
    fn fit_one(&self, f: &Frame, members: &[usize]) -> Result<Detection, ()> {
        let c = &self.config;
        let pts = self.points(f, members);
        let s = fit_sphere(&pts, &c.sphere).ok_or(())?;
        if s.rms > c.max_rms || s.inlier_fraction < c.min_inliers || s.at_bound {
            return Err(());
        }
        let mut bbox = [usize::MAX, usize::MAX, 0, 0];
        for &i in members {
            let (u, v) = (i % f.width, i / f.width);
            bbox = [bbox[0].min(u), bbox[1].min(v), bbox[2].max(u), bbox[3].max(v)];
        }
        Ok(Detection {
            center: self.shape.unround(s.center),
            radius: s.radius,
            stage: 0,
            score: 0.0,
            votes: [0.0; 6],
            ripeness: None,
            rms: s.rms,
            pixels: members.len(),
            bbox,
        })
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

/// Each of 8 bits moved to every third place (bit k to bit 3k).
const SPREAD: [u32; 256] = {
    let mut t = [0u32; 256];
    let mut v = 0;
    while v < 256 {
        let mut k = 0;
        while k < 8 {
            t[v] |= ((v as u32 >> k) & 1) << (3 * k);
            k += 1;
        }
        v += 1;
    }
    t
};

/// The colour memo's index of an sRGB colour: its channels' bits interleaved (Morton order),
/// so colours a few levels apart share a cache line (a 4x4x4 cube per 64 bytes). With the
/// channels side by side (r << 16 | g << 8 | b) the pixel pass waited on memory: a surface's
/// noisy colours landed 64 KiB apart in the 16 MiB table.
fn colour_key(px: [u8; 3]) -> usize {
    (SPREAD[px[0] as usize] << 2 | SPREAD[px[1] as usize] << 1 | SPREAD[px[2] as usize]) as usize
}

fn d2(a: [f64; 3], b: [f64; 3]) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Depth (z) of the first hit of the camera ray through `d` (z = 1) on a fruit of
    /// equatorial radius `r` and shape index `k` about `up`: the ray and the fruit rounded
    /// (a linear map, so the ray's parameter, here its depth, is kept), then a sphere.
    fn hit_shaped(d: [f64; 3], c: [f64; 3], r: f64, up: [f64; 3], k: f64) -> Option<f64> {
        let s = Spheroid::new(up, k);
        let (d, c) = (s.round(d), s.round(c));
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let (dd, b) = (dot(d, d), dot(d, c));
        let disc = b * b - dd * (dot(c, c) - r * r);
        (disc >= 0.0).then(|| (b - disc.sqrt()) / dd)
    }

    /// [`hit_shaped`] for a level camera and the crop's fruit.
    fn hit(d: [f64; 3], c: [f64; 3], r: f64) -> Option<f64> {
        hit_shaped(d, c, r, [0.0, -1.0, 0.0], SHAPE_INDEX)
    }

    /// A frame ray cast by `shade` (pixel column, ray direction with z = 1 -> depth, colour).
    fn render(
        w: usize,
        h: usize,
        k: Intrinsics,
        shade: impl Fn(usize, [f64; 3]) -> (f64, [u8; 3]),
    ) -> (Vec<u8>, Vec<f32>) {
        let mut rgb = vec![0u8; w * h * 3];
        let mut depth = vec![0f32; w * h];
        for v in 0..h {
            for u in 0..w {
                let d = [(u as f64 + 0.5 - k.cx) / k.fx, (v as f64 + 0.5 - k.cy) / k.fy, 1.0];
                let (z, col) = shade(u, d);
                let i = v * w + u;
                depth[i] = z as f32;
                rgb[3 * i..3 * i + 3].copy_from_slice(&col);
            }
        }
        (rgb, depth)
    }

    const WALL: (f64, [u8; 3]) = (1.2, [150, 145, 135]);

    /// The memo's index is a bijection of the 2^24 colours, and neighbouring levels stay
    /// within one 64-byte line.
    #[test]
    fn colour_keys_are_a_bijection() {
        let mut seen = vec![false; 1 << 24];
        for r in 0..=255u8 {
            for g in 0..=255u8 {
                for b in 0..=255u8 {
                    let k = colour_key([r, g, b]);
                    assert!(!seen[k], "{r} {g} {b}");
                    seen[k] = true;
                }
            }
        }
        assert_eq!(colour_key([4, 4, 4]) / 64, colour_key([7, 7, 7]) / 64);
    }

    /// A large oblate fruit (80 mm wide, 70 mm high) seen level from 0.6 m: its width and
    /// centre are read within 1.5 mm. Fitted as a sphere (shape index 1), the same fruit reads
    /// more than 2 mm narrow and nearer the camera: the bias that let fruit too wide for the
    /// hand pass as graspable.
    #[test]
    fn an_oblate_fruit_is_measured_at_its_width() {
        let (w, h) = (200usize, 160usize);
        let k = Intrinsics { fx: 300.0, fy: 300.0, cx: 100.0, cy: 80.0 };
        let (c, r) = ([0.03, 0.02, 0.6], 0.040);
        let (rgb, depth) = render(w, h, k, |_, d| hit(d, c, r).map_or(WALL, |t| (t, [190, 26, 20])));
        let frame = Frame { width: w, height: h, rgb: &rgb, depth: &depth, k, up: None };
        let found = Detector::new(DetectorConfig::default()).detect(&frame);
        assert_eq!(found.detections.len(), 1, "{:?}", found.detections);
        let d = &found.detections[0];
        assert!((d.radius - r).abs() < 0.0015, "{d:?}");
        assert!(d2(d.center, c).sqrt() < 0.0015, "{d:?}");
        let round = Detector::new(DetectorConfig { shape_index: 1.0, ..DetectorConfig::default() }).detect(&frame);
        let s = &round.detections[0];
        assert!(s.radius < r - 0.002 && s.center[2] < c[2] - 0.001, "{s:?}");
    }

    /// The same kind of frame in fog of 15 m visibility (Koschmieder, grey airlight), a far
    /// field without depth on the right and shade below: the fog is estimated from the frame,
    /// and the fruit are found after clearing, the farther one (in shade, as under a fog's
    /// diffuse light) though its fogged colour fails the colour test.
    #[test]
    fn fruit_are_found_through_fog() {
        let (w, h) = (160usize, 120usize);
        let k = Intrinsics { fx: 240.0, fy: 240.0, cx: 80.0, cy: 60.0 };
        let (beta, air) = (3.912 / 15.0, 0.27);
        let fog = |col: [u8; 3], range: f64| -> [u8; 3] {
            let t = (-beta * range).exp();
            col.map(|c| {
                let v = crate::colour::Linearize::default().channel(c) as f64;
                let s = v * t + air * (1.0 - t);
                let e = if s <= 0.003_130_8 { 12.92 * s } else { 1.055 * s.powf(1.0 / 2.4) - 0.055 };
                (e * 255.0).round() as u8
            })
        };
        let fruit = [([-0.15, 0.0, 1.3], 0.03, [80u8, 12, 10]), ([0.05, 0.05, 1.1], 0.033, [185, 30, 22])];
        let (rgb, depth) = render(w, h, k, |u, d| {
            if u >= 130 {
                return (0.0, fog([0, 0, 0], f64::INFINITY));
            }
            let mut best = if d[1] > 0.15 {
                (1.5, [3u8, 3, 3])
            } else if u < 30 {
                (1.2, [58u8, 112, 38])
            } else {
                (1.5, WALL.1)
            };
            for (c, r, col) in fruit {
                if let Some(t) = hit(d, c, r).filter(|t| *t < best.0) {
                    best = (t, col);
                }
            }
            let range = best.0 * (d[0] * d[0] + d[1] * d[1] + 1.0).sqrt();
            (best.0, fog(best.1, range))
        });
        // The fogged red of the farther fruit is no longer fruit-coloured.
        let lin = Linearize::default();
        let v = (0.0 / 1.3 * k.fy + k.cy) as usize;
        let u = (-0.15 / 1.3 * k.fx + k.cx) as usize;
        let i = v * w + u;
        let px = [rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2]];
        assert!(!FruitColour::default().accepts(lin.lab(px), 50.0), "{px:?} passes the colour test in fog");
        let mut det = Detector::new(DetectorConfig::default());
        let r = det.detect(&Frame { width: w, height: h, rgb: &rgb, depth: &depth, k, up: None });
        let haze = r.haze.expect("fog found");
        assert!((haze.beta - beta).abs() < 0.05 * beta, "{haze:?}");
        assert!(r.work.haze_samples > 0 && r.work.cleared > 0);
        assert_eq!(r.detections.len(), 2, "{:?}", r.detections);
        for (c, rad, _) in fruit {
            let d = r.detections.iter().min_by(|a, b| d2(a.center, c).total_cmp(&d2(b.center, c))).unwrap();
            assert!(d2(d.center, c).sqrt() < 0.006, "{d:?} vs {c:?}");
            assert!((d.radius - rad).abs() < 0.006, "{d:?}");
            assert!(d.stage >= 5, "{d:?}");
        }
    }

    /// At dusk (a twentieth of the light) a red fruit in shade keeps a CIELAB chroma of 6.6:
    /// found, because the frame's exposure (the wall, L* 12) lowers the chroma floor to 4;
    /// with the daylight floor of 8 at every exposure it is not.
    #[test]
    fn a_shaded_fruit_is_found_at_dusk() {
        let (w, h) = (160usize, 120usize);
        let k = Intrinsics { fx: 120.0, fy: 120.0, cx: 80.0, cy: 60.0 };
        let (c, r) = ([0.0, 0.0, 0.7], 0.03);
        let (rgb, depth) = render(w, h, k, |u, d| {
            let back = if u < 30 { (1.2, [18u8, 36, 10]) } else { (1.2, [33u8, 32, 29]) };
            hit(d, c, r).map_or(back, |t| (t, [21, 1, 0]))
        });
        let frame = Frame { width: w, height: h, rgb: &rgb, depth: &depth, k, up: None };
        let colour = FruitColour::default();
        let lab = Linearize::default().lab([21, 1, 0]);
        assert!((lab[1].hypot(lab[2]) - 6.6).abs() < 0.1, "{lab:?}");
        let found = Detector::new(DetectorConfig::default()).detect(&frame);
        assert_eq!(found.detections.len(), 1, "{:?}", found.detections);
        let d = &found.detections[0];
        assert!(d2(d.center, c).sqrt() < 0.004 && d.stage == 6, "{d:?}");
        let daylight = FruitColour { exposure_reference: 0.0, ..colour };
        let fixed = Detector::new(DetectorConfig { colour: daylight, ..DetectorConfig::default() }).detect(&frame);
        assert!(fixed.detections.is_empty(), "{:?}", fixed.detections);
    }

    /// A synthetic frame: a grey wall at 1.2 m, green leaves, and two tomatoes (a red one and
    /// a turning one) rendered by ray casting: both found, with their stage and centre.
    #[test]
    fn finds_two_rendered_tomatoes() {
        let (w, h) = (160usize, 120usize);
        let k = Intrinsics { fx: 120.0, fy: 120.0, cx: 80.0, cy: 60.0 };
        let fruit = [([-0.12, 0.0, 0.7], 0.03, [190u8, 26, 20]), ([0.1, 0.05, 0.6], 0.035, [205, 150, 66])];
        let (rgb, depth) = render(w, h, k, |u, d| {
            let mut best = if u < 30 { (1.2, [58u8, 112, 38]) } else { WALL };
            for (c, r, col) in fruit {
                if let Some(t) = hit(d, c, r).filter(|t| *t < best.0) {
                    best = (t, col);
                }
            }
            best
        });
        let mut det = Detector::new(DetectorConfig::default());
        let r = det.detect(&Frame { width: w, height: h, rgb: &rgb, depth: &depth, k, up: None });
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
        let r = det.detect(&Frame { width: w, height: h, rgb: &rgb, depth: &none, k, up: None });
        assert!(r.detections.is_empty() && r.valid_depth == 0);
    }

    /// The work of a frame is a function of the frame (and of the colours seen before): the
    /// same frame to two fresh detectors counts the same; seen again, only its colour
    /// conversions are spared (the memo holds them).
    #[test]
    fn work_is_counted_deterministically() {
        let (w, h) = (160usize, 120usize);
        let k = Intrinsics { fx: 120.0, fy: 120.0, cx: 80.0, cy: 60.0 };
        let (rgb, depth) = render(w, h, k, |_, d| hit(d, [0.0, 0.0, 0.7], 0.03).map_or(WALL, |t| (t, [190, 26, 20])));
        let f = Frame { width: w, height: h, rgb: &rgb, depth: &depth, k, up: None };
        let mut a = Detector::new(DetectorConfig::default());
        let first = a.detect(&f);
        assert_eq!(first.detections.len(), 1);
        let again = a.detect(&f).work;
        let fresh = Detector::new(DetectorConfig::default()).detect(&f).work;
        assert_eq!(fresh, first.work);
        let wk = first.work;
        assert_eq!((wk.pixels, wk.conversions), ((w * h) as u64, 2));
        assert!(wk.candidates > 50 && wk.fit_points >= wk.candidates && wk.surface_tests > wk.candidates, "{wk:?}");
        assert_eq!(again, DetectWork { conversions: 0, ..wk });
    }

    /// A ripe fruit 0.8 m ahead with a stem 8 mm wide in front of it, across its middle: two
    /// segments, one fruit.
    #[test]
    fn a_fruit_cut_by_a_stem_is_one_detection() {
        let (w, h) = (200usize, 160usize);
        let k = Intrinsics { fx: 300.0, fy: 300.0, cx: 100.0, cy: 80.0 };
        let (c, r) = ([0.0, 0.0, 0.8], 0.032);
        let (rgb, depth) = render(w, h, k, |_, d| {
            if (d[0] * 0.7).abs() < 0.004 {
                // The stem: a vertical bar 8 mm wide at 0.7 m.
                return (0.7, [58, 112, 38]);
            }
            hit(d, c, r).map_or(WALL, |t| (t, [190, 26, 20]))
        });
        let mut det = Detector::new(DetectorConfig::default());
        let found = det.detect(&Frame { width: w, height: h, rgb: &rgb, depth: &depth, k, up: None });
        assert_eq!(found.detections.len(), 1, "{:?}", found.detections);
        let d = &found.detections[0];
        assert!(d2(d.center, c).sqrt() < 0.004, "{d:?}");
        // Both halves went into the fit.
        assert!(d.bbox[0] < 95 && d.bbox[2] > 105, "{d:?}");
    }

    /// A turning fruit, coloured only over its lower third (the blossom end): the colour
    /// segment is a sliver of the cap, the sphere is placed from the whole surface.
    #[test]
    fn a_partly_coloured_fruit_is_placed_from_its_whole_surface() {
        let (w, h) = (200usize, 160usize);
        let k = Intrinsics { fx: 300.0, fy: 300.0, cx: 100.0, cy: 80.0 };
        let (c, r) = ([0.02, -0.01, 0.7], 0.03);
        let (rgb, depth) = render(w, h, k, |_, d| {
            hit(d, c, r).map_or(WALL, |t| (t, if t * d[1] - c[1] > 0.4 * r { [215, 110, 50] } else { [120, 150, 60] }))
        });
        let mut det = Detector::new(DetectorConfig::default());
        let found = det.detect(&Frame { width: w, height: h, rgb: &rgb, depth: &depth, k, up: None });
        assert_eq!(found.detections.len(), 1, "{:?}", found.detections);
        let d = &found.detections[0];
        assert!(d2(d.center, c).sqrt() < 0.003, "{d:?}");
        assert!((d.radius - r).abs() < 0.003, "{d:?}");
    }

    /// A pink fruit (coloured from its bottom over 45 % of its surface, its deep pink of red's
    /// hue) and a light red one (75 %), seen by a camera pitched 40 deg up at them: most of
    /// what it sees is coloured, and the stage is read from the front's height along the
    /// world's up (from TF), not from the share of coloured pixels.
    #[test]
    fn ripeness_is_read_along_the_worlds_up() {
        let (w, h) = (200usize, 160usize);
        let k = Intrinsics { fx: 300.0, fy: 300.0, cx: 100.0, cy: 80.0 };
        let pitch = 40f64.to_radians();
        let up = [0.0, -pitch.cos(), pitch.sin()];
        for (fraction, stage) in [(0.45, 4u8), (0.75, 5)] {
            let (c, r) = ([0.0, 0.0, 0.5], 0.03);
            let (rgb, depth) = render(w, h, k, |_, d| {
                hit_shaped(d, c, r, up, SHAPE_INDEX).map_or(WALL, |t| {
                    let p = [t * d[0] - c[0], t * d[1] - c[1], t - c[2]];
                    let h = (p[0] * up[0] + p[1] * up[1] + p[2] * up[2]) / (SHAPE_INDEX * r);
                    let below = 0.5 * (h + 1.0);
                    (t, if below < fraction { [232, 104, 84] } else { [132, 168, 70] })
                })
            });
            let mut det = Detector::new(DetectorConfig::default());
            let found = det.detect(&Frame { width: w, height: h, rgb: &rgb, depth: &depth, k, up: Some(up) });
            assert_eq!(found.detections.len(), 1, "{:?}", found.detections);
            let d = &found.detections[0];
            let pink = d.ripeness.expect("skin seen").pink;
            assert!((pink.fraction - fraction).abs() < 0.04, "{fraction}: {pink:?}");
            assert_eq!(d.stage, stage, "{d:?}");
            if stage == 4 {
                let coloured = rgb.chunks_exact(3).filter(|p| p[0] == 232).count();
                let green = rgb.chunks_exact(3).filter(|p| p[0] == 132).count();
                assert!(coloured > green, "mostly coloured in view: {coloured} vs {green}");
                assert!(d.votes[4] + d.votes[5] < 0.1, "{d:?}");
            }
        }
    }
}
