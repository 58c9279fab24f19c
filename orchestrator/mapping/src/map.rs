//! The occupancy map: log-odds voxels in 16^3 chunks, updated per scan as OctoMap's
//! `insertPointCloud` does (every voxel a ray passes before its end is one miss, every end
//! voxel one hit, a voxel both in one scan a hit; clamped log-odds), with MoveIt's additions:
//! points on the robot's own links are not obstacles (their rays still clear space), and
//! allowed objects (the fruit to grasp) are left out of collision queries and exports.
//!
//! Chunks are found through a `BTreeMap` (sorted) and, during a scan, a dense table over the
//! scan's extent; every output (voxel lists, boxes, scenes) is sorted, so the same scans give
//! the same bytes whatever the platform.

use crate::depth::{DepthFrame, Intrinsics};
use crate::ray::{clip, range, Grid, Key};
use crate::shape::{point_box_distance_sq, segment_box_distance, Primitive, Sphere};
use agrisim_msgs::agrisim::{CollisionObject, PlanningScene};
use agrisim_msgs::geometry_msgs::{Point, Pose, Quaternion};
use agrisim_msgs::shape_msgs::SolidPrimitive;
use agrisim_msgs::std_msgs::Header;
use nalgebra::{Isometry3, Point3};
use std::collections::BTreeMap;

/// Kind of the exported obstacles in a planning scene (the harvest planner treats every kind
/// but leaf, truss and floor as solid).
pub const OCCUPIED_KIND: &str = "occupied";

const BITS: i32 = 4;
const SIDE: i32 = 1 << BITS;
const VOXELS: usize = (SIDE * SIDE * SIDE) as usize;
const NONE: u32 = u32::MAX;
/// Scans whose extent holds at most this many voxels are marked in a dense grid (a byte
/// each: 64 MB, a 4 x 4 x 4 m box at 1 cm), larger ones straight in the chunks.
const DENSE_LIMIT: usize = 1 << 26;

// Per-scan marks.
const FREE: u8 = 1;
const HIT: u8 = 2;
const MODEL: u8 = 3;

/// Map parameters. The sensor model's defaults are OctoMap's (`OccupancyOcTreeBase`: hit 0.7,
/// miss 0.4, clamping 0.1192 and 0.971, threshold 0.5), which MoveIt's occupancy map monitor uses.
#[derive(Debug, Clone, PartialEq)]
pub struct MapConfig {
    /// Voxel edge [m].
    pub resolution: f64,
    /// Returns farther than this [m] only clear space up to it (OctoMap's `maxrange`).
    pub max_range: f64,
    pub prob_hit: f64,
    pub prob_miss: f64,
    pub clamp_min: f64,
    pub clamp_max: f64,
    /// A voxel whose probability is at least this is occupied.
    pub occupied_threshold: f64,
    /// Collision queries grow every occupied voxel by this [m].
    pub padding: f64,
    /// The robot's links are grown by this [m] for the self-filter (MoveIt's `padding_offset`;
    /// 0.03 m in its example sensor configurations).
    pub self_padding: f64,
}

impl Default for MapConfig {
    fn default() -> Self {
        MapConfig {
            resolution: 0.01,
            max_range: 2.0,
            prob_hit: 0.7,
            prob_miss: 0.4,
            clamp_min: 0.1192,
            clamp_max: 0.971,
            occupied_threshold: 0.5,
            padding: 0.01,
            self_padding: 0.03,
        }
    }
}

impl MapConfig {
    pub fn validate(&self) -> Result<(), String> {
        let p = |v: f64| v > 0.0 && v < 1.0;
        if !(self.resolution >= 1e-3 && self.resolution <= 1.0) {
            return Err(format!("map resolution {} m, expected 0.001..1", self.resolution));
        }
        if !(self.max_range > 0.0 && self.max_range.is_finite()) {
            return Err(format!("map max_range {} m, expected positive and finite", self.max_range));
        }
        if !(p(self.prob_hit) && p(self.prob_miss) && self.prob_hit > 0.5 && self.prob_miss < 0.5) {
            return Err(format!(
                "map prob_hit {} and prob_miss {}, expected 0.5..1 and 0..0.5",
                self.prob_hit, self.prob_miss
            ));
        }
        if !(p(self.clamp_min) && p(self.clamp_max) && self.clamp_min < self.clamp_max && p(self.occupied_threshold)) {
            return Err(format!(
                "map clamping {}..{} and threshold {}, expected probabilities with min < max",
                self.clamp_min, self.clamp_max, self.occupied_threshold
            ));
        }
        if !(self.padding >= 0.0
            && self.padding.is_finite()
            && self.self_padding >= 0.0
            && self.self_padding.is_finite())
        {
            return Err(format!("map padding {} and self_padding {}, expected >= 0", self.padding, self.self_padding));
        }
        Ok(())
    }
}

/// What a voxel is known as.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Occupancy {
    Unknown,
    Free,
    Occupied,
}

/// Counts of one scan's update.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ScanStats {
    /// Points handed in.
    pub points: usize,
    /// Points on the robot (self-filtered): their rays clear, their voxels are not obstacles.
    pub self_filtered: usize,
    /// Points beyond max range (rays cleared up to it).
    pub clipped: usize,
    /// Points (or the origin) outside the key range, dropped.
    pub dropped: usize,
    /// Voxels updated as hits and as misses.
    pub hits: usize,
    pub misses: usize,
    /// Work counted for the node's compute charge (deterministic): voxels stepped through by
    /// the rays' walks, cells of the scan's dense mark grid (cleared and swept; 0 when the
    /// scan is marked sparsely), and self-filter bound tests (in-range points times links).
    pub ray_steps: usize,
    pub dense_cells: usize,
    pub self_tests: usize,
}

/// A box of voxels, both corners included.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub struct VoxelBox {
    pub min: Key,
    pub max: Key,
}

impl VoxelBox {
    /// Its min and max corners in metres.
    pub fn bounds(&self, resolution: f64) -> ([f64; 3], [f64; 3]) {
        (self.min.map(|k| k as f64 * resolution), self.max.map(|k| (k as f64 + 1.0) * resolution))
    }
}

#[inline]
fn chunk_of(k: &Key) -> Key {
    [k[0] >> BITS, k[1] >> BITS, k[2] >> BITS]
}

#[inline]
fn local(k: &Key) -> usize {
    let m = SIDE - 1;
    (((k[2] & m) << (2 * BITS)) | ((k[1] & m) << BITS) | (k[0] & m)) as usize
}

fn logodds(p: f64) -> f32 {
    (p / (1.0 - p)).ln() as f32
}

/// The dense chunk table of one scan, and the last chunk looked up.
struct Table {
    lo: Key,
    dims: [usize; 3],
    slots: Vec<u32>,
    touched: Vec<u32>,
    last: (u64, usize),
}

pub struct OccupancyMap {
    config: MapConfig,
    grid: Grid,
    hit: f32,
    miss: f32,
    lo: f32,
    hi: f32,
    threshold: f32,
    index: BTreeMap<Key, u32>,
    /// Per chunk: its key and its count of occupied voxels.
    chunks: Vec<(Key, u32)>,
    /// Log-odds of chunk `s`'s voxel `i` at `s * VOXELS + i` (x fastest), NaN when unknown.
    log: Vec<f32>,
    /// This scan's marks (FREE, HIT, MODEL) in the same layout, zero outside a scan.
    marks: Vec<u8>,
    /// The dense marks of a scan (reused), and the largest extent marked that way.
    scratch: Vec<u8>,
    dense_limit: usize,
    allowed: Vec<Sphere>,
}

impl OccupancyMap {
    pub fn new(config: MapConfig) -> Result<OccupancyMap, String> {
        config.validate()?;
        Ok(OccupancyMap {
            grid: Grid::new(config.resolution),
            hit: logodds(config.prob_hit),
            miss: logodds(config.prob_miss),
            lo: logodds(config.clamp_min),
            hi: logodds(config.clamp_max),
            threshold: logodds(config.occupied_threshold),
            config,
            index: BTreeMap::new(),
            chunks: Vec::new(),
            log: Vec::new(),
            marks: Vec::new(),
            scratch: Vec::new(),
            dense_limit: DENSE_LIMIT,
            allowed: Vec::new(),
        })
    }

    /// Scans over more voxels than this are marked in the chunks directly rather than in a
    /// dense grid (same result; the tests check both ways).
    pub fn set_dense_limit(&mut self, voxels: usize) {
        self.dense_limit = voxels;
    }

    pub fn config(&self) -> &MapConfig {
        &self.config
    }

    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// Forgets everything seen.
    pub fn clear(&mut self) {
        self.index.clear();
        self.chunks.clear();
        self.log.clear();
        self.marks.clear();
    }

    /// The objects the robot may touch (MoveIt's allowed collisions: the fruit to grasp).
    /// Voxels that touch one are left out of collision queries and exports, not erased: the
    /// map keeps them for when the target changes.
    pub fn set_allowed(&mut self, allowed: Vec<Sphere>) {
        self.allowed = allowed;
    }

    pub fn allowed(&self) -> &[Sphere] {
        &self.allowed
    }

    /// Integrates one depth frame: `camera_pose` is the optical frame's pose in the map frame,
    /// `robot` the robot's links in the map frame (self-filter).
    pub fn insert_depth(
        &mut self,
        depth: &DepthFrame,
        k: &Intrinsics,
        camera_pose: &Isometry3<f64>,
        robot: &[Primitive],
    ) -> ScanStats {
        self.insert_depth_every(depth, k, camera_pose, robot, 1)
    }

    /// [`insert_depth`](Self::insert_depth) with every `stride`-th pixel of every `stride`-th
    /// row ([`DepthFrame::points_every`]).
    pub fn insert_depth_every(
        &mut self,
        depth: &DepthFrame,
        k: &Intrinsics,
        camera_pose: &Isometry3<f64>,
        robot: &[Primitive],
        stride: usize,
    ) -> ScanStats {
        let (origin, points) = depth.points_every(k, camera_pose, stride);
        self.insert_cloud(&origin, &points, robot)
    }

    /// Integrates one scan: points (map frame) seen from `origin`.
    pub fn insert_cloud(&mut self, origin: &[f32; 3], points: &[[f32; 3]], robot: &[Primitive]) -> ScanStats {
        let mut stats = ScanStats { points: points.len(), ..Default::default() };
        let Some(ko) = self.grid.key(origin) else {
            stats.dropped = points.len();
            return stats;
        };
        let max_range = self.config.max_range;
        let links: Vec<(Point3<f64>, f64, &Primitive)> = robot
            .iter()
            .map(|p| (Point3::from(p.pose.translation.vector), p.bounding_radius() + self.config.self_padding, p))
            .collect();
        // Each ray's end (clipped at max range) and what its end voxel is.
        let mut rays: Vec<([f32; 3], u8)> = Vec::with_capacity(points.len());
        let (mut lo, mut hi) = (ko, ko);
        for p in points {
            let (end, kind) = if range(origin, p) <= max_range {
                stats.self_tests += links.len();
                let q = Point3::new(p[0] as f64, p[1] as f64, p[2] as f64);
                let on_robot = links
                    .iter()
                    .any(|(c, r, l)| (q - c).norm_squared() <= r * r && l.contains(&q, self.config.self_padding));
                if on_robot {
                    stats.self_filtered += 1;
                    (*p, MODEL)
                } else {
                    (*p, HIT)
                }
            } else if p.iter().all(|v| v.is_finite()) {
                stats.clipped += 1;
                (clip(origin, p, max_range as f32), FREE)
            } else {
                stats.dropped += 1;
                continue;
            };
            let Some(ke) = self.grid.key(&end) else {
                stats.dropped += 1;
                continue;
            };
            for i in 0..3 {
                lo[i] = lo[i].min(ke[i]);
                hi[i] = hi[i].max(ke[i]);
            }
            rays.push((end, kind));
        }
        // One voxel of slack for the walk's rounding, then chunk units.
        let (vlo, vhi) = (lo.map(|v| v - 1), hi.map(|v| v + 1));
        let (lo, hi) = (chunk_of(&vlo), chunk_of(&vhi));
        let dims = [0, 1, 2].map(|i| (hi[i] - lo[i] + 1) as usize);
        let mut t = Table {
            lo,
            dims,
            slots: vec![NONE; dims[0] * dims[1] * dims[2]],
            touched: Vec::new(),
            last: (u64::MAX, 0),
        };
        let n = [0, 1, 2].map(|i| (vhi[i] - vlo[i] + 1) as usize);
        if n[0] * n[1] * n[2] <= self.dense_limit {
            stats.dense_cells = n[0] * n[1] * n[2];
            stats.ray_steps = self.mark_dense(origin, &rays, vlo, n, &mut t);
        } else {
            stats.ray_steps = self.mark_sparse(origin, &rays, &mut t);
        }
        // Apply the marks: one update per voxel per scan.
        let (hit, miss, lo, hi, thr) = (self.hit, self.miss, self.lo, self.hi, self.threshold);
        for &s in &t.touched {
            let r = s as usize * VOXELS..(s as usize + 1) * VOXELS;
            let mut occupied = 0;
            for (l, m) in self.log[r.clone()].iter_mut().zip(self.marks[r].iter_mut()) {
                if *m != 0 {
                    let d = if *m == HIT {
                        stats.hits += 1;
                        hit
                    } else {
                        stats.misses += 1;
                        miss
                    };
                    let v = if l.is_nan() { 0.0 } else { *l } + d;
                    *l = v.clamp(lo, hi);
                    *m = 0;
                }
                occupied += (*l >= thr) as u32;
            }
            self.chunks[s as usize].1 = occupied;
        }
        stats
    }

    /// Marks a scan straight into the chunks: end voxels first (robot over hit as MoveIt,
    /// hit over free as OctoMap), then every ray's walk.
    /// Returns the voxels the walks stepped through.
    fn mark_sparse(&mut self, origin: &[f32; 3], rays: &[([f32; 3], u8)], t: &mut Table) -> usize {
        for (end, kind) in rays {
            if *kind == FREE {
                continue;
            }
            let k = self.grid.key(end).expect("checked on entry");
            let m = self.mark(t, &k);
            if *m == 0 || (*kind == MODEL && *m == HIT) {
                *m = *kind;
            }
        }
        let grid = self.grid;
        let mut steps = 0;
        for (end, _) in rays {
            grid.walk(origin, end, |k| {
                steps += 1;
                let m = self.mark(t, &k);
                if *m == 0 {
                    *m = FREE;
                }
            });
        }
        steps
    }

    /// The same marks, made in a dense byte grid over the scan's extent (`n` voxels from
    /// `lo`; one add and a byte per step of the walks) and then moved into the chunks.
    /// Returns the voxels the walks stepped through.
    fn mark_dense(
        &mut self,
        origin: &[f32; 3],
        rays: &[([f32; 3], u8)],
        lo: Key,
        n: [usize; 3],
        t: &mut Table,
    ) -> usize {
        let mut g = std::mem::take(&mut self.scratch);
        g.clear();
        g.resize(n[0] * n[1] * n[2], 0);
        let at = |k: &Key| -> Option<usize> {
            let d = [k[0] - lo[0], k[1] - lo[1], k[2] - lo[2]];
            ((d[0] as u32 as usize) < n[0] && (d[1] as u32 as usize) < n[1] && (d[2] as u32 as usize) < n[2])
                .then(|| (d[2] as usize * n[1] + d[1] as usize) * n[0] + d[0] as usize)
        };
        let mut outside = Vec::new();
        let mut steps = 0;
        for (end, kind) in rays {
            if *kind == FREE {
                continue;
            }
            let k = self.grid.key(end).expect("checked on entry");
            let i = at(&k).expect("end voxels are inside the extent");
            if g[i] == 0 || (*kind == MODEL && g[i] == HIT) {
                g[i] = *kind;
            }
        }
        for (end, _) in rays {
            self.grid.walk(origin, end, |k| match at(&k) {
                Some(i) => {
                    steps += 1;
                    if g[i] == 0 {
                        g[i] = FREE;
                    }
                }
                // Walks stay within a voxel of their ends; kept exact all the same.
                None => {
                    steps += 1;
                    outside.push(k)
                }
            });
        }
        for z in 0..n[2] {
            for y in 0..n[1] {
                let row = &g[(z * n[1] + y) * n[0]..][..n[0]];
                if row.iter().all(|m| *m == 0) {
                    continue;
                }
                for (x, m) in row.iter().enumerate() {
                    if *m != 0 {
                        let k = [lo[0] + x as i32, lo[1] + y as i32, lo[2] + z as i32];
                        *self.mark(t, &k) = *m;
                    }
                }
            }
        }
        for k in outside {
            let m = self.mark(t, &k);
            if *m == 0 {
                *m = FREE;
            }
        }
        self.scratch = g;
        steps
    }

    /// The mark of voxel `k` in this scan, its chunk created if new.
    #[inline(always)]
    fn mark(&mut self, t: &mut Table, k: &Key) -> &mut u8 {
        let c = chunk_of(k);
        // The chunk key packed in one word (chunk coordinates fit 12 bits): comparing arrays
        // went through memory in the hot loop.
        let code = (c[0] as u32 as u64 & 0xfffff)
            | (c[1] as u32 as u64 & 0xfffff) << 20
            | (c[2] as u32 as u64 & 0xfffff) << 40;
        let s = if code == t.last.0 {
            t.last.1
        } else {
            let d = [0, 1, 2].map(|i| c[i] - t.lo[i]);
            let inside = (0..3).all(|i| d[i] >= 0 && (d[i] as usize) < t.dims[i]);
            let s = if inside {
                let ti = (d[2] as usize * t.dims[1] + d[1] as usize) * t.dims[0] + d[0] as usize;
                if t.slots[ti] == NONE {
                    let s = self.chunk(c);
                    t.slots[ti] = s;
                    t.touched.push(s);
                }
                t.slots[ti]
            } else {
                // Beyond the table (walks stay inside the scan's extent): a slow path.
                let s = self.chunk(c);
                if !t.touched.contains(&s) {
                    t.touched.push(s);
                }
                s
            } as usize;
            t.last = (code, s);
            s
        };
        &mut self.marks[s * VOXELS + local(k)]
    }

    #[inline(never)]
    fn chunk(&mut self, c: Key) -> u32 {
        let n = self.chunks.len() as u32;
        let s = *self.index.entry(c).or_insert(n);
        if s == n {
            self.chunks.push((c, 0));
            self.log.resize(self.log.len() + VOXELS, f32::NAN);
            self.marks.resize(self.marks.len() + VOXELS, 0);
        }
        s
    }

    fn get(&self, k: &Key) -> Option<f32> {
        let s = *self.index.get(&chunk_of(k))? as usize;
        let l = self.log[s * VOXELS + local(k)];
        (!l.is_nan()).then_some(l)
    }

    /// The voxel's log-odds, `None` when unknown.
    pub fn log_odds(&self, k: &Key) -> Option<f32> {
        self.get(k)
    }

    pub fn state(&self, k: &Key) -> Occupancy {
        match self.get(k) {
            None => Occupancy::Unknown,
            Some(l) if l >= self.threshold => Occupancy::Occupied,
            Some(_) => Occupancy::Free,
        }
    }

    /// The state of the voxel holding a point (map frame); unknown outside the key range.
    pub fn state_at(&self, p: &Point3<f64>) -> Occupancy {
        self.grid.key64(&[p.x, p.y, p.z]).map_or(Occupancy::Unknown, |k| self.state(&k))
    }

    /// Whether voxel `k` touches an allowed object.
    pub fn is_allowed(&self, k: &Key) -> bool {
        let (lo, hi) = self.grid.bounds(k);
        self.allowed
            .iter()
            .any(|s| point_box_distance_sq(&[s.center.x, s.center.y, s.center.z], &lo, &hi) <= s.radius * s.radius)
    }

    /// The first occupied, not allowed voxel (chunk order) within `reach` of the shape
    /// described by `dist` (distance from the shape's core to a voxel box), searching the
    /// keys of the box `[lo, hi]` grown by `reach`.
    fn first_hit(
        &self,
        lo: [f64; 3],
        hi: [f64; 3],
        reach: f64,
        dist: impl Fn(&[f64; 3], &[f64; 3]) -> f64,
    ) -> Option<Key> {
        if !(reach >= 0.0) || lo.iter().chain(&hi).any(|v| !v.is_finite()) {
            return None;
        }
        let k0 = self.grid.key64(&lo.map(|v| v - reach))?;
        let k1 = self.grid.key64(&hi.map(|v| v + reach))?;
        let (c0, c1) = (chunk_of(&k0), chunk_of(&k1));
        for cz in c0[2]..=c1[2] {
            for cy in c0[1]..=c1[1] {
                for cx in c0[0]..=c1[0] {
                    let Some(&s) = self.index.get(&[cx, cy, cz]) else { continue };
                    let (key, occupied) = self.chunks[s as usize];
                    if occupied == 0 {
                        continue;
                    }
                    let log = &self.log[s as usize * VOXELS..(s as usize + 1) * VOXELS];
                    let base = key.map(|v| v << BITS);
                    let a = [0, 1, 2].map(|i| k0[i].max(base[i]));
                    let b = [0, 1, 2].map(|i| k1[i].min(base[i] + SIDE - 1));
                    for z in a[2]..=b[2] {
                        for y in a[1]..=b[1] {
                            for x in a[0]..=b[0] {
                                let k = [x, y, z];
                                if log[local(&k)] >= self.threshold {
                                    let (vl, vh) = self.grid.bounds(&k);
                                    if dist(&vl, &vh) <= reach && !self.is_allowed(&k) {
                                        return Some(k);
                                    }
                                }
                            }
                        }
                    }
                }
            }
        }
        None
    }

    /// An occupied voxel (padded by `padding`, allowed objects left out) that a sphere
    /// touches, or `None`.
    pub fn sphere_hit(&self, c: &Point3<f64>, radius: f64) -> Option<Key> {
        let p = [c.x, c.y, c.z];
        self.first_hit(p, p, radius + self.config.padding, |lo, hi| point_box_distance_sq(&p, lo, hi).sqrt())
    }

    pub fn collides_sphere(&self, c: &Point3<f64>, radius: f64) -> bool {
        self.sphere_hit(c, radius).is_some()
    }

    pub fn collides_point(&self, p: &Point3<f64>) -> bool {
        self.sphere_hit(p, 0.0).is_some()
    }

    /// The same for a capsule: the segment `a`-`b` grown by `radius`.
    pub fn capsule_hit(&self, a: &Point3<f64>, b: &Point3<f64>, radius: f64) -> Option<Key> {
        let (pa, pb) = ([a.x, a.y, a.z], [b.x, b.y, b.z]);
        let lo = [0, 1, 2].map(|i| pa[i].min(pb[i]));
        let hi = [0, 1, 2].map(|i| pa[i].max(pb[i]));
        self.first_hit(lo, hi, radius + self.config.padding, |vl, vh| segment_box_distance(&pa, &pb, vl, vh))
    }

    pub fn collides_capsule(&self, a: &Point3<f64>, b: &Point3<f64>, radius: f64) -> bool {
        self.capsule_hit(a, b, radius).is_some()
    }

    /// Every known voxel with its log-odds, sorted by key.
    pub fn known(&self) -> Vec<(Key, f32)> {
        let mut out = Vec::new();
        for (key, &s) in &self.index {
            let base = key.map(|v| v << BITS);
            for (i, l) in self.log[s as usize * VOXELS..(s as usize + 1) * VOXELS].iter().enumerate() {
                if !l.is_nan() {
                    let i = i as i32;
                    out.push(([base[0] + (i & 15), base[1] + ((i >> 4) & 15), base[2] + (i >> 8)], *l));
                }
            }
        }
        out.sort_by_key(|(k, _)| *k);
        out
    }

    /// The occupied voxels that touch no allowed object, sorted by key.
    pub fn occupied(&self) -> Vec<Key> {
        let mut out = Vec::new();
        for (key, &s) in &self.index {
            if self.chunks[s as usize].1 == 0 {
                continue;
            }
            let base = key.map(|v| v << BITS);
            for (i, l) in self.log[s as usize * VOXELS..(s as usize + 1) * VOXELS].iter().enumerate() {
                if *l >= self.threshold {
                    let i = i as i32;
                    let k = [base[0] + (i & 15), base[1] + ((i >> 4) & 15), base[2] + (i >> 8)];
                    if !self.is_allowed(&k) {
                        out.push(k);
                    }
                }
            }
        }
        out.sort();
        out
    }

    /// The occupied voxels of [`occupied`](Self::occupied) merged into boxes: runs along x,
    /// then runs of equal extent on consecutive rows along y. Their union is exactly the
    /// occupied voxels; sorted by (z, y, x) of the min corner.
    pub fn boxes(&self) -> Vec<VoxelBox> {
        let mut keys = self.occupied();
        keys.sort_by_key(|k| [k[2], k[1], k[0]]);
        let mut out = Vec::new();
        // Open rectangles of the current z: (x0, x1) -> first row.
        let mut open: BTreeMap<(i32, i32), i32> = BTreeMap::new();
        let (mut cur_z, mut prev_y) = (i32::MIN, i32::MIN);
        let close = |open: &mut BTreeMap<(i32, i32), i32>, y1: i32, z: i32, out: &mut Vec<VoxelBox>| {
            for ((x0, x1), y0) in std::mem::take(open) {
                out.push(VoxelBox { min: [x0, y0, z], max: [x1, y1, z] });
            }
        };
        let mut i = 0;
        while i < keys.len() {
            let (y, z) = (keys[i][1], keys[i][2]);
            let mut row = Vec::new();
            while i < keys.len() && keys[i][1] == y && keys[i][2] == z {
                let x0 = keys[i][0];
                let mut x1 = x0;
                i += 1;
                while i < keys.len() && keys[i][1] == y && keys[i][2] == z && keys[i][0] == x1 + 1 {
                    x1 += 1;
                    i += 1;
                }
                row.push((x0, x1));
            }
            let mut next = BTreeMap::new();
            let continues = z == cur_z && y == prev_y + 1;
            if !continues {
                close(&mut open, prev_y, cur_z, &mut out);
            }
            for run in row {
                let y0 = if continues { open.remove(&run).unwrap_or(y) } else { y };
                next.insert(run, y0);
            }
            close(&mut open, prev_y, cur_z, &mut out);
            open = next;
            cur_z = z;
            prev_y = y;
        }
        close(&mut open, prev_y, cur_z, &mut out);
        out.sort_by_key(|b| ([b.min[2], b.min[1], b.min[0]], b.max));
        out
    }

    /// The occupied space as a planning scene in the map frame (`header.frame_id`): one box
    /// obstacle of kind [`OCCUPIED_KIND`] per merged box, grown by `inflate` on every side,
    /// the allowed objects left out. The harvest planner reads it as it reads the
    /// ground-truth `/planning_scene`.
    pub fn planning_scene(&self, header: Header, inflate: f64) -> PlanningScene {
        let r = self.config.resolution;
        let objects = self
            .boxes()
            .iter()
            .enumerate()
            .map(|(i, b)| {
                let (lo, hi) = b.bounds(r);
                CollisionObject {
                    id: format!("occupied/{i}"),
                    kind: OCCUPIED_KIND.into(),
                    primitive: SolidPrimitive {
                        r#type: SolidPrimitive::BOX,
                        dimensions: (0..3).map(|a| hi[a] - lo[a] + 2.0 * inflate).collect(),
                        ..Default::default()
                    },
                    pose: Pose {
                        position: Point {
                            x: 0.5 * (lo[0] + hi[0]),
                            y: 0.5 * (lo[1] + hi[1]),
                            z: 0.5 * (lo[2] + hi[2]),
                        },
                        orientation: Quaternion::IDENTITY,
                    },
                }
            })
            .collect();
        PlanningScene { header, objects }
    }
}
