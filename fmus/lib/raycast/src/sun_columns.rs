//! Shadow rays that no opaque object can stop, told without a traversal.
//!
//! All shadow rays toward one light direction are parallel. Seen along that direction a ray
//! is a point (its foot: where it crosses z = 0), and an object covers the region its
//! bounding box sweeps out (a hexagon). A grid over that view keeps, per cell, the highest
//! top of the opaque objects covering it. A ray leaving a point above that height only
//! climbs (the light is above the horizon), so it meets none of them: it needs only the
//! translucent objects (glass, film), a tree a fraction of the scene's size. The grid is
//! conservative, so every other ray takes the full traversal and the answers stay exact.
//!
//! Each cell also lists the opaque objects covering it, highest top first. A ray from a
//! point in the cell can meet only those whose top is above the point, so testing them one
//! by one tells exactly whether something opaque stops it, without a traversal: a few
//! primitive tests where the scene's tree took a walk from its root. Lists cost memory, so a
//! grid whose lists would exceed [`ENTRIES_PER_CELL`] times its cell limit keeps the tops
//! alone.

use crate::RayCaster;

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

/// Most (cell, object) entries in the lists of one grid (8 bytes each), per cell the grid
/// may have.
const ENTRIES_PER_CELL: usize = 4;

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
    /// Per cell, the opaque objects whose swept box covers it (empty when they would be too
    /// long, [`ENTRIES_PER_CELL`]).
    lists: Lists,
    /// Primitive count of the scene the lists index (a check against another scene), and
    /// which of its primitives are opaque (one bit each).
    scene_prims: usize,
    opaque: Vec<u64>,
    translucent: RayCaster,
}

/// What a grid tells of one shadow ray ([`SunColumns::occluder`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shadow {
    /// No opaque object of the scene stops it: the glass and film alone answer.
    Clear,
    /// This opaque primitive of the scene (an index, as [`Occluders`](crate::Occluders) keep) stops it.
    Blocked(u32),
    /// The grid cannot tell (it keeps no lists, was built for another scene, or the near
    /// limit is negative): the whole scene must answer.
    Unknown,
}

impl SunColumns {
    /// The grid for rays along `dir` (unit, toward the light) over `caster`'s objects for
    /// which `opaque(id)` holds, with cells of `cell` metres (larger if the grid would
    /// exceed `max_cells`). None for a light below [`MIN_SIN_ELEVATION`].
    pub fn new(
        caster: &RayCaster,
        dir: [f64; 3],
        opaque: impl Fn(u32) -> bool,
        cell: f64,
        max_cells: usize,
    ) -> Option<SunColumns> {
        if !(dir[2] >= MIN_SIN_ELEVATION && cell > 0.0 && max_cells > 0) {
            return None;
        }
        let w = [dir[0] / dir[2], dir[1] / dir[2]];
        let opaque_prims: Vec<usize> = (0..caster.prims.len()).filter(|&k| opaque(caster.ids[k])).collect();
        let boxes: Vec<_> = opaque_prims.iter().map(|&k| caster.boxes[k]).collect();
        let mut bits = vec![0u64; caster.prims.len().div_ceil(64)];
        opaque_prims.iter().for_each(|&k| bits[k / 64] |= 1 << (k % 64));
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
            return Some(SunColumns {
                dir,
                w,
                origin: [0.0; 2],
                cell,
                per_metre: 1.0 / cell,
                nx: 0,
                ny: 0,
                top: vec![],
                lists: Lists::default(),
                scene_prims: caster.prims.len(),
                opaque: bits,
                translucent,
            });
        }
        let area = (hi[0] - lo[0]) * (hi[1] - lo[1]);
        let cell = cell.max((area / max_cells as f64).sqrt() * 1.01);
        let nx = ((hi[0] - lo[0]) / cell).ceil().max(1.0) as usize;
        let ny = ((hi[1] - lo[1]) / cell).ceil().max(1.0) as usize;
        let mut grid = SunColumns {
            dir,
            w,
            origin: lo,
            cell,
            per_metre: 1.0 / cell,
            nx,
            ny,
            top: vec![f32::NEG_INFINITY; nx * ny],
            lists: Lists::default(),
            scene_prims: caster.prims.len(),
            opaque: bits,
            translucent,
        };
        match grid.lists(caster, &opaque_prims, ENTRIES_PER_CELL * max_cells) {
            Some(lists) => {
                // A cell's top is its list's first.
                for (c, top) in grid.top.iter_mut().enumerate() {
                    if lists.start[c] < lists.start[c + 1] {
                        *top = lists.entries[lists.start[c] as usize].0;
                    }
                }
                grid.lists = lists;
            }
            None => {
                let mut cells = vec![];
                for b in &boxes {
                    let top = padded_top(b.1[2]);
                    cells.clear();
                    grid.cells(b, |c| cells.push(c));
                    for &c in &cells {
                        grid.top[c] = grid.top[c].max(top);
                    }
                }
            }
        }
        Some(grid)
    }

    /// The lists of the primitives `prims` of `caster`, if they hold at most `max_entries`.
    fn lists(&self, caster: &RayCaster, prims: &[usize], max_entries: usize) -> Option<Lists> {
        let n = self.nx * self.ny;
        let mut count = vec![0u32; n];
        // Each primitive's cells, found once: `covered[first[i] .. first[i + 1]]`.
        let mut covered: Vec<u32> = vec![];
        let mut first = Vec::with_capacity(prims.len() + 1);
        first.push(0usize);
        for &k in prims {
            self.cells(&caster.boxes[k], |c| {
                count[c] += 1;
                covered.push(c as u32);
            });
            if covered.len() > max_entries || covered.len() >= u32::MAX as usize {
                return None;
            }
            first.push(covered.len());
        }
        let mut start = Vec::with_capacity(n + 1);
        start.push(0u32);
        for &c in &count {
            start.push(start[start.len() - 1] + c);
        }
        // Primitives taken highest top first, so each cell's list comes out in that order.
        let tops: Vec<f32> = prims.iter().map(|&k| padded_top(caster.boxes[k].1[2])).collect();
        let mut order: Vec<usize> = (0..prims.len()).collect();
        order.sort_by(|&a, &b| tops[b].total_cmp(&tops[a]).then(a.cmp(&b)));
        let mut at = start[..n].to_vec();
        let mut list = vec![(0f32, 0u32); covered.len()];
        for i in order {
            for &c in &covered[first[i]..first[i + 1]] {
                list[at[c as usize] as usize] = (tops[i], prims[i] as u32);
                at[c as usize] += 1;
            }
        }
        Some(Lists { start, entries: list })
    }

    /// Calls `f` with every cell that the box `(mn, mx)` swept along the direction covers.
    fn cells(&self, &(mn, mx): &([f64; 3], [f64; 3]), mut f: impl FnMut(usize)) {
        let [wx, wy] = self.w;
        // The box's points at height z have feet in its (x, y) rectangle shifted by -z w.
        let (sy0, sy1) = (mn[2] * wy, mx[2] * wy);
        let rows = self.index(mn[1] - sy0.max(sy1) - PAD, 1)..=self.index(mx[1] - sy0.min(sy1) + PAD, 1);
        for j in rows {
            // The heights whose shifted rectangle meets this row's band of y.
            let (b0, b1) =
                (self.origin[1] + j as f64 * self.cell - PAD, self.origin[1] + (j + 1) as f64 * self.cell + PAD);
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
            cols.for_each(|i| f(j * self.nx + i));
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
        match self.foot_cell(p) {
            Foot::Outside => true,
            Foot::Cell(c) => p[2] > self.top[c] as f64,
            Foot::NotFinite => false,
        }
    }

    /// Whether an opaque object of `scene` stops the ray from `p` along the direction with
    /// `t` in `[tmin, tmax]` (`tmin >= 0`), exactly as the scene's own shadow query would
    /// decide it: the objects listed for the ray's cell whose top is above `p` are tested
    /// one by one with the same primitive test, `hint` first (an object an earlier answer of
    /// this grid named: neighbouring points are often shaded by the same leaf).
    /// [`Shadow::Unknown`] for a grid without lists or a `scene` it was not built from.
    pub fn occluder(&self, scene: &RayCaster, p: [f64; 3], tmin: f64, tmax: f64, hint: Option<u32>) -> Shadow {
        if scene.prims.len() != self.scene_prims || !(tmin >= 0.0) {
            return Shadow::Unknown;
        }
        let c = match self.foot_cell(p) {
            Foot::Outside => return Shadow::Clear,
            Foot::Cell(c) if p[2] > self.top[c] as f64 => return Shadow::Clear,
            Foot::Cell(c) if !self.lists.start.is_empty() => c,
            _ => return Shadow::Unknown,
        };
        let stops = |k: u32| scene.prims[k as usize].along(self.dir).intersect(p, tmin, tmax).is_some();
        // An opaque object that stops the ray decides it, listed here or not.
        let hint =
            hint.filter(|&k| (k as usize) < self.scene_prims && self.opaque[k as usize / 64] >> (k % 64) & 1 == 1);
        if let Some(k) = hint.filter(|&k| stops(k)) {
            return Shadow::Blocked(k);
        }
        match self.lists.above(c, p[2]).find(|&k| Some(k) != hint && stops(k)) {
            Some(k) => Shadow::Blocked(k),
            None => Shadow::Clear,
        }
    }

    /// The cell of `p`'s foot.
    fn foot_cell(&self, p: [f64; 3]) -> Foot {
        let f = [p[0] - p[2] * self.w[0], p[1] - p[2] * self.w[1]];
        if !(f[0].is_finite() && f[1].is_finite() && p[2].is_finite()) {
            return Foot::NotFinite;
        }
        let (u, v) = ((f[0] - self.origin[0]) * self.per_metre, (f[1] - self.origin[1]) * self.per_metre);
        if self.top.is_empty() || u < 0.0 || v < 0.0 || u >= self.nx as f64 || v >= self.ny as f64 {
            return Foot::Outside;
        }
        Foot::Cell(v as usize * self.nx + u as usize)
    }

    /// The scene's translucent objects: for a [`SunColumns::clear`] ray,
    /// `translucent().pass_through(..)` gives what the whole scene's would.
    pub fn translucent(&self) -> &RayCaster {
        &self.translucent
    }
}

/// Per cell c, primitives (indices into the scene's) highest top first,
/// `entries[start[c] .. start[c + 1]]` as (padded top, primitive): side by side, one cache
/// line serves both. All empty for none.
#[derive(Clone, Default)]
struct Lists {
    start: Vec<u32>,
    entries: Vec<(f32, u32)>,
}

impl Lists {
    /// The primitives of cell `c` whose top is at or above `z`: listed highest top first, the
    /// rest lie wholly below a ray climbing from `z`.
    fn above(&self, c: usize, z: f64) -> impl Iterator<Item = u32> + '_ {
        let (a, b) = (self.start[c] as usize, self.start[c + 1] as usize);
        self.entries[a..b].iter().take_while(move |&&(top, _)| z <= top as f64).map(|&(_, k)| k)
    }
}

/// Where a point's foot lies.
enum Foot {
    /// Outside the grid: no opaque object's swept box covers it.
    Outside,
    Cell(usize),
    NotFinite,
}

/// An object's top `z` padded up for rounding ([`TOP_PAD`]), as an f32 at or above it.
fn padded_top(z: f64) -> f32 {
    up_f32(z + TOP_PAD * (1.0 + z.abs()))
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
        write!(
            f,
            "SunColumns({}x{} cells of {} m toward {:?}, {} listed)",
            self.nx,
            self.ny,
            self.cell,
            self.dir,
            self.lists.entries.len()
        )
    }
}
