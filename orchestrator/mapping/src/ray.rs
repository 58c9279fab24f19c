//! Voxel keys and the ray walk (3-D DDA, Amanatides and Woo, "A Fast Voxel Traversal Algorithm
//! for Ray Tracing", Eurographics 1987).
//!
//! The arithmetic follows OctoMap's `coordToKey` and `computeRayKeys` (single-precision points,
//! double-precision walk, the same tie-breaking and the same stop rule), so a scan marks the
//! same voxels in this map as in an OctoMap of the same resolution; `python/bench_mapping.py`
//! measures the agreement. Voxel `k` spans `[k, k + 1) * resolution` on each axis.

/// Integer voxel coordinates.
pub type Key = [i32; 3];

/// Keys are kept within OctoMap's 16-bit range (`-32768..32768` per axis: +-327 m at 1 cm).
pub const KEY_LIMIT: i32 = 1 << 15;

/// The voxel grid: its edge and its inverse (OctoMap multiplies by the inverse).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    pub resolution: f64,
    pub inv: f64,
}

impl Grid {
    pub fn new(resolution: f64) -> Grid {
        Grid { resolution, inv: 1.0 / resolution }
    }

    /// The voxel index of one coordinate, `None` outside the key range.
    #[inline]
    pub fn index(&self, c: f64) -> Option<i32> {
        let s = (self.inv * c).floor();
        (s >= -(KEY_LIMIT as f64) && s < KEY_LIMIT as f64).then_some(s as i32)
    }

    /// The voxel of a point, `None` outside the key range or non-finite.
    #[inline]
    pub fn key(&self, p: &[f32; 3]) -> Option<Key> {
        Some([self.index(p[0] as f64)?, self.index(p[1] as f64)?, self.index(p[2] as f64)?])
    }

    /// The voxel of a point given in double precision.
    #[inline]
    pub fn key64(&self, p: &[f64; 3]) -> Option<Key> {
        Some([self.index(p[0])?, self.index(p[1])?, self.index(p[2])?])
    }

    /// Centre coordinate of voxel index `k`.
    #[inline]
    pub fn center(&self, k: i32) -> f64 {
        (k as f64 + 0.5) * self.resolution
    }

    /// The voxel's box, min and max corners.
    #[inline]
    pub fn bounds(&self, k: &Key) -> ([f64; 3], [f64; 3]) {
        let r = self.resolution;
        (k.map(|i| i as f64 * r), k.map(|i| (i as f64 + 1.0) * r))
    }

    /// Calls `f` with every voxel the segment from `origin` to `end` passes before the voxel of
    /// `end` (that one excluded; the origin's voxel included unless it is the end's). Returns
    /// false, having called nothing, when either point is outside the key range.
    #[inline(always)]
    pub fn walk(&self, origin: &[f32; 3], end: &[f32; 3], mut f: impl FnMut(Key)) -> bool {
        let (Some(ko), Some(ke)) = (self.key(origin), self.key(end)) else {
            return false;
        };
        if ko == ke {
            return true;
        }
        f(ko);
        let mut dir = [end[0] - origin[0], end[1] - origin[1], end[2] - origin[2]];
        // OctoMap: the squared norm in single precision, its root in double, stored as float.
        let length = ((dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]) as f64).sqrt() as f32;
        for d in &mut dir {
            *d /= length;
        }
        // Per axis: step, parametric distance to the next border, distance between borders.
        let axis = |i: usize| -> (i32, f64, f64) {
            let step = if dir[i] > 0.0 {
                1
            } else if dir[i] < 0.0 {
                -1
            } else {
                return (0, f64::MAX, f64::MAX);
            };
            let mut border = self.center(ko[i]);
            border += (step as f64 * self.resolution * 0.5) as f32 as f64;
            (step, (border - origin[i] as f64) / dir[i] as f64, self.resolution / (dir[i].abs() as f64))
        };
        // Scalars rather than arrays indexed by the axis: the loop keeps them in registers.
        let ((sx, mut tx, dx), (sy, mut ty, dy), (sz, mut tz, dz)) = (axis(0), axis(1), axis(2));
        let ([mut x, mut y, mut z], [ex, ey, ez]) = (ko, ke);
        let length = length as f64;
        loop {
            if tx < ty {
                if tx < tz {
                    x += sx;
                    tx += dx;
                } else {
                    z += sz;
                    tz += dz;
                }
            } else if ty < tz {
                y += sy;
                ty += dy;
            } else {
                z += sz;
                tz += dz;
            }
            if x == ex && y == ey && z == ez {
                return true;
            }
            // Past the end's distance without meeting its voxel (rounding): stop, as OctoMap.
            // (`min(tx, ty, tz) > length`, without `f64::min`'s NaN handling: none is NaN.)
            if tx > length && ty > length && tz > length {
                return true;
            }
            f([x, y, z]);
        }
    }
}

/// The end of a ray cut at `max_range` from `origin`, in OctoMap's arithmetic (single precision).
#[inline]
pub fn clip(origin: &[f32; 3], p: &[f32; 3], max_range: f32) -> [f32; 3] {
    let mut d = [p[0] - origin[0], p[1] - origin[1], p[2] - origin[2]];
    let len = ((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) as f64).sqrt();
    if len > 0.0 {
        for v in &mut d {
            *v /= len as f32;
        }
    }
    [origin[0] + d[0] * max_range, origin[1] + d[1] * max_range, origin[2] + d[2] * max_range]
}

/// The distance from `origin` to `p` as OctoMap's range test computes it.
#[inline]
pub fn range(origin: &[f32; 3], p: &[f32; 3]) -> f64 {
    let d = [p[0] - origin[0], p[1] - origin[1], p[2] - origin[2]];
    ((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) as f64).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn keys(g: &Grid, a: [f32; 3], b: [f32; 3]) -> Vec<Key> {
        let mut v = Vec::new();
        assert!(g.walk(&a, &b, |k| v.push(k)));
        v
    }

    #[test]
    fn axis_ray_marks_the_voxels_before_the_end() {
        let g = Grid::new(0.1);
        let v = keys(&g, [0.05, 0.05, 0.05], [0.55, 0.05, 0.05]);
        assert_eq!(v, (0..5).map(|x| [x, 0, 0]).collect::<Vec<_>>());
        // Backwards, through negative keys.
        let v = keys(&g, [0.05, 0.05, 0.05], [-0.25, 0.05, 0.05]);
        assert_eq!(v, vec![[0, 0, 0], [-1, 0, 0], [-2, 0, 0]]);
        // Same voxel: nothing.
        assert!(keys(&g, [0.01, 0.01, 0.01], [0.09, 0.02, 0.03]).is_empty());
    }

    #[test]
    fn diagonal_ray_is_face_connected_and_ends_next_to_the_end() {
        let g = Grid::new(0.01);
        let (a, b) = ([0.003f32, 0.004, 0.001], [0.537f32, -0.211, 0.319]);
        let v = keys(&g, a, b);
        assert_eq!(v[0], g.key(&a).unwrap());
        for w in v.windows(2) {
            let d: i32 = (0..3).map(|i| (w[1][i] - w[0][i]).abs()).sum();
            assert_eq!(d, 1, "{w:?}");
        }
        let e = g.key(&b).unwrap();
        let last = v.last().unwrap();
        assert_eq!((0..3).map(|i| (e[i] - last[i]).abs()).sum::<i32>(), 1);
        // Every voxel is within half a diagonal of the segment.
        for k in &v {
            let c = [0, 1, 2].map(|i| g.center(k[i]));
            let ab = [0, 1, 2].map(|i| (b[i] - a[i]) as f64);
            let ac = [0, 1, 2].map(|i| c[i] - a[i] as f64);
            let t = (0..3).map(|i| ab[i] * ac[i]).sum::<f64>() / (0..3).map(|i| ab[i] * ab[i]).sum::<f64>();
            let d = (0..3).map(|i| (ac[i] - t * ab[i]).powi(2)).sum::<f64>().sqrt();
            assert!(d <= 0.01 * 3f64.sqrt() / 2.0 + 1e-9, "{k:?} {d}");
        }
    }

    #[test]
    fn out_of_range_points_walk_nothing() {
        let g = Grid::new(0.01);
        assert!(!g.walk(&[0.0; 3], &[400.0, 0.0, 0.0], |_| panic!()));
        assert!(!g.walk(&[0.0; 3], &[f32::NAN, 0.0, 0.0], |_| panic!()));
        assert_eq!(g.key(&[-327.68, 0.0, 327.67]), Some([-32768, 0, 32767]));
    }

    proptest::proptest! {
        /// Any segment: the walk starts in the origin's voxel, steps to a face neighbour each
        /// time, every voxel it marks meets the segment, and it stops next to the end's voxel.
        #[test]
        fn walks_follow_the_segment(a in proptest::array::uniform3(-3.0f32..3.0), b in proptest::array::uniform3(-3.0f32..3.0)) {
            let g = Grid::new(0.05);
            let v = keys(&g, a, b);
            let (ka, kb) = (g.key(&a).unwrap(), g.key(&b).unwrap());
            if ka == kb {
                proptest::prop_assert!(v.is_empty());
            } else {
                proptest::prop_assert_eq!(v[0], ka);
                for w in v.windows(2) {
                    proptest::prop_assert_eq!((0..3).map(|i| (w[1][i] - w[0][i]).abs()).sum::<i32>(), 1);
                }
                let seg = |k: &Key| {
                    let (lo, hi) = g.bounds(k);
                    crate::shape::segment_box_distance(&a.map(|x| x as f64), &b.map(|x| x as f64), &lo, &hi)
                };
                for k in &v {
                    proptest::prop_assert!(seg(k) < 1e-5, "{:?} is {} from the segment", k, seg(k));
                }
                proptest::prop_assert!(!v.contains(&kb));
                let last = v.last().unwrap();
                let gap: i32 = (0..3).map(|i| (kb[i] - last[i]).abs()).sum();
                // Next to the end, or (rounding at a corner) one more step away, as OctoMap.
                proptest::prop_assert!(gap <= 2, "ends {} steps from the end voxel", gap);
            }
        }
    }

    #[test]
    fn clip_keeps_the_direction() {
        let e = clip(&[1.0, 1.0, 1.0], &[1.0, 1.0, 11.0], 2.0);
        assert_eq!(e, [1.0, 1.0, 3.0]);
        assert_eq!(range(&[0.0; 3], &[3.0, 4.0, 0.0]), 5.0);
    }
}
