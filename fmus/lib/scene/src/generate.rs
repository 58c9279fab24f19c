//! The deterministic scene generator: configuration + seed -> objects and layout.
//!
//! Every random choice draws from a stream keyed by (seed, what, where) — e.g. (seed, row,
//! plant) — so the scene is a pure function of its inputs, and changing one part (adding an
//! obstacle) leaves every other part where it was. Ids are dense from 0 in generation order:
//! hall, rows (structure then plants), placed obstacles, random obstacles, aisle blocks.
//!
//! Names: `floor`, `wall_xmin|xmax|ymin|ymax`, `roof`; per row `row{r}/post{k}`,
//! `row{r}/gutter`, `row{r}/pipe{0|1}`; per plant `row{r}/plant{p}/stem`, `.../leaf{k}`,
//! `.../truss{t}`, `.../fruit{t}_{f}` (fruit f of truss t); `obstacle{i}` (placed),
//! `random_obstacle{i}`, `block{aisle}`.

use crate::config::GreenhouseConfig;
use crate::layout::Layout;
use crate::scene::{quat_axis_angle, quat_mul, Kind, Object, Placement, Shape};
use agrisim_math::Rng;
use std::f64::consts::{FRAC_PI_2, PI};

/// A generated greenhouse: the objects and the layout they were built from.
#[derive(Clone, Debug, PartialEq)]
pub struct Greenhouse {
    pub objects: Vec<Object>,
    pub layout: Layout,
}

impl Greenhouse {
    /// The object with this id (ids are dense, so this is an index).
    pub fn object(&self, id: u32) -> Option<&Object> {
        self.objects.get(id as usize)
    }
}

// Stream labels, so sub-streams of different purposes never coincide.
const PLANT: u64 = 1;
const OBSTACLE: u64 = 2;
/// The shape of one compound leaf (a stream of its own, so the plant's stream draws what it
/// always drew and the trusses and fruit stay where they were).
const LEAFLET: u64 = 3;

/// Thickness of the walls, floor slab and roof [m].
const SLAB: f64 = 0.2;
/// Random obstacles keep this far from the aisle ends and from each other along x [m]
/// (robot length 1.2 m + margin), so that one never closes an aisle together with another.
const OBSTACLE_GAP: f64 = 1.6;

/// Generates the scene for a configuration (assumed valid, see [`GreenhouseConfig::validate`])
/// and a seed. Same inputs -> identical output, on every platform.
pub fn generate(cfg: &GreenhouseConfig, seed: u64) -> Greenhouse {
    let layout = Layout::from_config(cfg);
    let mut b = Builder { objects: Vec::with_capacity(estimate(cfg)) };
    if cfg.walls {
        hall(&mut b, cfg);
    }
    for row in &layout.rows {
        row_structure(&mut b, cfg, row.index, row.y, row.x_start, row.x_end);
        let n = (cfg.row_length / cfg.plant_spacing).floor() as usize;
        for p in 0..n {
            let x = row.x_start + (p as f64 + 0.5) * cfg.plant_spacing;
            plant(&mut b, cfg, seed, row.index, p, x, row.y);
        }
    }
    for (i, o) in cfg.obstacles.iter().enumerate() {
        let h = [0.5 * o.size_x, 0.5 * o.size_y, 0.5 * o.height];
        b.push(format!("obstacle{i}"), Kind::Obstacle, Shape::Box { half: h }, Placement::at(o.x, o.y, h[2]));
    }
    random_obstacles(&mut b, cfg, seed, &layout);
    for &a in &cfg.block_aisles {
        let aisle = &layout.aisles[a];
        // Reaches the row lines on both sides, so nothing can slip past it.
        let half = [0.15, 0.5 * (aisle.width + cfg.row_width), 0.5];
        let x = 0.5 * (aisle.x_start + aisle.x_end);
        b.push(format!("block{a}"), Kind::Obstacle, Shape::Box { half }, Placement::at(x, aisle.y, half[2]));
    }
    Greenhouse { objects: b.objects, layout }
}

struct Builder {
    objects: Vec<Object>,
}

impl Builder {
    fn push(&mut self, name: String, kind: Kind, shape: Shape, placement: Placement) {
        let id = self.objects.len() as u32;
        self.objects.push(Object { id, name, kind, shape, placement });
    }
}

fn estimate(cfg: &GreenhouseConfig) -> usize {
    let plants = (cfg.row_length / cfg.plant_spacing) as usize;
    let per_plant = 1 + cfg.leaf_density * (2 + 2 * MAX_PAIRS) + cfg.trusses_per_plant * (1 + 2 * cfg.fruit_per_truss);
    let per_row = plants * per_plant + (cfg.row_length / cfg.post_spacing) as usize + 4;
    cfg.rows * per_row + 8 + cfg.obstacles.len() + cfg.random_obstacles + cfg.block_aisles.len()
}

/// Floor slab (top at z = 0), four walls outside `bounds`, roof at `height`.
fn hall(b: &mut Builder, cfg: &GreenhouseConfig) {
    let (l, w, h, t) = (cfg.length, cfg.width, cfg.height, SLAB);
    let bx = |hx: f64, hy: f64, hz: f64| Shape::Box { half: [hx, hy, hz] };
    b.push(
        "floor".into(),
        Kind::Floor,
        bx(0.5 * l + t, 0.5 * w + t, 0.5 * t),
        Placement::at(0.5 * l, 0.5 * w, -0.5 * t),
    );
    b.push(
        "wall_xmin".into(),
        Kind::Wall,
        bx(0.5 * t, 0.5 * w + t, 0.5 * h),
        Placement::at(-0.5 * t, 0.5 * w, 0.5 * h),
    );
    b.push(
        "wall_xmax".into(),
        Kind::Wall,
        bx(0.5 * t, 0.5 * w + t, 0.5 * h),
        Placement::at(l + 0.5 * t, 0.5 * w, 0.5 * h),
    );
    b.push("wall_ymin".into(), Kind::Wall, bx(0.5 * l, 0.5 * t, 0.5 * h), Placement::at(0.5 * l, -0.5 * t, 0.5 * h));
    b.push("wall_ymax".into(), Kind::Wall, bx(0.5 * l, 0.5 * t, 0.5 * h), Placement::at(0.5 * l, w + 0.5 * t, 0.5 * h));
    b.push(
        "roof".into(),
        Kind::Roof,
        bx(0.5 * l + t, 0.5 * w + t, 0.5 * t),
        Placement::at(0.5 * l, 0.5 * w, h + 0.5 * t),
    );
}

/// Posts in the row line, the overhead gutter, and two heating pipes under the row.
fn row_structure(b: &mut Builder, cfg: &GreenhouseConfig, r: usize, y: f64, x0: f64, x1: f64) {
    let len = x1 - x0;
    let xm = 0.5 * (x0 + x1);
    if cfg.posts {
        let top = if cfg.gutters { cfg.gutter_height } else { cfg.plant_height + 0.5 };
        // Inside [x0, x1], so the headland stays clear.
        let usable = (len - 2.0 * cfg.post_radius).max(0.0);
        let n = (usable / cfg.post_spacing).floor() as usize;
        for k in 0..=n {
            let x = x0 + cfg.post_radius + k as f64 * cfg.post_spacing;
            let shape = Shape::Cylinder { radius: cfg.post_radius, half_height: 0.5 * top };
            b.push(format!("row{r}/post{k}"), Kind::Post, shape, Placement::at(x, y, 0.5 * top));
        }
    }
    if cfg.gutters {
        let half = [0.5 * len, (0.15f64).min(0.5 * cfg.row_width), 0.08];
        b.push(format!("row{r}/gutter"), Kind::Gutter, Shape::Box { half }, Placement::at(xm, y, cfg.gutter_height));
    }
    if cfg.heating_pipes {
        // Local z -> map x: +90 deg about y.
        let along_x = quat_axis_angle([0.0, 1.0, 0.0], FRAC_PI_2);
        let z = (0.1f64).max(cfg.pipe_radius);
        for (k, s) in [(0, -1.0), (1, 1.0)] {
            let shape = Shape::Cylinder { radius: cfg.pipe_radius, half_height: 0.5 * len };
            let pl = Placement { translation: [xm, y + s * cfg.pipe_offset, z], rotation: along_x };
            b.push(format!("row{r}/pipe{k}"), Kind::HeatingPipe, shape, pl);
        }
    }
}

/// One tomato plant: a stem, leaf blobs, trusses alternating sides with fruit hanging below.
/// Everything stays inside the row envelope (|y - row y| <= row_width / 2).
fn plant(b: &mut Builder, cfg: &GreenhouseConfig, seed: u64, r: usize, p: usize, x: f64, y: f64) {
    let mut rng = Rng::stream(seed, &[PLANT, r as u64, p as u64]);
    let half_env = 0.5 * cfg.row_width;
    let h = cfg.plant_height;
    let sx = x + rng.range(-0.02, 0.02) * cfg.plant_spacing;
    let sy = y + rng.range(-1.0, 1.0) * (half_env - cfg.stem_radius).min(0.02);
    let stem = Shape::Cylinder { radius: cfg.stem_radius, half_height: 0.5 * h };
    b.push(format!("row{r}/plant{p}/stem"), Kind::Stem, stem, Placement::at(sx, sy, 0.5 * h));

    // Leaves: compound leaves (see [`compound_leaf`]), evenly layered up the stem, random yaw
    // and droop, alternating sides, each inside the box the single leaf blob used to fill.
    let nl = cfg.leaf_density;
    for k in 0..nl {
        let l = rng.range(0.8, 1.0) * cfg.leaf_size[0].min(cfg.row_width);
        let wd = rng.range(0.8, 1.0) * cfg.leaf_size[1].min(cfg.row_width);
        let half = [0.5 * l, 0.5 * wd, 0.005];
        let side = if k % 2 == 0 { 1.0 } else { -1.0 };
        let z = 0.3 + (k as f64 + rng.range(0.2, 0.8)) / nl as f64 * (h - 0.4);
        let yaw = side * FRAC_PI_2 + rng.range(-0.6, 0.6);
        let droop = rng.range(-0.35, 0.35);
        // Roll about the leaf's length (local x), then yaw.
        let rot = quat_mul(quat_axis_angle([0.0, 0.0, 1.0], yaw), quat_axis_angle([1.0, 0.0, 0.0], droop));
        let mut obj = Placement { translation: [sx, y, z], rotation: rot };
        let probe = Object { id: 0, name: String::new(), kind: Kind::Leaf, shape: Shape::Box { half }, placement: obj };
        let (lo, hi) = probe.aabb();
        let (ext_x, ext_y) = (0.5 * (hi[0] - lo[0]), 0.5 * (hi[1] - lo[1]));
        let room = (half_env - ext_y).max(0.0);
        // The leaf's base (local -x end) at the stem: its centre half a length out along the
        // leaf's axis, kept in the row envelope. (The two draws that used to place the blob
        // are still drawn, so everything drawn after them is where it was.)
        let (_, _) = (rng.range(0.3, 1.0), rng.range(-0.25, 0.25));
        let axis = probe.placement.transform_point([0.5 * l, 0.0, 0.0]);
        let want_y = sy + (axis[1] - y);
        obj.translation[1] = want_y.clamp(y - room, y + room);
        // Within the row's x range too (the headland stays clear).
        let lx = x - (p as f64 + 0.5) * cfg.plant_spacing + ext_x + 1e-6;
        let hx = lx - 2.0 * ext_x + cfg.row_length - 2e-6;
        let want = axis[0];
        obj.translation[0] = if lx <= hx { want.clamp(lx, hx) } else { 0.5 * (lx + hx) };
        let mut shape_rng = Rng::stream(seed, &[LEAFLET, r as u64, p as u64, k as u64]);
        // 3 or 4 pairs of leaflets by position, not by seed: a scene's object count (and so
        // its ids) is the same for every seed.
        let pairs = 3 + (k + p) % 2;
        for (j, (kind_name, shape, local)) in compound_leaf(half, pairs, &mut shape_rng).into_iter().enumerate() {
            let pl = Placement {
                translation: obj.transform_point(local.translation),
                rotation: quat_mul(rot, local.rotation),
            };
            let name = match kind_name {
                LeafPart::Rachis => format!("row{r}/plant{p}/leaf{k}"),
                LeafPart::Leaflet => format!("row{r}/plant{p}/leaf{k}_{j}"),
            };
            b.push(name, Kind::Leaf, shape, pl);
        }
    }

    // Trusses: levels spread over the fruit band, alternate sides, facing the aisles.
    let nt = cfg.trusses_per_plant;
    let [f_lo, f_hi] = cfg.fruit_height;
    let reach = (half_env - 0.02).max(0.05); // how far from the row line a truss extends
    let mut placed: Vec<([f64; 3], f64)> = vec![];
    for t in 0..nt {
        let side = if t % 2 == 0 { 1.0 } else { -1.0 };
        let zt = f_lo + 0.08 + (t as f64 + rng.range(0.3, 0.7)) / nt as f64 * (f_hi - f_lo);
        let yaw = side * FRAC_PI_2 + rng.range(-0.35, 0.35);
        let (sy_, cy_) = yaw.sin_cos();
        let len = 0.8 * reach;
        // Local z -> horizontal direction (cos yaw, sin yaw, 0): tip down to +x, then yaw.
        let rot = quat_mul(quat_axis_angle([0.0, 0.0, 1.0], yaw), quat_axis_angle([0.0, 1.0, 0.0], FRAC_PI_2));
        let c = [sx + cy_ * 0.5 * len, sy + sy_ * 0.5 * len, zt];
        let truss = Shape::Cylinder { radius: 0.004, half_height: 0.5 * len };
        b.push(format!("row{r}/plant{p}/truss{t}"), Kind::Truss, truss, Placement { translation: c, rotation: rot });
        let nf = cfg.fruit_per_truss;
        for f in 0..nf {
            let [k_lo, k_hi] = cfg.fruit_radius_limits;
            let radius = cfg.fruit_radius * (1.0 + cfg.fruit_radius_spread * rng.scene_normal()).clamp(k_lo, k_hi);
            let d = len * (0.35 + 0.65 * (f as f64 + 0.5) / nf.max(1) as f64);
            let mut fx = sx + cy_ * d + rng.range(-0.02, 0.02);
            let mut fy = sy + sy_ * d + rng.range(-0.02, 0.02);
            let fz = (zt - radius - rng.range(0.0, 0.05)).clamp(f_lo, f_hi);
            // Keep the fruit inside the envelope.
            let lim = (half_env - radius).max(0.0);
            fy = fy.clamp(y - lim, y + lim);
            let x_row = x - (p as f64 + 0.5) * cfg.plant_spacing;
            let (xl, xh) = (
                (x - 0.5 * cfg.plant_spacing).max(x_row + radius),
                (x + 0.5 * cfg.plant_spacing).min(x_row + cfg.row_length - radius),
            );
            fx = if xl <= xh { fx.clamp(xl, xh) } else { x };
            let stage = rng.weighted(&cfg.ripeness) as u8 + 1;
            // Fruit of a truss hang at different levels instead of interpenetrating: a fruit
            // that would overlap one already on this plant hangs just below it.
            // (Rarely the bottom of the band is reached: then just above the one it touches,
            // still under the truss; failing that, where it was.)
            let fz = hang_clear(&placed, [fx, fy, fz], radius, -1.0, f_lo, zt - radius)
                .or_else(|| hang_clear(&placed, [fx, fy, fz], radius, 1.0, f_lo, zt - radius))
                .unwrap_or(fz);
            placed.push(([fx, fy, fz], radius));
            b.push(
                format!("row{r}/plant{p}/fruit{t}_{f}"),
                Kind::Fruit { ripeness: stage },
                Shape::Sphere { radius },
                Placement::at(fx, fy, fz),
            );
            // The pedicel: from the top of the fruit's collider (where the calyx sits, see
            // the camera's crop module) up to the nearest point of the truss.
            let along = ((fx - sx) * cy_ + (fy - sy) * sy_).clamp(0.0, len);
            let top = [fx, fy, fz + radius];
            let mut q = [sx + cy_ * along, sy + sy_ * along, zt];
            // (A fruit right at the truss still gets one, so the count never depends on the
            // seed.)
            q[2] = q[2].max(top[2] + 2.0 * PEDICEL_RADIUS);
            if let Some((shape, pl)) = rod(top, q, PEDICEL_RADIUS) {
                b.push(format!("row{r}/plant{p}/pedicel{t}_{f}"), Kind::Truss, shape, pl);
            }
        }
    }
}

/// Radius of a pedicel [m] (3-4 mm thick: our reading of photographs). SEINet's "Solanum
/// lycopersicum" gives pedicels 1-1.2 cm long; ours run from the fruit to the truss, as long
/// as the fruit hangs below it (0-5 cm, more where fruit were moved apart).
pub const PEDICEL_RADIUS: f64 = 0.002;

/// A cylinder of `radius` from `a` to `b` (None if they are less than a radius apart).
fn rod(a: [f64; 3], b: [f64; 3], radius: f64) -> Option<(Shape, Placement)> {
    let v = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if len < radius {
        return None;
    }
    let u = [v[0] / len, v[1] / len, v[2] / len];
    // The rotation taking local z onto u: about z x u by acos(u_z).
    let axis = [-u[1], u[0], 0.0];
    let s = (axis[0] * axis[0] + axis[1] * axis[1]).sqrt();
    let rotation = if s < 1e-12 {
        if u[2] > 0.0 {
            [0.0, 0.0, 0.0, 1.0]
        } else {
            [1.0, 0.0, 0.0, 0.0]
        }
    } else {
        quat_axis_angle([axis[0] / s, axis[1] / s, 0.0], u[2].clamp(-1.0, 1.0).acos())
    };
    let translation = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), 0.5 * (a[2] + b[2])];
    Some((Shape::Cylinder { radius, half_height: 0.5 * len }, Placement { translation, rotation }))
}

/// What a part of a compound leaf is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LeafPart {
    /// Petiole and rachis, one rod from the stem to the terminal leaflet.
    Rachis,
    Leaflet,
}

/// Most pairs of lateral leaflets of a compound leaf.
pub const MAX_PAIRS: usize = 4;
/// Half thickness of a leaflet [m] (a tomato leaflet is 0.2-0.3 mm thick; 2 mm keeps rays
/// and contacts robust).
pub const LEAFLET_HALF_THICKNESS: f64 = 0.001;
/// Radius of the petiole and rachis [m] (4-5 mm thick at the base).
pub const RACHIS_RADIUS: f64 = 0.0025;

/// One tomato leaf inside the box of half extents `half` (local x from the base at -x to the
/// tip at +x, leaf blade in the xy plane): the petiole and rachis, a terminal leaflet and 3 or
/// 4 (`pairs`) pairs of lateral leaflets (7 or 9 leaflets), each a thin box whose outline (ovate,
/// serrate) the camera cuts out of it. Parts in the leaf's frame.
///
/// Morphology: SEINet, Arizona flora, "Solanum lycopersicum" (leaves irregularly pinnately
/// compound, 20-40 cm long, 7-10 cm wide; primary lateral leaflets 3-4(-5) pairs, 2-5 cm long,
/// 0.8-2.5 cm wide, ovate to elliptic, apex acute-attenuate, margin dentate-crenate; terminal
/// leaflet usually larger, 3-6 x 1.5-3 cm; petiole 1.2-6 cm) and Britton and Brown,
/// Illustrated Flora (1913), "Lycopersicon": "the larger [leaflets] 7-9, ovate or
/// ovate-lanceolate, ... dentate". Small interstitial leaflets are left out. Leaflets are
/// half as long as wide (the ratios above), the terminal one 0.3 of the leaf, the bare petiole
/// 0.2 of it; laterals stand 40-60 deg off the rachis toward the tip and grow toward the tip
/// (our reading of photographs).
pub fn compound_leaf(half: [f64; 3], pairs: usize, rng: &mut Rng) -> Vec<(LeafPart, Shape, Placement)> {
    let (hx, hy) = (half[0], half[1]);
    let len = 2.0 * hx;
    let pairs = pairs.clamp(1, MAX_PAIRS);
    let t_len = (0.3 * len).min(2.0 * 2.0 * hy * 0.95);
    let t_wid = 0.5 * t_len;
    let mut parts = Vec::with_capacity(2 + 2 * pairs);
    // Petiole + rachis to the terminal leaflet's base, along local x (local z -> x).
    let along_x = quat_axis_angle([0.0, 1.0, 0.0], FRAC_PI_2);
    let r_end = hx - t_len;
    parts.push((
        LeafPart::Rachis,
        Shape::Cylinder { radius: RACHIS_RADIUS.min(half[2]), half_height: 0.5 * (r_end + hx) },
        Placement { translation: [0.5 * (r_end - hx), 0.0, 0.0], rotation: along_x },
    ));
    parts.push((
        LeafPart::Leaflet,
        Shape::Box { half: [0.5 * t_len, 0.5 * t_wid, LEAFLET_HALF_THICKNESS] },
        Placement::at(hx - 0.5 * t_len, 0.0, 0.0),
    ));
    let gap = RACHIS_RADIUS;
    let x_a = -hx + 0.2 * len;
    for i in 0..pairs {
        // Nearer the tip: later and larger.
        let grow = 0.75 + 0.25 * (i + 1) as f64 / pairs as f64;
        for side in [1.0, -1.0] {
            let alpha = rng.range(40f64.to_radians(), 60f64.to_radians());
            let (sa, ca) = alpha.sin_cos();
            // Longest leaflet (width half its length) whose box stays within the leaf's width.
            let fit = (hy - gap * sa) / (sa + 0.25 * ca);
            let l_len = (0.28 * len * grow).min(fit) * rng.range(0.9, 1.0);
            let l_wid = 0.5 * l_len;
            let fwd = (gap + l_len) * ca + 0.5 * l_wid * sa;
            let back = 0.5 * l_wid * sa;
            let x_b = (hx - 0.6 * t_len - fwd).max(x_a);
            let x0 = if pairs > 1 { x_a + (x_b - x_a) * i as f64 / (pairs - 1) as f64 } else { x_a };
            let x0 = x0.clamp(-hx + back, hx - fwd);
            let d = gap + 0.5 * l_len;
            // Left leaflets just above the blade's mid-plane, right ones just below: no two
            // overlap in one plane.
            let z = side * 2.0 * LEAFLET_HALF_THICKNESS;
            parts.push((
                LeafPart::Leaflet,
                Shape::Box { half: [0.5 * l_len, 0.5 * l_wid, LEAFLET_HALF_THICKNESS] },
                Placement::axis_angle([x0 + d * ca, side * d * sa, z], [0.0, 0.0, 1.0], side * alpha),
            ));
        }
    }
    parts
}

/// Gap kept between neighbouring fruit [m].
const FRUIT_GAP: f64 = 0.003;

/// The height nearest `c[2]` in direction `dir` (-1 down, +1 up) where a fruit of radius `r`
/// at (c[0], c[1]) overlaps none of `placed` (moving past each one it would touch,
/// repeatedly); `None` if that leaves [`z_min`, `z_max`].
fn hang_clear(placed: &[([f64; 3], f64)], c: [f64; 3], r: f64, dir: f64, z_min: f64, z_max: f64) -> Option<f64> {
    let mut z = c[2];
    for _ in 0..=placed.len() {
        let mut moved = false;
        for &(q, rq) in placed {
            let need = r + rq + FRUIT_GAP;
            let h2 = (q[0] - c[0]).powi(2) + (q[1] - c[1]).powi(2);
            if h2 >= need * need {
                continue;
            }
            let v = (need * need - h2).sqrt();
            if (z - q[2]).abs() < v {
                z = q[2] + dir * v;
                moved = true;
            }
        }
        if !moved {
            break;
        }
    }
    (z >= z_min && z <= z_max.max(c[2])).then_some(z)
}

/// Random box obstacles in the active aisles, each touching one row envelope so that the
/// rest of the aisle (at least `min_passage`) stays free, and at least `OBSTACLE_GAP` from
/// each other along x so no two of them close an aisle together. A draw that does not fit
/// after 200 attempts is skipped.
fn random_obstacles(b: &mut Builder, cfg: &GreenhouseConfig, seed: u64, layout: &Layout) {
    if layout.aisles.is_empty() {
        return;
    }
    // Footprints already in each aisle: (aisle, x_lo, x_hi).
    let mut taken: Vec<(usize, f64, f64)> = Vec::new();
    for o in &cfg.obstacles {
        for a in &layout.aisles {
            if (o.y - a.y).abs() < 0.5 * (a.width + o.size_y) {
                taken.push((a.index, o.x - 0.5 * o.size_x, o.x + 0.5 * o.size_x));
            }
        }
    }
    for &ai in &cfg.block_aisles {
        let a = &layout.aisles[ai];
        let xm = 0.5 * (a.x_start + a.x_end);
        taken.push((ai, xm - 0.15, xm + 0.15));
    }
    for i in 0..cfg.random_obstacles {
        let mut rng = Rng::stream(seed, &[OBSTACLE, i as u64]);
        for _ in 0..200 {
            let a = &layout.aisles[rng.scene_below(layout.aisles.len() as u64) as usize];
            let side = if rng.scene_uniform() < 0.5 { -1.0 } else { 1.0 };
            let [s_lo, s_hi] = cfg.random_obstacle_size;
            let (sx, sy) = (rng.range(s_lo, s_hi), rng.range(s_lo, s_hi));
            let hz = rng.range(cfg.random_obstacle_height[0], cfg.random_obstacle_height[1]);
            let (lo, hi) = (a.x_start + OBSTACLE_GAP + 0.5 * sx, a.x_end - OBSTACLE_GAP - 0.5 * sx);
            if lo >= hi {
                break;
            }
            let x = rng.range(lo, hi);
            let clash = taken.iter().any(|&(ti, x0, x1)| {
                ti == a.index && x - 0.5 * sx < x1 + OBSTACLE_GAP && x + 0.5 * sx > x0 - OBSTACLE_GAP
            });
            if clash {
                continue;
            }
            let y = a.y + side * 0.5 * (a.width - sy);
            let yaw = if rng.scene_uniform() < 0.5 { 0.0 } else { PI };
            taken.push((a.index, x - 0.5 * sx, x + 0.5 * sx));
            let shape = Shape::Box { half: [0.5 * sx, 0.5 * sy, 0.5 * hz] };
            b.push(format!("random_obstacle{i}"), Kind::Obstacle, shape, Placement::yawed([x, y, 0.5 * hz], yaw));
            break;
        }
    }
}
