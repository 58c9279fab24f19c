//! A static 2-D occupancy map of the scene (ROS nav_msgs/OccupancyGrid layout): a cell is
//! occupied when some object's solid, cut to a height band (the robot's), overlaps the cell's
//! interior. Exact for spheres, boxes and upright cylinders; tilted cylinders use their
//! circumscribed 16-gon prism (conservative by at most 2 % of the radius).

use crate::scene::{Object, Shape};

/// Occupancy grid: cell (i, j) covers x in origin.x + [i, i+1) * resolution and y likewise;
/// `data[j * width + i]` is 0 (free) or 100 (occupied).
#[derive(Clone, Debug, PartialEq)]
pub struct OccupancyMap {
    pub resolution: f64,
    pub origin: [f64; 2],
    pub width: usize,
    pub height: usize,
    pub data: Vec<i8>,
}

pub const FREE: i8 = 0;
pub const OCCUPIED: i8 = 100;

/// Sides of the prism that stands in for a tilted cylinder.
const PRISM_SIDES: usize = 16;
const EPS: f64 = 1e-9;

impl OccupancyMap {
    /// Rasterizes every object whose solid reaches into `z_band` = (z_low, z_high) over the
    /// floor area `bounds` = [xmin, ymin, xmax, ymax]. Objects merely touching the band (the
    /// floor's top face at z = 0 with z_low = 0) do not count.
    pub fn from_objects(objects: &[Object], resolution: f64, z_band: (f64, f64), bounds: [f64; 4]) -> OccupancyMap {
        assert!(resolution > 0.0, "resolution must be positive");
        let width = (((bounds[2] - bounds[0]) / resolution) - EPS).ceil().max(1.0) as usize;
        let height = (((bounds[3] - bounds[1]) / resolution) - EPS).ceil().max(1.0) as usize;
        let mut map = OccupancyMap {
            resolution,
            origin: [bounds[0], bounds[1]],
            width,
            height,
            data: vec![FREE; width * height],
        };
        for o in objects {
            map.add(o, z_band);
        }
        map
    }

    /// Marks the footprint of one more object (e.g. a placed obstacle).
    pub fn add(&mut self, o: &Object, (z0, z1): (f64, f64)) {
        let (mn, mx) = o.aabb();
        if !(mx[2] > z0 && mn[2] < z1) {
            return;
        }
        let c = o.placement.translation;
        match o.shape {
            Shape::Sphere { radius } => {
                let dz = if c[2] < z0 {
                    z0 - c[2]
                } else if c[2] > z1 {
                    c[2] - z1
                } else {
                    0.0
                };
                let r2 = radius * radius - dz * dz;
                if r2 > 0.0 {
                    self.fill_disc(c[0], c[1], r2.sqrt());
                }
            }
            Shape::Cylinder { radius, half_height } if upright(o) => {
                if c[2] + half_height > z0 && c[2] - half_height < z1 {
                    self.fill_disc(c[0], c[1], radius);
                }
            }
            Shape::Cylinder { radius, half_height } => {
                let rc = radius / (std::f64::consts::PI / PRISM_SIDES as f64).cos();
                let ring: Vec<[f64; 2]> = (0..PRISM_SIDES)
                    .map(|k| {
                        let a = std::f64::consts::TAU * k as f64 / PRISM_SIDES as f64;
                        [rc * a.cos(), rc * a.sin()]
                    })
                    .collect();
                let mut verts = Vec::with_capacity(2 * PRISM_SIDES);
                for z in [-half_height, half_height] {
                    verts.extend(ring.iter().map(|p| o.placement.transform_point([p[0], p[1], z])));
                }
                let n = PRISM_SIDES;
                let mut edges = Vec::with_capacity(3 * n);
                for k in 0..n {
                    edges.push((k, (k + 1) % n));
                    edges.push((n + k, n + (k + 1) % n));
                    edges.push((k, n + k));
                }
                self.fill_polyhedron(&verts, &edges, z0, z1);
            }
            Shape::Box { half } => {
                let mut verts = Vec::with_capacity(8);
                for k in 0..8 {
                    let s = |b: usize| if k & b != 0 { 1.0 } else { -1.0 };
                    verts.push(o.placement.transform_point([s(1) * half[0], s(2) * half[1], s(4) * half[2]]));
                }
                let mut edges = Vec::with_capacity(12);
                for a in 0..8usize {
                    for bit in [1, 2, 4] {
                        if a & bit == 0 {
                            edges.push((a, a | bit));
                        }
                    }
                }
                self.fill_polyhedron(&verts, &edges, z0, z1);
            }
        }
    }

    /// The cell (i along x, j along y) containing (x, y), if inside the map.
    pub fn cell(&self, x: f64, y: f64) -> Option<(usize, usize)> {
        let fx = ((x - self.origin[0]) / self.resolution).floor();
        let fy = ((y - self.origin[1]) / self.resolution).floor();
        if fx < 0.0 || fy < 0.0 || fx >= self.width as f64 || fy >= self.height as f64 || fx.is_nan() || fy.is_nan() {
            return None;
        }
        Some((fx as usize, fy as usize))
    }

    /// Whether (x, y) lies in an occupied cell. Outside the map counts as occupied (the robot
    /// cannot go there).
    pub fn is_occupied_at(&self, x: f64, y: f64) -> bool {
        match self.cell(x, y) {
            Some((i, j)) => self.data[j * self.width + i] >= 50,
            None => true,
        }
    }

    /// Centre of cell (i, j) in the map frame.
    pub fn cell_center(&self, i: usize, j: usize) -> [f64; 2] {
        [self.origin[0] + (i as f64 + 0.5) * self.resolution, self.origin[1] + (j as f64 + 0.5) * self.resolution]
    }

    /// Number of occupied cells.
    pub fn occupied_count(&self) -> usize {
        self.data.iter().filter(|&&v| v >= 50).count()
    }

    /// Cell index range [lo, hi] (inclusive) covering the interval [a, b] along one axis.
    fn span(&self, a: f64, b: f64, axis: usize) -> Option<(usize, usize)> {
        let n = if axis == 0 { self.width } else { self.height };
        let lo = ((a - self.origin[axis]) / self.resolution).floor().max(0.0);
        let hi = ((b - self.origin[axis]) / self.resolution).floor().min(n as f64 - 1.0);
        (lo <= hi).then_some((lo as usize, hi as usize))
    }

    fn cell_rect(&self, i: usize, j: usize) -> [f64; 4] {
        let r = self.resolution;
        let x0 = self.origin[0] + i as f64 * r;
        let y0 = self.origin[1] + j as f64 * r;
        [x0, y0, x0 + r, y0 + r]
    }

    /// Marks every cell overlapping the axis-aligned rectangle [x0, x1] x [y0, y1].
    pub fn fill_rect(&mut self, x0: f64, y0: f64, x1: f64, y1: f64) {
        self.fill_convex(&[[x0, y0], [x1, y0], [x1, y1], [x0, y1]]);
    }

    fn fill_disc(&mut self, cx: f64, cy: f64, r: f64) {
        let (Some((i0, i1)), Some((j0, j1))) = (self.span(cx - r, cx + r, 0), self.span(cy - r, cy + r, 1)) else {
            return;
        };
        for j in j0..=j1 {
            for i in i0..=i1 {
                let [x0, y0, x1, y1] = self.cell_rect(i, j);
                // Distance from the centre to the cell rectangle; strictly inside r = overlap.
                let dx = (x0 - cx).max(0.0).max(cx - x1);
                let dy = (y0 - cy).max(0.0).max(cy - y1);
                if dx * dx + dy * dy < r * r - EPS {
                    self.data[j * self.width + i] = OCCUPIED;
                }
            }
        }
    }

    /// Clips a convex polyhedron (vertices + edges) to the z band, projects it to the floor
    /// and fills the convex polygon.
    fn fill_polyhedron(&mut self, verts: &[[f64; 3]], edges: &[(usize, usize)], z0: f64, z1: f64) {
        let mut pts: Vec<[f64; 2]> = verts.iter().filter(|v| v[2] >= z0 && v[2] <= z1).map(|v| [v[0], v[1]]).collect();
        for &(a, b) in edges {
            let (p, q) = (verts[a], verts[b]);
            for z in [z0, z1] {
                if (p[2] - z) * (q[2] - z) < 0.0 {
                    let t = (z - p[2]) / (q[2] - p[2]);
                    pts.push([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]);
                }
            }
        }
        let hull = convex_hull(pts);
        if hull.is_empty() {
            return;
        }
        self.fill_convex(&hull);
    }

    fn fill_convex(&mut self, hull: &[[f64; 2]]) {
        let (mut x0, mut y0, mut x1, mut y1) = (f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY);
        for p in hull {
            x0 = x0.min(p[0]);
            y0 = y0.min(p[1]);
            x1 = x1.max(p[0]);
            y1 = y1.max(p[1]);
        }
        let (Some((i0, i1)), Some((j0, j1))) = (self.span(x0, x1, 0), self.span(y0, y1, 1)) else { return };
        // Full-dimensional polygons must overlap a cell's interior; degenerate ones (a face
        // seen edge-on) count when they touch it.
        let degenerate = polygon_area(hull) < 1e-12;
        let tol = if degenerate { -EPS } else { EPS };
        let axes: Vec<[f64; 2]> = (0..hull.len())
            .map(|k| {
                let (p, q) = (hull[k], hull[(k + 1) % hull.len()]);
                [-(q[1] - p[1]), q[0] - p[0]]
            })
            .filter(|a| a[0] != 0.0 || a[1] != 0.0)
            .collect();
        for j in j0..=j1 {
            for i in i0..=i1 {
                let rect = self.cell_rect(i, j);
                if overlaps(hull, &axes, rect, (x0, y0, x1, y1), tol) {
                    self.data[j * self.width + i] = OCCUPIED;
                }
            }
        }
    }
}

fn upright(o: &Object) -> bool {
    let m = o.placement.matrix();
    (m[2][2].abs() - 1.0).abs() < 1e-12
}

/// Separating-axis test of a convex polygon against an axis-aligned rectangle.
fn overlaps(hull: &[[f64; 2]], axes: &[[f64; 2]], r: [f64; 4], bb: (f64, f64, f64, f64), tol: f64) -> bool {
    let (x0, y0, x1, y1) = bb;
    if x1.min(r[2]) - x0.max(r[0]) <= tol || y1.min(r[3]) - y0.max(r[1]) <= tol {
        return false;
    }
    let corners = [[r[0], r[1]], [r[2], r[1]], [r[2], r[3]], [r[0], r[3]]];
    for a in axes {
        let len = (a[0] * a[0] + a[1] * a[1]).sqrt();
        let proj = |p: &[f64; 2]| (a[0] * p[0] + a[1] * p[1]) / len;
        let (mut pa, mut pb) = (f64::INFINITY, f64::NEG_INFINITY);
        for p in hull {
            let v = proj(p);
            pa = pa.min(v);
            pb = pb.max(v);
        }
        let (mut ra, mut rb) = (f64::INFINITY, f64::NEG_INFINITY);
        for p in &corners {
            let v = proj(p);
            ra = ra.min(v);
            rb = rb.max(v);
        }
        if pb.min(rb) - pa.max(ra) <= tol {
            return false;
        }
    }
    true
}

fn polygon_area(p: &[[f64; 2]]) -> f64 {
    let n = p.len();
    if n < 3 {
        return 0.0;
    }
    let mut a = 0.0;
    for k in 0..n {
        let (u, v) = (p[k], p[(k + 1) % n]);
        a += u[0] * v[1] - v[0] * u[1];
    }
    0.5 * a.abs()
}

/// Andrew's monotone chain; returns the hull counter-clockwise without repeated points.
fn convex_hull(mut pts: Vec<[f64; 2]>) -> Vec<[f64; 2]> {
    pts.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    pts.dedup();
    if pts.len() < 3 {
        return pts;
    }
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
    let mut lower: Vec<[f64; 2]> = Vec::new();
    for &p in &pts {
        while lower.len() >= 2 && cross(lower[lower.len() - 2], lower[lower.len() - 1], p) <= 0.0 {
            lower.pop();
        }
        lower.push(p);
    }
    let mut upper: Vec<[f64; 2]> = Vec::new();
    for &p in pts.iter().rev() {
        while upper.len() >= 2 && cross(upper[upper.len() - 2], upper[upper.len() - 1], p) <= 0.0 {
            upper.pop();
        }
        upper.push(p);
    }
    lower.pop();
    upper.pop();
    lower.extend(upper);
    lower
}
