//! The crop as a detector meets it: detail the camera draws inside the colliders of the
//! shared scene, and the crop's colours and gloss.
//!
//! Geometry (what the world FMU and the LiDAR use is the scene's: a sphere per fruit, a thin
//! box per leaflet, cylinders for stems, petioles, trusses and pedicels). Inside those the
//! camera draws, and only the camera:
//!
//! - **Fruit:** an oblate spheroid of the collider's equatorial radius and a shape index
//!   (height / width, as Tomato Analyzer defines it: Brewer et al. 2006, J. Am. Soc. Hortic.
//!   Sci. 131) of 0.85-0.90 per fruit: slightly flattened round greenhouse cultivars (the
//!   range is the issue's; not checked against a published table). It lies within the
//!   sphere, 0.10-0.15 r (3-5 mm) below its poles, below the LiDAR's 2 cm range noise; the
//!   contacts keep the sphere. A calyx stub (the receptacle, 3.5 mm radius) stands on top up
//!   to the collider's top, where the scene's pedicel starts.
//! - **Calyx:** 5 or 6 sepals (Britton and Brown, Illustrated Flora 1913, "Lycopersicon":
//!   calyx 5-parted, rarely 6; Flora of Pakistan: calyx lobes 5-6 mm, triangular-acuminate,
//!   enlarging in fruit; SEINet "Solanum lycopersicum": calyx 0.5-1.2 cm, lobes linear), drawn
//!   as a star lying on the fruit's shoulder, 9-14 mm long, slightly twisted. Calyx pixels
//!   belong to the fruit's instance (label): the calyx is inside the fruit's collider and
//!   leaves the plant with the fruit when it is picked, as annotators of tomato data sets
//!   draw it (the fruit's mask includes its calyx); the pedicel above is the truss's.
//! - **Leaflets:** an ovate outline with an acute tip and a dentate margin (teeth deeper near
//!   the base: SEINet, "margin dentate-crenate to shallowly lobed, more so near base") is
//!   cut out of each leaflet's box; rays outside it go on. Shadows, the LiDAR and contacts see
//!   the box (the outline fills about 75 % of it).
//!
//! Colour: ripeness follows the USDA colour classification (United States Standards for
//! Grades of Fresh Tomatoes, 7 CFR 51.1860: breakers a break in colour on at most 10 % of the
//! surface, turning 10-30 %, pink 30-60 %, light red 60-90 %, red over 90 %); "the normal
//! break occurs at the blossom end", so the coloured part is a cap from the blossom end up,
//! of an area drawn per fruit within its stage's range, with a wavy front. Hue and value vary
//! per fruit, seeded by the object id (deterministic). Skin is glossy: Blinn-Phong highlights
//! of the sun (normalised, exponent 100, Schlick Fresnel with F0 = 0.04, the cuticle's
//! refractive index about 1.5) and a Fresnel-weighted reflection of the sky; leaves are
//! matte and paler beneath ("somewhat glaucous beneath": Flora Europaea, Tutin et al.
//! 1972), with a lighter midrib and veins.

use crate::lighting::{self, Lighting};
use crate::optics::Vec3;
use crate::scene::Scene;
use crate::shading::Palette;
use agrisim_math::vec3::{mat_t_vec, mat_vec};
use agrisim_raycast::{Hit, RayCaster, MAX_PACKET};
use agrisim_scene::{Kind, Placement, Shape};
use std::f64::consts::TAU;

/// What the detail inside an object's collider does to a ray that met the collider.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Detail {
    /// The collider's surface is what is seen.
    Keep,
    /// A surface inside the collider.
    Hit(Hit),
    /// The ray passes: cast on from this distance.
    Pass(f64),
}

/// Most objects a ray may pass through the detail of before the hit is taken as it is.
pub const PASSES: usize = 4;

/// Shape index (height / width) of fruit: per fruit, uniform in this range.
pub const SHAPE_INDEX: [f64; 2] = [0.85, 0.90];
/// Radius of the calyx stub on top of a fruit [m].
pub const STUB_RADIUS: f64 = 0.0035;

/// The detail of `hit`'s object for the ray `o + t d`.
pub fn refine(scene: &Scene, o: Vec3, d: Vec3, hit: &Hit) -> Detail {
    if !matches!(scene.kind(hit.object), Kind::Fruit { .. } | Kind::Leaf) {
        return Detail::Keep;
    }
    let Some(&(shape, pl)) = scene.geometry.get(hit.object as usize) else { return Detail::Keep };
    match (scene.kind(hit.object), shape) {
        (Kind::Fruit { .. }, Shape::Sphere { radius }) => fruit_hit(hit, o, d, pl.translation, radius),
        (Kind::Leaf, Shape::Box { half }) => leaflet_hit(hit, o, d, &pl, half),
        _ => Detail::Keep,
    }
}

/// The first surface seen along `o + t d` from `hit` on (the scene's first hit among the scene
/// and `movers`), with the crop's detail: a ray through a leaflet's cut-out or past a fruit's
/// spheroid is cast on, up to [`PASSES`] times.
pub fn resolve(scene: &Scene, movers: &RayCaster, o: Vec3, d: Vec3, far: f64, mut hit: Option<Hit>) -> Option<Hit> {
    for _ in 0..PASSES {
        let h = hit?;
        match refine(scene, o, d, &h) {
            Detail::Keep => return hit,
            Detail::Hit(r) => return Some(r),
            Detail::Pass(t) => hit = scene.caster.cast_among(o, d, t, far, movers),
        }
    }
    hit
}

/// [`resolve`] for a packet of rays from `o` (`hits` their first hits), the rays that pass
/// cast on together.
pub fn resolve_packet(scene: &Scene, movers: &RayCaster, o: Vec3, dirs: &[Vec3], far: f64, hits: &mut [Option<Hit>]) {
    let mut live = [0usize; MAX_PACKET];
    let mut sub = [[0.0; 3]; MAX_PACKET];
    let mut mins = [0.0; MAX_PACKET];
    let mut out = [None; MAX_PACKET];
    let mut m = 0;
    for (i, h) in hits.iter_mut().enumerate() {
        if let Some(cur) = h {
            match refine(scene, o, dirs[i], cur) {
                Detail::Keep => {}
                Detail::Hit(r) => *h = Some(r),
                Detail::Pass(t) => {
                    (live[m], sub[m], mins[m]) = (i, dirs[i], t);
                    m += 1;
                }
            }
        }
    }
    for round in 1..=PASSES {
        if m == 0 {
            return;
        }
        scene.caster.cast_packet_beyond(o, &sub[..m], &mins[..m], far, movers, &mut out[..m]);
        let mut next = 0;
        for q in 0..m {
            let i = live[q];
            hits[i] = out[q];
            let Some(cur) = out[q] else { continue };
            if round == PASSES {
                continue;
            }
            match refine(scene, o, dirs[i], &cur) {
                Detail::Keep => {}
                Detail::Hit(r) => hits[i] = Some(r),
                Detail::Pass(t) => {
                    (live[next], sub[next], mins[next]) = (i, dirs[i], t);
                    next += 1;
                }
            }
        }
        m = next;
    }
}

/// A key mixed into a fruit's or leaflet's id for its own appearance draws.
fn mix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Uniform [0, 1) draw `k` of object `id`.
fn draw(id: u32, k: u64) -> f64 {
    (mix64(mix64(id as u64 ^ 0xC0FF_EE00_0000_0000) ^ k) >> 11) as f64 / (1u64 << 53) as f64
}

/// The seeded looks of one fruit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FruitLook {
    /// Height over width.
    pub shape_index: f64,
    /// Sepals of the calyx (5 or 6), their length [m] and the star's turn [rad].
    pub sepals: u32,
    pub sepal_length: f64,
    pub calyx_turn: f64,
    /// Coloured (not green) fraction of the surface, for the fruit's stage.
    pub coloured: f64,
    /// Per-channel factors of the fruit's hue and value.
    pub tint: [f64; 3],
    /// Phases of the colour front's waves.
    pub phase: [f64; 2],
}

/// Coloured surface fraction per USDA stage: (low, high). Red's upper end is over 1 so that
/// most red fruit are red all over.
const COLOURED: [[f64; 2]; 6] = [[0.0, 0.0], [0.03, 0.10], [0.10, 0.30], [0.30, 0.60], [0.60, 0.90], [0.92, 1.1]];

impl FruitLook {
    pub fn of(id: u32, stage: u8) -> FruitLook {
        let s = stage.clamp(1, 6) as usize - 1;
        let [lo, hi] = COLOURED[s];
        let v = draw(id, 7) - 0.5;
        FruitLook {
            shape_index: shape_index(id),
            sepals: if draw(id, 2) < 0.7 { 5 } else { 6 },
            sepal_length: 0.009 + 0.005 * draw(id, 3),
            calyx_turn: TAU * draw(id, 4),
            coloured: lo + (hi - lo) * draw(id, 5),
            tint: [1.0 + 0.12 * v, 1.0 + 0.10 * (draw(id, 8) - 0.5) - 0.05 * v, 1.0 + 0.2 * (draw(id, 9) - 0.5)]
                .map(|t| t * (0.92 + 0.16 * draw(id, 6))),
            phase: [TAU * draw(id, 10), TAU * draw(id, 11)],
        }
    }
}

/// Fruit `id`'s shape index (alone: every hit on a fruit asks for it).
pub fn shape_index(id: u32) -> f64 {
    SHAPE_INDEX[0] + (SHAPE_INDEX[1] - SHAPE_INDEX[0]) * draw(id, 1)
}

/// The spheroid and calyx stub inside a fruit's sphere (centre `c`, radius `r`).
fn fruit_hit(hit: &Hit, o: Vec3, d: Vec3, c: Vec3, r: f64) -> Detail {
    let k = shape_index(hit.object);
    let p = [o[0] - c[0], o[1] - c[1], o[2] - c[2]];
    // Scaled so the spheroid is the sphere of radius r.
    let (ps, ds) = ([p[0], p[1], p[2] / k], [d[0], d[1], d[2] / k]);
    let mut best = f64::INFINITY;
    let mut normal = [0.0; 3];
    if let Some((t, _)) = roots(ps, ds, r) {
        if t > 0.0 {
            best = t;
            let q = [p[0] + t * d[0], p[1] + t * d[1], p[2] + t * d[2]];
            normal = unit([q[0], q[1], q[2] / (k * k)]);
        }
    }
    // The stub: a vertical cylinder from inside the spheroid's top to the sphere's top.
    let (z0, z1) = (k * r - 0.2 * STUB_RADIUS, r);
    let a = d[0] * d[0] + d[1] * d[1];
    if a > 0.0 {
        let b = p[0] * d[0] + p[1] * d[1];
        let cc = p[0] * p[0] + p[1] * p[1] - STUB_RADIUS * STUB_RADIUS;
        let disc = b * b - a * cc;
        if disc >= 0.0 {
            let t = (-b - disc.sqrt()) / a;
            let z = p[2] + t * d[2];
            if t > 0.0 && t < best && z >= z0 && z <= z1 {
                best = t;
                normal = unit([p[0] + t * d[0], p[1] + t * d[1], 0.0]);
            }
        }
    }
    if d[2] < 0.0 {
        let t = (z1 - p[2]) / d[2];
        let (x, y) = (p[0] + t * d[0], p[1] + t * d[1]);
        if t > 0.0 && t < best && x * x + y * y <= STUB_RADIUS * STUB_RADIUS {
            best = t;
            normal = [0.0, 0.0, 1.0];
        }
    }
    if best.is_finite() {
        return Detail::Hit(Hit { distance: best, object: hit.object, normal });
    }
    match roots(p, d, r) {
        Some((_, t1)) if t1 >= hit.distance => Detail::Pass(t1 + 1e-6 + 1e-9 * t1),
        _ => Detail::Keep,
    }
}

/// Where the shadow ray of a point `p` (just off a surface of `object`) toward `sun` starts:
/// a point on a fruit's spheroid lies inside its collider, which would shade it, so its ray
/// starts where it leaves the collider (only the fruit's own detail lies in between).
pub fn shadow_start(scene: &Scene, object: u32, p: Vec3, sun: Vec3) -> Vec3 {
    match (scene.kind(object), scene.geometry.get(object as usize)) {
        (Kind::Fruit { .. }, Some(&(Shape::Sphere { radius }, pl))) => {
            let c = pl.translation;
            match roots([p[0] - c[0], p[1] - c[1], p[2] - c[2]], sun, radius) {
                Some((_, t1)) if t1 > 0.0 => {
                    let t = t1 + 1e-6;
                    [p[0] + t * sun[0], p[1] + t * sun[1], p[2] + t * sun[2]]
                }
                _ => p,
            }
        }
        _ => p,
    }
}

/// The two crossings (t0 <= t1) of `p + t d` with the sphere of radius `r` at the origin.
fn roots(p: Vec3, d: Vec3, r: f64) -> Option<(f64, f64)> {
    let a = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    let b = p[0] * d[0] + p[1] * d[1] + p[2] * d[2];
    let c = p[0] * p[0] + p[1] * p[1] + p[2] * p[2] - r * r;
    let disc = b * b - a * c;
    if disc < 0.0 {
        return None;
    }
    let s = disc.sqrt();
    let q = if b > 0.0 { -(b + s) } else { -b + s };
    if q == 0.0 {
        return None;
    }
    let (t0, t1) = (q / a, c / q);
    Some(if t0 <= t1 { (t0, t1) } else { (t1, t0) })
}

fn unit(v: Vec3) -> Vec3 {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    [v[0] / n, v[1] / n, v[2] / n]
}

/// A leaflet's outline cut out of its box (half extents `half`, placed at `pl`).
fn leaflet_hit(hit: &Hit, o: Vec3, d: Vec3, pl: &Placement, half: [f64; 3]) -> Detail {
    let m = pl.matrix();
    let c = pl.translation;
    let q = [o[0] + hit.distance * d[0] - c[0], o[1] + hit.distance * d[1] - c[1], o[2] + hit.distance * d[2] - c[2]];
    let lq = mat_t_vec(&m, q);
    if inside_leaflet(hit.object, lq[0] / half[0], lq[1] / half[1]) {
        return Detail::Keep;
    }
    // On past the box: where the ray leaves it.
    let lo = mat_t_vec(&m, [o[0] - c[0], o[1] - c[1], o[2] - c[2]]);
    let ld = mat_t_vec(&m, d);
    let mut t_out = f64::INFINITY;
    for i in 0..3 {
        if ld[i] != 0.0 {
            let (t1, t2) = ((-half[i] - lo[i]) / ld[i], (half[i] - lo[i]) / ld[i]);
            t_out = t_out.min(t1.max(t2));
        }
    }
    if t_out.is_finite() && t_out >= hit.distance {
        Detail::Pass(t_out + 1e-6 + 1e-9 * t_out)
    } else {
        Detail::Pass(hit.distance + 1e-6)
    }
}

/// Half width (fraction of the box's half width) of a leaflet at `s` in [0, 1] from its base
/// to its tip, before the teeth: ovate, widest at 0.38, a truncate base, an acute tip.
pub fn leaflet_width(s: f64) -> f64 {
    const WIDEST: f64 = 0.38;
    if !(0.0..=1.0).contains(&s) {
        return 0.0;
    }
    if s < WIDEST {
        let p = (WIDEST - s) / WIDEST;
        (1.0 - 0.7 * p * p).sqrt()
    } else {
        let q = (s - WIDEST) / (1.0 - WIDEST);
        (1.0 - q * q * q.sqrt()) * (1.0 - 0.25 * q)
    }
}

/// Teeth per side of leaflet `id`'s margin (10-14).
fn teeth(id: u32) -> f64 {
    10.0 + (5.0 * draw(id, 20)).floor()
}

/// True if (u, v) (box coordinates over half extents, u from the base -1 to the tip +1)
/// lies inside leaflet `id`'s serrated outline.
pub fn inside_leaflet(id: u32, u: f64, v: f64) -> bool {
    let s = 0.5 * (u + 1.0);
    let w = leaflet_width(s);
    // Dentate: saw teeth pointing to the tip (the margin rises slowly to each tooth's tip,
    // then drops), deeper near the base.
    let phase = if v >= 0.0 { draw(id, 21) } else { draw(id, 22) };
    let x = teeth(id) * s + phase;
    let tooth = x - x.floor();
    let depth = 0.04 + 0.07 * (1.0 - s);
    v.abs() <= w * (1.0 - depth * (1.0 - tooth))
}

/// Linear radiance (before the layers seen through and fog) of the surface of `object` at
/// `p` with unit normal `n` (facing the viewer) seen along `d`, under `l` with cos(incidence)
/// `cos_sun` and the unblocked fraction `beam` of the sun's beam.
#[allow(clippy::too_many_arguments)]
pub fn radiance(
    scene: &Scene,
    palette: &Palette,
    l: &Lighting,
    object: u32,
    p: Vec3,
    n: Vec3,
    d: Vec3,
    cos_sun: f64,
    beam: f64,
) -> [f64; 3] {
    let e = lighting::irradiance(l, cos_sun, beam, n[2]);
    let kind = scene.kind(object);
    let geometry = scene.geometry.get(object as usize);
    let (albedo, gloss) = match (kind, geometry) {
        (Kind::Fruit { ripeness }, Some(&(Shape::Sphere { radius }, pl))) => {
            let c = pl.translation;
            fruit_albedo(palette, object, ripeness, [p[0] - c[0], p[1] - c[1], p[2] - c[2]], radius)
        }
        (Kind::Leaf, Some(&(Shape::Box { half }, pl))) => leaflet_albedo(palette, object, &pl, half, p, n),
        (Kind::Leaf, _) => (srgb(palette, [86, 128, 52]), Gloss::NONE),
        _ => (palette.albedo(kind), Gloss::NONE),
    };
    let mut c = [albedo[0] * e, albedo[1] * e, albedo[2] * e];
    if gloss.weight > 0.0 {
        let s = gloss_radiance(l, gloss, n, d, cos_sun, beam);
        c.iter_mut().for_each(|v| *v += s);
    }
    c
}

/// Specular reflection of a surface: weight (0 = none) and Blinn-Phong exponent.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gloss {
    pub weight: f64,
    pub exponent: i32,
}

impl Gloss {
    pub const NONE: Gloss = Gloss { weight: 0.0, exponent: 1 };
    /// Tomato skin: a smooth waxy cuticle.
    pub const SKIN: Gloss = Gloss { weight: 1.0, exponent: 100 };
    /// The calyx: hairy, nearly matte. (Leaves and stalks, hairy too, are drawn matte: their
    /// sheen would be under 3 % of the light and cost a tenth of a frame.)
    pub const MATTE: Gloss = Gloss { weight: 0.35, exponent: 12 };
}

/// Reflectance of the cuticle at normal incidence (refractive index about 1.5).
const F0: f64 = 0.04;

/// Specular radiance (grey) of a glossy surface: the sun by normalised Blinn-Phong, and the
/// sky mirrored (weighted by how far the mirrored ray points up), both with Schlick's Fresnel
/// factor.
pub fn gloss_radiance(l: &Lighting, g: Gloss, n: Vec3, d: Vec3, cos_sun: f64, beam: f64) -> f64 {
    let v = [-d[0], -d[1], -d[2]];
    let cos_v = (n[0] * v[0] + n[1] * v[1] + n[2] * v[2]).clamp(0.0, 1.0);
    let mut s = 0.0;
    if beam > 0.0 && cos_sun > 0.0 {
        let h = unit([l.sun[0] + v[0], l.sun[1] + v[1], l.sun[2] + v[2]]);
        let n_h = (n[0] * h[0] + n[1] * h[1] + n[2] * h[2]).max(0.0);
        let h_v = (h[0] * v[0] + h[1] * v[1] + h[2] * v[2]).clamp(0.0, 1.0);
        let f = F0 + (1.0 - F0) * (1.0 - h_v).powi(5);
        s += l.direct * beam * cos_sun * f * (g.exponent as f64 + 8.0) / 8.0 * n_h.powi(g.exponent);
    }
    // The mirrored ray's rise: the sky above it, foliage and floor (dark) around it.
    let r_z = d[2] - 2.0 * (d[0] * n[0] + d[1] * n[1] + d[2] * n[2]) * n[2];
    if r_z > 0.0 {
        let f = F0 + (1.0 - F0) * (1.0 - cos_v).powi(5);
        s += f * l.diffuse * r_z.sqrt();
    }
    g.weight * s
}

fn srgb(p: &Palette, c: [u8; 3]) -> [f64; 3] {
    c.map(|v| p.linear(v))
}

fn mix(a: [f64; 3], b: [f64; 3], t: f64) -> [f64; 3] {
    [0, 1, 2].map(|i| a[i] + (b[i] - a[i]) * t)
}

fn smoothstep(e0: f64, e1: f64, x: f64) -> f64 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// The part of a fruit a point lies on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FruitPart {
    Skin,
    Calyx,
}

/// Which part of fruit `id` (equatorial radius `r`) the point `q` (relative to its centre, on
/// its surface) lies on: the calyx's star of sepals and stub on top, else skin.
pub fn fruit_part(id: u32, q: Vec3, r: f64) -> FruitPart {
    part_of(&FruitLook::of(id, 1), q, r)
}

/// [`fruit_part`] given the fruit's looks.
fn part_of(look: &FruitLook, q: Vec3, r: f64) -> FruitPart {
    let k = look.shape_index;
    if q[2] >= k * r - 0.25 * STUB_RADIUS && q[0] * q[0] + q[1] * q[1] <= 1.0001 * STUB_RADIUS * STUB_RADIUS {
        return FruitPart::Calyx;
    }
    // Polar angle on the unit sphere the spheroid scales to; arc length from the top.
    let zn = (q[2] / (k * r)).clamp(-1.0, 1.0);
    // Most of the skin is far below the sepals: 2 sin(theta / 2) = sqrt(2 (1 - zn)) <= theta,
    // so a chord beyond the sepals (with a margin far above acos's rounding) is skin without
    // the acos. The answer is the one the acos gives.
    if (2.0 * (1.0 - zn)).sqrt() * r > look.sepal_length * (1.0 + 1e-9) {
        return FruitPart::Skin;
    }
    let theta = zn.acos();
    let rho = theta * r;
    if rho > look.sepal_length {
        return FruitPart::Skin;
    }
    if rho < 0.0045 {
        return FruitPart::Calyx;
    }
    let f = rho / look.sepal_length;
    let n = look.sepals as f64;
    // Each sepal bends a little as it runs down the shoulder.
    let phi = q[1].atan2(q[0]) - look.calyx_turn - 0.35 * f;
    let sector = TAU / n;
    let delta = (phi / sector - (phi / sector).round()) * sector;
    let half_width = 0.0028 * (1.0 - f).powf(0.7);
    if delta.abs() * theta.sin() * r <= half_width {
        FruitPart::Calyx
    } else {
        FruitPart::Skin
    }
}

/// Albedo and gloss of fruit `id` (USDA stage `stage`, equatorial radius `r`) at `q`
/// (relative to its centre).
fn fruit_albedo(p: &Palette, id: u32, stage: u8, q: Vec3, r: f64) -> ([f64; 3], Gloss) {
    let look = FruitLook::of(id, stage);
    if part_of(&look, q, r) == FruitPart::Calyx {
        // Darker at the base of the star, lighter at the tips.
        let rho = (q[2] / (look.shape_index * r)).clamp(-1.0, 1.0).acos() * r;
        let t = (rho / look.sepal_length).clamp(0.0, 1.0);
        return (mix(srgb(p, [58, 100, 34]), srgb(p, [96, 140, 56]), t), Gloss::MATTE);
    }
    // Fraction of the surface below q's height (a sphere's: (z + 1) / 2), from the blossom
    // end at the bottom; the colour's front waves around the fruit.
    let zn = (q[2] / (look.shape_index * r)).clamp(-1.0, 1.0);
    let below = 0.5 * (zn + 1.0);
    let green_top = mix(srgb(p, [132, 168, 70]), srgb(p, [84, 128, 44]), smoothstep(0.55, 0.95, below));
    let mut c = green_top;
    if look.coloured > 0.0 {
        // (The wave's angle and sines only where the front is drawn with it.)
        let front = if look.coloured < 1.0 {
            let phi = q[1].atan2(q[0]);
            let wave = 0.05 * (3.0 * phi + look.phase[0]).sin() + 0.03 * (5.0 * phi + look.phase[1]).sin();
            look.coloured + wave
        } else {
            look.coloured
        };
        let t = smoothstep(front + 0.05, front - 0.05, below);
        // Behind the front the colour deepens toward the stage's own.
        let (edge, deep) = match stage {
            2 | 3 => ([214, 176, 92], [226, 140, 84]),
            4 => ([224, 150, 96], [232, 104, 84]),
            5 => ([226, 118, 74], [214, 60, 44]),
            _ => ([206, 70, 38], [182, 26, 18]),
        };
        let depth = ((front - below) / 0.3).clamp(0.0, 1.0);
        let coloured = mix(srgb(p, edge), srgb(p, deep), depth);
        c = mix(c, coloured, t);
    }
    // The blossom-end scar: a small pale brown point.
    if below < 0.003 {
        c = mix(c, srgb(p, [150, 126, 74]), 0.7);
    }
    ([0, 1, 2].map(|i| (c[i] * look.tint[i]).min(1.0)), Gloss::SKIN)
}

/// Albedo and gloss (none) of leaflet `id` at the map point `p` with normal `n`: darker above than
/// below, a lighter midrib and veins, a seeded shade per leaflet.
fn leaflet_albedo(pal: &Palette, id: u32, pl: &Placement, half: [f64; 3], p: Vec3, n: Vec3) -> ([f64; 3], Gloss) {
    let m = pl.matrix();
    let c = pl.translation;
    let lq = mat_t_vec(&m, [p[0] - c[0], p[1] - c[1], p[2] - c[2]]);
    let up = mat_vec(&m, [0.0, 0.0, 1.0]);
    let above = n[0] * up[0] + n[1] * up[1] + n[2] * up[2] >= 0.0;
    let (u, v) = (lq[0] / half[0], lq[1] / half[1]);
    let s = 0.5 * (u + 1.0);
    let mut col = if above { srgb(pal, [50, 98, 32]) } else { srgb(pal, [98, 136, 74]) };
    let w = leaflet_width(s).max(1e-3);
    let vr = v.abs() / w;
    if vr < 0.05 {
        col = mix(col, srgb(pal, [118, 156, 78]), 0.6);
    } else {
        // Secondary veins: running out from the midrib toward the tip.
        let x = 7.0 * (s - 0.3 * vr);
        if x - x.floor() < 0.06 && vr < 0.85 {
            col = mix(col, srgb(pal, [104, 146, 66]), 0.35);
        }
    }
    let shade = 0.85 + 0.3 * draw(id, 30);
    let yellow = 0.06 * (draw(id, 31) - 0.5);
    col = [col[0] * shade * (1.0 + yellow), col[1] * shade, col[2] * shade * (1.0 - yellow)];
    (col, Gloss::NONE)
}

#[cfg(test)]
mod tests {
    use super::*;
    use agrisim_scene::Object;
    use std::f64::consts::PI;

    fn fruit_scene(ripeness: u8) -> Scene {
        let fruit = Object {
            id: 0,
            name: "fruit".into(),
            kind: Kind::Fruit { ripeness },
            shape: Shape::Sphere { radius: 0.03 },
            placement: Placement::at(0.0, 0.0, 0.0),
        };
        Scene::from_objects(&[fruit])
    }

    #[test]
    fn fruit_is_oblate_within_its_collider() {
        let scene = fruit_scene(6);
        let none = RayCaster::new(&[]);
        let k = FruitLook::of(0, 6).shape_index;
        assert!((0.85..=0.9).contains(&k));
        // Width: a ray along x through the centre meets the equator at the collider.
        let side = resolve(
            &scene,
            &none,
            [-1.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            10.0,
            scene.caster.cast([-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], 0.0, 10.0, &[]),
        )
        .unwrap();
        assert!((side.distance - 0.97).abs() < 1e-9);
        // Height: a ray from below meets the blossom end k r from the centre, not r.
        let d = [0.0, 0.0, 1.0];
        let h = scene.caster.cast([0.0, 0.0, -1.0], d, 0.0, 10.0, &[]);
        let bottom = resolve(&scene, &none, [0.0, 0.0, -1.0], d, 10.0, h).unwrap();
        assert!((bottom.distance - (1.0 - k * 0.03)).abs() < 1e-9, "{}", bottom.distance);
        assert_eq!(bottom.normal, [0.0, 0.0, -1.0]);
        // A ray through the collider's top cap, above the spheroid and beside the stub,
        // passes.
        let o = [-1.0, 0.0, 0.0285];
        let h = scene.caster.cast(o, [1.0, 0.0, 0.0], 0.0, 10.0, &[]);
        assert!(h.is_some());
        let x = [-1.0, 0.006, 0.0285];
        let h2 = scene.caster.cast(x, [1.0, 0.0, 0.0], 0.0, 10.0, &[]);
        assert!(h2.is_some());
        assert_eq!(resolve(&scene, &none, x, [1.0, 0.0, 0.0], 10.0, h2), None);
        // Above the spheroid, through the stub: the stub is seen, as part of the fruit.
        let stub = resolve(&scene, &none, o, [1.0, 0.0, 0.0], 10.0, h).unwrap();
        assert_eq!(stub.object, 0);
        assert!((stub.distance - (1.0 - STUB_RADIUS)).abs() < 1e-9);
    }

    #[test]
    fn calyx_on_top_and_its_sepals() {
        for id in 0..50 {
            let look = FruitLook::of(id, 6);
            let (k, r) = (look.shape_index, 0.03);
            let at =
                |theta: f64, phi: f64| [r * theta.sin() * phi.cos(), r * theta.sin() * phi.sin(), k * r * theta.cos()];
            assert_eq!(fruit_part(id, at(0.0, 0.0), r), FruitPart::Calyx);
            assert_eq!(fruit_part(id, at(PI, 0.0), r), FruitPart::Skin);
            assert_eq!(fruit_part(id, at(0.5 * PI, 0.3), r), FruitPart::Skin);
            // Count the sepals on a ring a third of their length from the top.
            let theta = 0.6 * look.sepal_length / r;
            let ring: Vec<bool> =
                (0..720).map(|i| fruit_part(id, at(theta, TAU * i as f64 / 720.0), r) == FruitPart::Calyx).collect();
            let starts = (0..720).filter(|&i| ring[i] && !ring[(i + 719) % 720]).count();
            assert_eq!(starts as u32, look.sepals, "fruit {id}");
            assert!((5..=6).contains(&look.sepals));
        }
    }

    #[test]
    fn leaflet_outline_is_ovate_and_serrate() {
        assert_eq!(leaflet_width(1.0), 0.0);
        assert!((leaflet_width(0.38) - 1.0).abs() < 1e-12);
        assert!(leaflet_width(0.0) > 0.3);
        // Within the box; fills 55-80 % of it; the margin along one side goes in and out as
        // many times as the leaflet has teeth.
        for id in 0..20 {
            let n = 400;
            let mut inside = 0;
            for i in 0..n {
                for j in 0..n {
                    let (u, v) = (-1.0 + 2.0 * (i as f64 + 0.5) / n as f64, -1.0 + 2.0 * (j as f64 + 0.5) / n as f64);
                    inside += inside_leaflet(id, u, v) as usize;
                }
            }
            let fill = inside as f64 / (n * n) as f64;
            assert!((0.55..0.8).contains(&fill), "{fill}");
            // Teeth between 5 % and 90 % of the length, where the margin drops by more than
            // 0.5 % of the box's width behind each tooth's tip.
            let edge = |u: f64| (0..2000).map(|j| j as f64 / 2000.0).take_while(|&v| inside_leaflet(id, u, v)).count();
            let (s0, s1) = (0.05, 0.9);
            let steps = 4000;
            let mut dips = 0;
            let mut last = edge(2.0 * s0 - 1.0) as f64;
            for i in 1..=steps {
                let s = s0 + (s1 - s0) * i as f64 / steps as f64;
                let e = edge(2.0 * s - 1.0) as f64;
                dips += (last - e > 10.0) as usize;
                last = e;
            }
            let x = |s: f64| teeth(id) * s + draw(id, 21);
            let t = (x(s1).floor() - x(s0).floor()) as usize;
            assert_eq!(dips, t, "leaflet {id}");
        }
    }

    #[test]
    fn ripeness_colours_from_the_blossom_end() {
        let p = Palette::default();
        let r = 0.03;
        let col = |id: u32, stage: u8, zn: f64| {
            let k = FruitLook::of(id, stage).shape_index;
            let s = (1.0 - zn * zn).sqrt();
            fruit_albedo(&p, id, stage, [r * s, 0.0, k * r * zn], r).0
        };
        for id in 0..30 {
            // Green: green everywhere; red: red at the blossom end and the equator.
            for zn in [-0.99, -0.5, 0.0, 0.5, 0.8] {
                let [rr, g, _] = col(id, 1, zn);
                assert!(g > rr, "green fruit {id} at {zn}");
            }
            for zn in [-0.99, -0.5, 0.0] {
                let [rr, g, _] = col(id, 6, zn);
                assert!(rr > 3.0 * g, "red fruit {id} at {zn}");
            }
            // Breakers: coloured at the blossom end, green at the equator and shoulder.
            let [rr, g, _] = col(id, 2, -0.995);
            assert!(rr > g, "breaker {id} blossom end");
            for zn in [0.0, 0.6] {
                let [rr, g, _] = col(id, 2, zn);
                assert!(g > rr, "breaker {id} at {zn}");
            }
            // Pink: coloured below the equator's lower half, green near the top.
            let [rr, g, _] = col(id, 4, -0.9);
            assert!(rr > 1.5 * g);
            let [rr, g, _] = col(id, 4, 0.8);
            assert!(g > rr);
        }
        // Fruit of one stage differ in tint, the same fruit is always the same.
        assert_ne!(FruitLook::of(1, 6).tint, FruitLook::of(2, 6).tint);
        assert_eq!(FruitLook::of(3, 6), FruitLook::of(3, 6));
    }

    #[test]
    fn skin_shows_the_sun_mirrored_and_leaves_hardly() {
        let l = Lighting::new(0.0, 45.0, 0.3);
        // The mirror direction: the view bisects the sun and the normal.
        let n = [0.0, 0.0, 1.0];
        let d = unit([-l.sun[0], -l.sun[1], l.sun[2]]);
        let d = [-d[0], -d[1], -d[2]];
        let cos_sun = l.sun[2];
        let peak = gloss_radiance(&l, Gloss::SKIN, n, d, cos_sun, 1.0);
        assert!(peak > 0.2, "{peak}");
        let off = unit([0.3 - l.sun[0], 0.2, -l.sun[2]]);
        assert!(gloss_radiance(&l, Gloss::SKIN, n, off, cos_sun, 1.0) < 0.2 * peak);
        assert!(gloss_radiance(&l, Gloss::MATTE, n, d, cos_sun, 1.0) < 0.3 * peak);
        // In shadow only the sky's reflection is left.
        assert!(gloss_radiance(&l, Gloss::SKIN, n, d, cos_sun, 0.0) < 0.1 * peak);
    }
}
