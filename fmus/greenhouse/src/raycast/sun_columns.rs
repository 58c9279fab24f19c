//! Shadow rays that no opaque object can stop, told without a traversal.
//!
//! All shadow rays toward one light direction are parallel. Seen along that direction a ray
//! is a point (its foot: where it crosses z = 0), and an object covers the region its
//! bounding box sweeps out (a hexagon). A grid over that view keeps, per cell, the highest
//! top of the opaque objects covering it. A ray leaving a point above that height only
//! climbs (the light is above the horizon), so it meets none of them: it needs only the
//! translucent objects (glass, film), a tree a fraction of the scene's size. The grid is
//! conservative, so every other ray takes the full traversal and the answers stay exact.

use super::RayCaster;

/// Lowest light elevation (sine) with a grid: below it shadow rays run nearly level and
/// sweep boxes across most of the grid.
const MIN_SIN_ELEVATION: f64 = 0.05;

/// Slack added around every swept box [m], far above the rounding of the foot and of the
/// sweep at greenhouse scales (~1e-13 m), far below a cell.
const PAD: f64 = 1e-6;

/// Slack added to an object's top, relative to (1 + |z|) [m]: above the rounding of the
/// primitives' intersection arithmetic (~1e-12 m at greenhouse scales), below the offset
/// off a surface that shadow rays start from (1e-6 m: a point on the floor is above it).
const TOP_PAD: f64 = 1e-9;

/// The grid of one light direction over one scene, with the scene's translucent objects.
#[derive(Clone)]
pub struct SunColumns {
    dir: [f64; 3],
    /// A point's foot is its (x, y) minus its z times this (the direction's slope).
    w: [f64; 2],
    /// Corner of cell (0, 0) and the cell size [m].
    origin: [f64; 2],
    cell: f64,
    /// 1 / cell: a foot within rounding of a cell's edge lies in both cells' padded cover.
    per_metre: f64,
    nx: usize,
    ny: usize,
    /// Per cell (row-major in y): the highest top (z, padded up) of an opaque object whose
    /// swept box covers the cell, rounded up to f32; -inf where none does.
    top: Vec<f32>,
    translucent: RayCaster,
}

impl SunColumns {
    /// The grid for rays along `dir` (unit, toward the light) over `caster`'s objects for
    /// which `opaque(id)` holds, with cells of `cell` metres (larger if the grid would
    /// exceed `max_cells`). None for a light below [`MIN_SIN_ELEVATION`].
    pub fn new(caster: &RayCaster, dir: [f64; 3], opaque: impl Fn(u32) -> bool, cell: f64, max_cells: usize) -> Option<SunColumns> {
        if !(dir[2] >= MIN_SIN_ELEVATION && cell > 0.0 && max_cells > 0) {
            return None;
        }
        let w = [dir[0] / dir[2], dir[1] / dir[2]];
        let boxes: Vec<_> = (0..caster.prims.len()).filter(|&k| opaque(caster.ids[k])).map(|k| caster.boxes[k]).collect();
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for (mn, mx) in &boxes {
            for a in 0..2 {
                let (s0, s1) = (mn[2] * w[a], mx[2] * w[a]);
                lo[a] = lo[a].min(mn[a] - s0.max(s1) - PAD);
                hi[a] = hi[a].max(mx[a] - s0.min(s1) + PAD);
            }
        }
        let translucent = caster.subset(|id| !opaque(id));
        if boxes.is_empty() {
            return Some(SunColumns { dir, w, origin: [0.0; 2], cell, per_metre: 1.0 / cell, nx: 0, ny: 0, top: vec![], translucent });
        }
        let area = (hi[0] - lo[0]) * (hi[1] - lo[1]);
        let cell = cell.max((area / max_cells as f64).sqrt() * 1.01);
        let nx = ((hi[0] - lo[0]) / cell).ceil().max(1.0) as usize;
        let ny = ((hi[1] - lo[1]) / cell).ceil().max(1.0) as usize;
        let mut grid = SunColumns { dir, w, origin: lo, cell, per_metre: 1.0 / cell, nx, ny, top: vec![f32::NEG_INFINITY; nx * ny], translucent };
        for b in &boxes {
            grid.cover(b);
        }
        Some(grid)
    }

    /// Raises the cells that the box `(mn, mx)` swept along the direction covers to its top.
    fn cover(&mut self, &(mn, mx): &([f64; 3], [f64; 3])) {
        let [wx, wy] = self.w;
        let top = up_f32(mx[2] + TOP_PAD * (1.0 + mx[2].abs()));
        // The box's points at height z have feet in its (x, y) rectangle shifted by -z w.
        let (sy0, sy1) = (mn[2] * wy, mx[2] * wy);
        let rows = self.index(mn[1] - sy0.max(sy1) - PAD, 1)..=self.index(mx[1] - sy0.min(sy1) + PAD, 1);
        for j in rows {
            // The heights whose shifted rectangle meets this row's band of y.
            let (b0, b1) = (self.origin[1] + j as f64 * self.cell - PAD, self.origin[1] + (j + 1) as f64 * self.cell + PAD);
            let (mut z0, mut z1) = (mn[2], mx[2]);
            if wy > 0.0 {
                z0 = z0.max((mn[1] - b1) / wy);
                z1 = z1.min((mx[1] - b0) / wy);
            } else if wy < 0.0 {
                z0 = z0.max((mx[1] - b0) / wy);
                z1 = z1.min((mn[1] - b1) / wy);
            } else if mn[1] > b1 || mx[1] < b0 {
                continue;
            }
            if z0 > z1 {
                continue;
            }
            let (sx0, sx1) = (z0 * wx, z1 * wx);
            let cols = self.index(mn[0] - sx0.max(sx1) - PAD, 0)..=self.index(mx[0] - sx0.min(sx1) + PAD, 0);
            let row = &mut self.top[j * self.nx..(j + 1) * self.nx];
            for t in &mut row[cols] {
                *t = t.max(top);
            }
        }
    }

    /// The cell index along axis `a` of coordinate `v`, clamped to the grid.
    fn index(&self, v: f64, a: usize) -> usize {
        let n = [self.nx, self.ny][a];
        (((v - self.origin[a]) / self.cell).floor().max(0.0) as usize).min(n - 1)
    }

    /// The direction the grid was built for.
    pub fn dir(&self) -> [f64; 3] {
        self.dir
    }

    /// True if no opaque object of the scene can stop a ray from `p` along the direction (with
    /// any near limit >= 0): its foot lies in no opaque object's swept box, or lies above the
    /// top of every one that covers it. False means only "maybe".
    pub fn clear(&self, p: [f64; 3]) -> bool {
        let f = [p[0] - p[2] * self.w[0], p[1] - p[2] * self.w[1]];
        if !(f[0].is_finite() && f[1].is_finite() && p[2].is_finite()) {
            return false;
        }
        let (u, v) = ((f[0] - self.origin[0]) * self.per_metre, (f[1] - self.origin[1]) * self.per_metre);
        if self.top.is_empty() || u < 0.0 || v < 0.0 || u >= self.nx as f64 || v >= self.ny as f64 {
            return true;
        }
        p[2] > self.top[v as usize * self.nx + u as usize] as f64
    }

    /// The scene's translucent objects: for a [`SunColumns::clear`] ray,
    /// `translucent().pass_through(..)` gives what the whole scene's would.
    pub fn translucent(&self) -> &RayCaster {
        &self.translucent
    }
}

/// The least f32 at or above `v` (finite v).
fn up_f32(v: f64) -> f32 {
    let f = v as f32;
    if (f as f64) < v {
        f.next_up()
    } else {
        f
    }
}

impl std::fmt::Debug for SunColumns {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "SunColumns({}x{} cells of {} m toward {:?})", self.nx, self.ny, self.cell, self.dir)
    }
}
