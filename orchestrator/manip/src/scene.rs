//! The environment in the planning frame: primitives with poses, each with a kind that says
//! which contacts matter, indexed by a uniform grid so a sphere query touches only nearby
//! objects whatever the size of the scene.

use crate::prim::Prim;
use agrisim_robot::Shape;
use nalgebra::{Isometry3, Point3, Vector3};

/// How an obstacle takes part in collision checking.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ObstacleKind {
    /// Must not be touched by any arm body (stems, structure, crates).
    Solid,
    /// Ignored by the planner (leaves: soft, pushed aside).
    Soft,
    /// May be touched by the hand and fingers, not by the arm links (the fruit to grasp).
    Target,
}

/// One environment object.
#[derive(Debug, Clone)]
pub struct Obstacle {
    pub name: String,
    pub shape: Shape,
    /// Primitive frame in the planning frame (cylinders and capsules along local z).
    pub pose: Isometry3<f64>,
    pub kind: ObstacleKind,
}

impl Obstacle {
    pub fn new(name: impl Into<String>, shape: Shape, pose: Isometry3<f64>, kind: ObstacleKind) -> Obstacle {
        Obstacle { name: name.into(), shape, pose, kind }
    }
}

/// The environment with its broad phase. Immutable once built: rebuild for a new scene
/// (building costs O(objects x cells they cover), microseconds for a plant row).
#[derive(Debug, Clone)]
pub struct Scene {
    objects: Vec<Obstacle>,
    prims: Vec<Prim>,
    grid: Grid,
}

#[derive(Debug, Clone)]
struct Grid {
    origin: Point3<f64>,
    cell: f64,
    dims: [usize; 3],
    /// Object indices per cell, x fastest.
    cells: Vec<Vec<u32>>,
}

/// Upper bound of cells per axis (memory and build time stay small for large scenes).
const MAX_CELLS: usize = 48;
/// Smallest cell edge (m): about an arm link's diameter.
const MIN_CELL: f64 = 0.08;

impl Scene {
    pub fn new(objects: Vec<Obstacle>) -> Scene {
        let prims: Vec<Prim> = objects.iter().map(|o| Prim::new(o.shape, o.pose)).collect();
        let mut lo = Point3::from(Vector3::repeat(f64::INFINITY));
        let mut hi = Point3::from(Vector3::repeat(f64::NEG_INFINITY));
        for (o, p) in objects.iter().zip(&prims) {
            if o.kind == ObstacleKind::Soft {
                continue;
            }
            let (a, b) = p.aabb();
            lo = lo.inf(&a);
            hi = hi.sup(&b);
        }
        let grid = if lo.x.is_finite() {
            let ext = hi - lo;
            // MAX_CELLS - 1 intervals: the far faces still fall inside the last cell.
            let cell = (ext.max() / (MAX_CELLS - 1) as f64).max(MIN_CELL);
            let dims = [0, 1, 2].map(|i| (ext[i] / cell).floor() as usize + 1);
            let mut cells = vec![Vec::new(); dims[0] * dims[1] * dims[2]];
            let mut g = Grid { origin: lo, cell, dims, cells: Vec::new() };
            for (i, (o, p)) in objects.iter().zip(&prims).enumerate() {
                if o.kind == ObstacleKind::Soft {
                    continue;
                }
                let (a, b) = p.aabb();
                if let Some((c0, c1)) = g.range(&a, &b) {
                    for z in c0[2]..=c1[2] {
                        for y in c0[1]..=c1[1] {
                            for x in c0[0]..=c1[0] {
                                cells[(z * dims[1] + y) * dims[0] + x].push(i as u32);
                            }
                        }
                    }
                }
            }
            g.cells = cells;
            g
        } else {
            Grid { origin: Point3::origin(), cell: 1.0, dims: [0; 3], cells: Vec::new() }
        };
        Scene { objects, prims, grid }
    }

    /// An empty environment.
    pub fn empty() -> Scene {
        Scene::new(Vec::new())
    }

    pub fn objects(&self) -> &[Obstacle] {
        &self.objects
    }

    pub(crate) fn prim(&self, i: usize) -> &Prim {
        &self.prims[i]
    }

    /// Calls `f` with the index of every non-soft object whose cells overlap the sphere's
    /// bounding box (possibly more than once) and returns the first index for which `f` is
    /// true (grid order, so deterministic), stopping there.
    pub(crate) fn near(&self, c: &Point3<f64>, r: f64, mut f: impl FnMut(usize) -> bool) -> Option<usize> {
        let g = &self.grid;
        let (c0, c1) = g.range(&(c - Vector3::repeat(r)), &(c + Vector3::repeat(r)))?;
        for z in c0[2]..=c1[2] {
            for y in c0[1]..=c1[1] {
                for x in c0[0]..=c1[0] {
                    for &i in &g.cells[(z * g.dims[1] + y) * g.dims[0] + x] {
                        if f(i as usize) {
                            return Some(i as usize);
                        }
                    }
                }
            }
        }
        None
    }
}

impl Grid {
    /// Cell index range covered by a box, `None` when it misses the grid.
    fn range(&self, a: &Point3<f64>, b: &Point3<f64>) -> Option<([usize; 3], [usize; 3])> {
        if self.dims.contains(&0) {
            return None;
        }
        let mut c0 = [0; 3];
        let mut c1 = [0; 3];
        for i in 0..3 {
            let lo = ((a[i] - self.origin[i]) / self.cell).floor();
            let hi = ((b[i] - self.origin[i]) / self.cell).floor();
            let n = self.dims[i] as f64;
            if hi < 0.0 || lo >= n {
                return None;
            }
            c0[i] = lo.max(0.0) as usize;
            c1[i] = hi.min(n - 1.0) as usize;
        }
        Some((c0, c1))
    }
}
