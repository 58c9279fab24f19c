//! One frame: a primary ray per pixel (centre of the pixel) against the scene, then the
//! colour (shadow ray toward the sun), the instance label and the depth with the stereo
//! sensor's failure modes and noise. Rows are rendered on several threads; every pixel's
//! result (noise included) depends on the pixel alone, so frames are bit-reproducible.

use crate::crop;
use crate::lighting::Lighting;
use crate::optics::{ray_through, CameraPose, Intrinsics, Vec3};
use crate::scene::Scene;
use crate::shading::{self, Palette};
use agrisim_math::vec3::{cross, mat_vec, normalize};
use agrisim_math::Rng;
use agrisim_raycast::{Hit, Occluders, RayCaster, Shadow, SunColumns, MAX_PACKET};
use agrisim_scene::Object;
use agrisim_schedule::on_threads;

/// Depth noise (issue 5 item 2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DepthNoise {
    None,
    /// Gaussian with a fixed sigma (the paper: 0.015 m).
    Fixed {
        sigma: f64,
    },
    /// Intel's stereo RMS: sigma(z) = z^2 subpixel / (fx baseline).
    Stereo {
        subpixel: f64,
    },
}

impl DepthNoise {
    pub fn sigma(&self, z: f64, fx: f64, baseline: f64) -> f64 {
        match *self {
            DepthNoise::None => 0.0,
            DepthNoise::Fixed { sigma } => sigma,
            DepthNoise::Stereo { subpixel } => z * z * subpixel / (fx * baseline),
        }
    }
}

#[derive(Clone, Debug)]
pub struct DepthModel {
    pub range: (f64, f64),
    pub noise: DepthNoise,
    pub baseline: f64,
    /// Left-edge band of a left-referenced stereo pair.
    pub invalid_band: bool,
    /// A pixel is dropped when a 4-neighbour is nearer by more than this fraction of its
    /// depth (0 = off).
    pub edge_ratio: f64,
}

/// Width in pixels of the left invalid band for a surface at depth `z` (Intel's formula).
pub fn invalid_band_width(fx: f64, baseline: f64, z: f64) -> f64 {
    fx * baseline / z
}

/// What one frame produced, row-major, `width x height`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Frame {
    pub rgb: Vec<u8>,
    /// Measured depth z [m], 0 = no data.
    pub depth: Vec<f32>,
    /// True z of the first surface per pixel (0 = no hit), before clipping and noise.
    pub true_depth: Vec<f32>,
    /// Scene object id + 1, 0 = nothing.
    pub labels: Vec<i32>,
    pub valid: usize,
}

/// Far limit of primary rays [m] (colour sees beyond the depth range).
const FAR: f64 = 1000.0;
/// Offset of secondary rays off a surface [m].
const EPS: f64 = 1e-6;
/// Rows per work chunk; chunks are dealt to threads round-robin.
const CHUNK_ROWS: usize = 8;
/// Columns of a primary-ray packet (CHUNK_ROWS x TILE_COLS <= MAX_PACKET rays).
const TILE_COLS: usize = 8;
/// Most shadow rays in one packet (a tile's lit points, nearest first).
const SHADOW_PACKET: usize = 16;
const _: () = assert!(CHUNK_ROWS * TILE_COLS <= MAX_PACKET && SHADOW_PACKET <= MAX_PACKET);

/// What a frame is rendered from. `dynamic` are moving objects (the robot's body); their ids
/// must not collide with scene ids.
#[derive(Clone, Copy)]
pub struct Shot<'a> {
    pub scene: &'a Scene,
    pub dynamic: &'a [Object],
    pub k: &'a Intrinsics,
    pub pose: &'a CameraPose,
    pub light: &'a Lighting,
    /// [`sun_columns`] of `scene` and `light`, or none (the same frame, all shadow rays
    /// traversing the whole scene).
    pub columns: &'a [SunColumns],
    pub depth: &'a DepthModel,
}

/// Renders one frame on `threads` threads (>= 1). `rng` gives the frame's noise key (one draw
/// per frame); each pixel's depth noise is then drawn from that key and the pixel index alone,
/// so the frame is the same whatever the number of threads.
pub fn render(shot: &Shot, rng: &mut Rng, threads: usize) -> Frame {
    let mut f = Frame::default();
    render_into(&mut f, shot, rng, threads);
    f
}

/// [`render`] into the buffers of an earlier frame (any size: they are resized), which it
/// overwrites entirely. A camera renders every frame into the same buffers: fresh ones of
/// 14 MB (1280x720) were pages the kernel had to map and clear at every frame.
pub fn render_into(f: &mut Frame, shot: &Shot, rng: &mut Rng, threads: usize) {
    let &Shot { scene, dynamic, k, pose, light, columns, depth } = shot;
    let (w, h) = (k.width as usize, k.height as usize);
    let n = w * h;
    f.rgb.resize(3 * n, 0);
    f.depth.resize(n, 0.0);
    f.true_depth.resize(n, 0.0);
    f.labels.resize(n, 0);
    let movers = RayCaster::new(dynamic);
    let xs: Vec<f64> = (0..w).map(|u| k.plane_x(u as f64)).collect();
    let columns = if columns_match(columns, light) { columns } else { &[] };
    let cover_pow = std::array::from_fn(|n| light.cover_tau.powi(n as i32));
    let ctx = Ctx { scene, movers: &movers, k, pose, light, columns, cover_pow, palette: Palette::default(), xs: &xs };
    let threads = threads.clamp(1, h.div_ceil(CHUNK_ROWS).max(1));
    let chunks = f
        .rgb
        .chunks_mut(3 * w * CHUNK_ROWS)
        .zip(f.true_depth.chunks_mut(w * CHUNK_ROWS))
        .zip(f.labels.chunks_mut(w * CHUNK_ROWS));
    let ctx = &ctx;
    on_threads(threads, chunks, |c, ((rgb, z), l)| {
        ctx.rows(c * CHUNK_ROWS, rgb, z, l);
        0
    });
    apply_depth_model(f, k, depth, light.fog.map(|g| g.depth_limit), rng.next_u64(), threads);
}

/// What every pixel needs.
struct Ctx<'a> {
    scene: &'a Scene,
    /// The frame's moving objects, prepared once.
    movers: &'a RayCaster,
    k: &'a Intrinsics,
    pose: &'a CameraPose,
    light: &'a Lighting,
    /// One per sun sample, or none.
    columns: &'a [SunColumns],
    /// The cover's transmittance to the powers 0..16 (`powi` once, not per shadow ray).
    cover_pow: [f64; 16],
    palette: Palette,
    /// The pixel columns' plane coordinates ([`Intrinsics::plane_x`]), a division each once
    /// per frame.
    xs: &'a [f64],
}

/// What a primary ray shows, before the sun's beam is known.
#[derive(Clone, Copy, Debug)]
enum Surface {
    /// Sky (or nothing), final linear RGB.
    Sky([f64; 3]),
    /// A surface: the shadow ray's start `p` (just off it), the normal `n` (facing the ray),
    /// the ray's direction `d`, cos(incidence) of the sun, transmittance of the layers seen
    /// through, fog path length, the object.
    Lit { p: Vec3, n: Vec3, d: Vec3, cos_sun: f64, through: f64, fog_path: f64, object: u32 },
}

/// Panes of glass or film a camera ray sees through (beyond: the last one is shown).
const SEE_THROUGH: usize = 4;

/// A camera ray seeing through panes: its current hit, the light passed so far and the
/// distance to the first pane (where the air inside the greenhouse ends).
#[derive(Clone, Copy, Debug)]
struct Layers {
    hit: Option<Hit>,
    through: f64,
    inside: f64,
}

impl Layers {
    /// If the current hit is a pane (an object casting no shadow), counts it and gives the
    /// near limit to cast on from; None when the ray is done.
    fn pane(&mut self, kind: &impl Fn(u32) -> agrisim_scene::Kind, tau: f64) -> Option<f64> {
        match self.hit {
            Some(h) if !shading::casts_shadow(kind(h.object)) => {
                self.through *= tau;
                self.inside = self.inside.min(h.distance);
                Some(h.distance + 1e-4)
            }
            _ => None,
        }
    }
}

/// Sub-pixel offsets of 2x2 supersampling.
const SUB: [(f64, f64); 4] = [(-0.25, -0.25), (0.25, -0.25), (-0.25, 0.25), (0.25, 0.25)];

impl Ctx<'_> {
    /// Renders rows from `v0` into the row-major slices (as many rows as they hold, at most
    /// [`CHUNK_ROWS`]). Primary rays go as packets: tiles of [`TILE_COLS`] columns by the
    /// chunk's rows, one origin, exact per-ray hits.
    fn rows(&self, v0: usize, rgb: &mut [u8], z: &mut [f32], labels: &mut [i32]) {
        let w = self.k.width as usize;
        let rows = z.len() / w;
        let ys: Vec<f64> = (v0..v0 + rows).map(|v| self.k.plane_y(v as f64)).collect();
        let mut d_opt = [[0.0; 3]; MAX_PACKET];
        let mut dirs = [[0.0; 3]; MAX_PACKET];
        let mut hits = [None; MAX_PACKET];
        // The occluders of the chunk's latest shadow rays, tried first by the next ones.
        let mut recent = Recent::default();
        for u0 in (0..w).step_by(TILE_COLS) {
            let cols = TILE_COLS.min(w - u0);
            let n = rows * cols;
            for i in 0..n {
                d_opt[i] = ray_through(self.xs[u0 + i % cols], ys[i / cols]);
                dirs[i] = mat_vec(&self.pose.rotation, d_opt[i]);
            }
            self.scene.caster.cast_packet(self.pose.origin, &dirs[..n], 0.0, FAR, self.movers, &mut hits[..n]);
            crop::resolve_packet(self.scene, self.movers, self.pose.origin, &dirs[..n], FAR, &mut hits[..n]);
            for i in 0..n {
                let j = (i / cols) * w + u0 + i % cols;
                (z[j], labels[j]) = match &hits[i] {
                    Some(hit) => ((hit.distance * d_opt[i][2]) as f32, hit.object as i32 + 1),
                    None => (0.0, 0),
                };
            }
            if self.light.supersample {
                for i in 0..n {
                    let j = (i / cols) * w + u0 + i % cols;
                    let lin = self.supersampled(((j % w) as f64, (v0 + j / w) as f64));
                    rgb[3 * j..3 * j + 3].copy_from_slice(&shading::encode_srgb_rgb(lin));
                }
                continue;
            }
            // Surfaces (through glass: the tile's rays that met a pane go on as packets),
            // then their shadow rays toward the sun, then colours.
            let mut layers = [Layers { hit: None, through: 1.0, inside: f64::INFINITY }; MAX_PACKET];
            for i in 0..n {
                layers[i].hit = hits[i];
            }
            self.see_through_packet(&dirs[..n], &mut layers[..n]);
            let mut surfaces = [Surface::Sky([0.0; 3]); MAX_PACKET];
            for i in 0..n {
                surfaces[i] = self.surface_beyond(dirs[i], &layers[i]);
            }
            let beams = self.beams(&surfaces[..n], &mut recent);
            for i in 0..n {
                let j = (i / cols) * w + u0 + i % cols;
                let lin = self.shade(&surfaces[i], beams[i]);
                rgb[3 * j..3 * j + 3].copy_from_slice(&shading::encode_srgb_rgb(lin));
            }
        }
    }

    /// 2x2 supersampled colour of pixel (u, v): four rays, each shaded alone.
    fn supersampled(&self, (u, v): (f64, f64)) -> [f64; 3] {
        let mut acc = [0.0; 3];
        for (du, dv) in SUB {
            let ds = mat_vec(&self.pose.rotation, self.k.ray(u + du, v + dv));
            let hs = self.scene.caster.cast_among(self.pose.origin, ds, 0.0, FAR, self.movers);
            let hs = crop::resolve(self.scene, self.movers, self.pose.origin, ds, FAR, hs);
            let c = self.radiance(ds, hs.as_ref());
            (0..3).for_each(|i| acc[i] += 0.25 * c[i]);
        }
        acc
    }

    /// Unblocked fraction of the sun's beam at each lit surface of a tile (0 elsewhere): per
    /// sun sample, the sample's [`SunColumns`] tell which shadow rays an opaque object stops
    /// and which none can (those go through the scene's glass and film alone, as packets);
    /// without them, the rays go through the whole scene as packets.
    fn beams(&self, surfaces: &[Surface], recent: &mut Recent) -> [f64; MAX_PACKET] {
        let l = self.light;
        let mut beams = [0.0; MAX_PACKET];
        // Keyed as (squared distance as f32, pixel) in one u64: for non-negative floats the
        // bits order as the values.
        let o = self.pose.origin;
        let mut lit = [0u64; MAX_PACKET];
        let mut at = [[0.0; 3]; MAX_PACKET];
        let mut m = 0;
        for (i, s) in surfaces.iter().enumerate() {
            if let Surface::Lit { p, cos_sun, object, .. } = *s {
                if l.sun_up && cos_sun > 0.0 {
                    let p = crop::shadow_start(self.scene, object, p, l.sun);
                    let d2 =
                        (p[0] - o[0]) * (p[0] - o[0]) + (p[1] - o[1]) * (p[1] - o[1]) + (p[2] - o[2]) * (p[2] - o[2]);
                    lit[m] = ((d2 as f32).to_bits() as u64) << 32 | i as u64;
                    at[i] = p;
                    m += 1;
                }
            }
        }
        let Some(samples) = self.light.sun_samples() else {
            lit[..m].iter().for_each(|&key| beams[pixel(key)] = l.cover_tau);
            return beams;
        };
        for k in 0..samples {
            let s = sun_disc_sample(l.sun, k, samples);
            let Some(columns) = self.columns.get(k as usize) else {
                self.shadow_packets(&mut lit[..m], &at, s, &self.scene.caster, &mut recent.scene, &mut beams);
                continue;
            };
            // What the columns tell: blocked points get nothing from this sample, clear ones
            // go through the glass and film alone (to the back), the rest through the scene.
            let mut r = m;
            let mut q = 0;
            let mut unknown = 0;
            while q < r {
                match columns.occluder(&self.scene.caster, at[pixel(lit[q])], EPS, FAR, recent.blocker) {
                    Shadow::Clear => {
                        r -= 1;
                        lit.swap(q, r);
                    }
                    Shadow::Blocked(b) => {
                        recent.blocker = Some(b);
                        q += 1;
                    }
                    Shadow::Unknown => {
                        lit.swap(q, unknown);
                        unknown += 1;
                        q += 1;
                    }
                }
            }
            self.shadow_packets(&mut lit[..unknown], &at, s, &self.scene.caster, &mut recent.scene, &mut beams);
            self.shadow_packets(&mut lit[r..m], &at, s, columns.translucent(), &mut recent.clear, &mut beams);
        }
        lit[..m].iter().for_each(|&key| beams[pixel(key)] /= samples as f64);
        beams
    }

    /// Adds the transmittance toward `s` at the lit points `keys` (see [`Ctx::beams`]) to
    /// their beams, cast against `caster` (the scene, or its glass and film alone) and the
    /// movers, in packets of [`SHADOW_PACKET`] points close together.
    fn shadow_packets(
        &self,
        keys: &mut [u64],
        at: &[Vec3; MAX_PACKET],
        s: Vec3,
        caster: &RayCaster,
        recent: &mut Occluders,
        beams: &mut [f64; MAX_PACKET],
    ) {
        // Nearest the camera first: a tile across an edge holds a near leaf and the far
        // background, and one packet spanning both culls almost nothing. Each ray's answer
        // is exact whatever rays share its packet, so only the groups matter, not the order
        // within one: selecting each group's boundary is enough, no sort.
        let mut rest = &mut *keys;
        while rest.len() > SHADOW_PACKET {
            rest.select_nth_unstable(SHADOW_PACKET);
            rest = &mut rest[SHADOW_PACKET..];
        }
        let mut out = [None; SHADOW_PACKET];
        let mut points = [[0.0; 3]; SHADOW_PACKET];
        let opaque = opaque(self.scene);
        for group in keys.chunks(SHADOW_PACKET) {
            let g = group.len();
            for (q, &key) in group.iter().enumerate() {
                points[q] = at[pixel(key)];
            }
            caster.pass_through_cached(&points[..g], s, EPS, FAR, self.movers, opaque, recent, &mut out[..g]);
            for (q, &key) in group.iter().enumerate() {
                beams[pixel(key)] += transmittance(out[q], &self.cover_pow);
            }
        }
    }

    /// Linear RGB seen along `d` (map frame) given its first hit (one ray alone).
    fn radiance(&self, d: Vec3, hit: Option<&Hit>) -> [f64; 3] {
        let s = self.surface(d, hit);
        let beam = match s {
            Surface::Lit { p, cos_sun, object, .. } if self.light.sun_up && cos_sun > 0.0 => {
                self.beam(crop::shadow_start(self.scene, object, p, self.light.sun))
            }
            _ => 0.0,
        };
        self.shade(&s, beam)
    }

    /// What the ray along `d` shows: through up to 4 layers of glass or film (colour only),
    /// the sky or a surface. Fog and haze fill the greenhouse up to its cover (the air outside
    /// is not modelled).
    fn surface(&self, d: Vec3, hit: Option<&Hit>) -> Surface {
        let mut layers = Layers { hit: hit.cloned(), through: 1.0, inside: f64::INFINITY };
        let kind = |id| self.scene.kind(id);
        if let Some(tau) = self.light.cover_see_through {
            for _ in 0..SEE_THROUGH {
                match layers.pane(&kind, tau) {
                    Some(beyond) => {
                        let h = self.scene.caster.cast_among(self.pose.origin, d, beyond, FAR, self.movers);
                        layers.hit = crop::resolve(self.scene, self.movers, self.pose.origin, d, FAR, h);
                    }
                    None => break,
                }
            }
        }
        self.surface_beyond(d, &layers)
    }

    /// [`Ctx::surface`] for a tile's rays at once: the rays whose hit is a pane go on past it
    /// together, up to [`SEE_THROUGH`] panes, each ray exactly as it would alone.
    fn see_through_packet(&self, dirs: &[Vec3], layers: &mut [Layers]) {
        let Some(tau) = self.light.cover_see_through else { return };
        let kind = |id| self.scene.kind(id);
        let mut which = [0usize; MAX_PACKET];
        let mut sub = [[0.0; 3]; MAX_PACKET];
        let mut mins = [0.0; MAX_PACKET];
        let mut out = [None; MAX_PACKET];
        for _ in 0..SEE_THROUGH {
            let mut m = 0;
            for (i, layer) in layers.iter_mut().enumerate() {
                if let Some(beyond) = layer.pane(&kind, tau) {
                    (which[m], sub[m], mins[m]) = (i, dirs[i], beyond);
                    m += 1;
                }
            }
            if m == 0 {
                return;
            }
            self.scene.caster.cast_packet_beyond(
                self.pose.origin,
                &sub[..m],
                &mins[..m],
                FAR,
                self.movers,
                &mut out[..m],
            );
            for q in 0..m {
                layers[which[q]].hit = crop::resolve(self.scene, self.movers, self.pose.origin, sub[q], FAR, out[q]);
            }
        }
    }

    /// What a ray shows given its first hit past the panes it saw through.
    fn surface_beyond(&self, d: Vec3, layers: &Layers) -> Surface {
        let l = self.light;
        let (hit, through, inside) = (layers.hit, layers.through, layers.inside);
        let Some(hit) = hit else {
            let sky = l.sky.map(|v| v * through);
            return Surface::Sky(match l.fog {
                Some(f) => {
                    let t = (-f.beta * inside).exp();
                    [0, 1, 2].map(|i| sky[i] * t + f.colour[i] * (1.0 - t))
                }
                None => sky,
            });
        };
        let mut nrm = hit.normal;
        if nrm[0] * d[0] + nrm[1] * d[1] + nrm[2] * d[2] > 0.0 {
            nrm = [-nrm[0], -nrm[1], -nrm[2]];
        }
        let cos_sun = nrm[0] * l.sun[0] + nrm[1] * l.sun[1] + nrm[2] * l.sun[2];
        let o = self.pose.origin;
        let p = [
            o[0] + hit.distance * d[0] + EPS * nrm[0],
            o[1] + hit.distance * d[1] + EPS * nrm[1],
            o[2] + hit.distance * d[2] + EPS * nrm[2],
        ];
        Surface::Lit { p, n: nrm, d, cos_sun, through, fog_path: hit.distance.min(inside), object: hit.object }
    }

    /// Linear RGB of a surface given the unblocked fraction of the sun's beam on it.
    fn shade(&self, s: &Surface, beam: f64) -> [f64; 3] {
        let l = self.light;
        let (p, n, d, cos_sun, through, fog_path, object) = match *s {
            Surface::Sky(c) => return c,
            Surface::Lit { p, n, d, cos_sun, through, fog_path, object } => {
                (p, n, d, cos_sun, through, fog_path, object)
            }
        };
        let c = crop::radiance(self.scene, &self.palette, l, object, p, n, d, cos_sun, beam).map(|v| v * through);
        match l.fog {
            Some(f) => {
                let t = (-f.beta * fog_path).exp();
                [0, 1, 2].map(|i| c[i] * t + f.colour[i] * (1.0 - t))
            }
            None => c,
        }
    }

    /// Fraction of the sun's beam reaching `p` (0 = shadow; cover layers attenuate).
    fn beam(&self, p: Vec3) -> f64 {
        let l = self.light;
        let Some(n) = self.light.sun_samples() else { return l.cover_tau };
        let sum: f64 = (0..n)
            .map(|k| {
                transmitted(
                    self.scene,
                    self.columns.get(k as usize),
                    self.movers,
                    p,
                    sun_disc_sample(l.sun, k, n),
                    &self.cover_pow,
                )
            })
            .sum();
        sum / n as f64
    }
}

/// Cell size of the shadow grids [m] and most cells per grid (8 bytes each, plus their
/// lists: at most 4 entries of 8 bytes per cell, see [`SunColumns`]). On the default
/// greenhouse under `sensors.toml`'s sun, 5 cm cells clear 36 % of the shadow rays of a
/// view along an aisle and 24 % of one at a row (2 cm: 40 % and 24 %; 10 cm: 32 % and 18 %).
const COLUMN_CELL: f64 = 0.05;
const MAX_COLUMN_CELLS: usize = 1 << 22;

/// The shadow grids of `scene` for each of `light`'s sun samples ([`SunColumns`]): which
/// shadow rays no opaque object can stop, so they skip the scene's tree for its glass and film
/// alone. Empty without shadows or with the sun too low.
pub fn sun_columns(scene: &Scene, light: &Lighting) -> Vec<SunColumns> {
    let Some(n) = light.sun_samples().filter(|_| light.sun_up) else { return vec![] };
    let opaque = opaque(scene);
    let columns: Option<Vec<_>> = (0..n)
        .map(|k| {
            SunColumns::new(&scene.caster, sun_disc_sample(light.sun, k, n), opaque, COLUMN_CELL, MAX_COLUMN_CELLS)
        })
        .collect();
    columns.unwrap_or_default()
}

/// True if `columns` were built for `light`'s sun samples.
fn columns_match(columns: &[SunColumns], light: &Lighting) -> bool {
    let n = light.sun_samples().unwrap_or(0);
    columns.len() == n as usize && columns.iter().zip(0..n).all(|(c, k)| c.dir() == sun_disc_sample(light.sun, k, n))
}

/// Angular radius of the sun's disc [rad] (0.2666 deg).
const SUN_RADIUS: f64 = 0.2666 * std::f64::consts::PI / 180.0;

/// Direction `i` of `n` fixed points on the sun's disc: the centre, then a ring at 0.7 of the
/// radius (deterministic, no noise).
fn sun_disc_sample(s: Vec3, i: u32, n: u32) -> Vec3 {
    if i == 0 || n == 1 {
        return s;
    }
    // An orthonormal basis around s.
    let a = if s[2].abs() < 0.9 { [0.0, 0.0, 1.0] } else { [1.0, 0.0, 0.0] };
    let e1 = normalize(cross(s, a));
    let e2 = cross(s, e1);
    let phi = 2.0 * std::f64::consts::PI * (i - 1) as f64 / (n - 1) as f64;
    let r = 0.7 * SUN_RADIUS;
    let (sp, cp) = phi.sin_cos();
    normalize([0, 1, 2].map(|k| s[k] + r * (cp * e1[k] + sp * e2[k])))
}

/// The shadow ray: 0 if something opaque lies between `p` and the sun, else `tau` per glass
/// or film surface crossed (16 or more: 0, as deep as anyone renders). With the sample's
/// columns, a ray they clear goes through the glass and film alone.
fn transmitted(
    scene: &Scene,
    columns: Option<&SunColumns>,
    movers: &RayCaster,
    p: Vec3,
    s: Vec3,
    cover_pow: &[f64; 16],
) -> f64 {
    let caster = match columns.map(|c| (c, c.occluder(&scene.caster, p, EPS, FAR, None))) {
        Some((_, Shadow::Blocked(_))) => return 0.0,
        Some((c, Shadow::Clear)) => c.translucent(),
        _ => &scene.caster,
    };
    transmittance(caster.pass_through(p, s, EPS, FAR, movers, opaque(scene)), cover_pow)
}

/// What a chunk's shadow rays remember for the next ones: the occluders found by the scene's
/// and by the glass-and-film traversals, and the last object the columns found blocking.
#[derive(Default)]
struct Recent {
    scene: Occluders,
    clear: Occluders,
    blocker: Option<u32>,
}

/// Which of `scene`'s object ids stop sunlight (all but glass and film; the robot's links too).
fn opaque(scene: &Scene) -> impl Fn(u32) -> bool + Copy + '_ {
    |id| shading::casts_shadow(scene.kind(id))
}

/// The pixel of a lit point's key in [`Ctx::beams`].
fn pixel(key: u64) -> usize {
    (key & 0xFFFF_FFFF) as usize
}

/// A shadow ray's answer as the beam's transmittance.
fn transmittance(pass: Option<u32>, cover_pow: &[f64; 16]) -> f64 {
    match pass {
        Some(n) if n < 16 => cover_pow[n as usize],
        _ => 0.0,
    }
}

/// SplitMix64's finalizer: a bijective 64-bit mix.
fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Range clip, fog limit (along the ray), discontinuities, left band, noise: true_depth ->
/// depth, rows in chunks on `threads` threads. Pixel i's noise is drawn from a generator
/// seeded by mix(key, i), so the result does not depend on the threads.
pub fn apply_depth_model(
    f: &mut Frame,
    k: &Intrinsics,
    m: &DepthModel,
    fog_limit: Option<f64>,
    key: u64,
    threads: usize,
) {
    let w = k.width as usize;
    let zt = &f.true_depth;
    // No pixel in range lies beyond a fog limit past the range's end along the frame's most
    // oblique ray (a corner's): clear air's limit is kilometres, no test per pixel then.
    // Division rounds monotonically, so the per-pixel test could not fail either.
    let x = k.plane_x(0.0).abs().max(k.plane_x(w as f64 - 1.0).abs());
    let y = k.plane_y(0.0).abs().max(k.plane_y(k.height as f64 - 1.0).abs());
    let corner = ray_through(x, y)[2];
    let fog_limit = fog_limit.filter(|&limit| !(m.range.1 / corner <= limit));
    // The pixel columns' plane coordinates, for the fog limit along each ray.
    let xs: Vec<f64> = match fog_limit {
        Some(_) => (0..w).map(|u| k.plane_x(u as f64)).collect(),
        None => vec![],
    };
    f.valid = on_threads(threads, f.depth.chunks_mut(w * CHUNK_ROWS), |c, out| {
        depth_rows(c * CHUNK_ROWS, out, zt, &xs, k, m, fog_limit, key)
    });
}

/// [`apply_depth_model`] for the rows from `v0` that `out` holds; returns how many are valid.
#[allow(clippy::too_many_arguments)]
fn depth_rows(
    v0: usize,
    out: &mut [f32],
    zt: &[f32],
    xs: &[f64],
    k: &Intrinsics,
    m: &DepthModel,
    fog_limit: Option<f64>,
    key: u64,
) -> usize {
    let (w, h) = (k.width as usize, k.height as usize);
    let mut valid = 0;
    for v in v0..v0 + out.len() / w {
        let y = k.plane_y(v as f64);
        for u in 0..w {
            let i = v * w + u;
            let z = zt[i] as f64;
            let mut ok = z > 0.0 && z >= m.range.0 && z <= m.range.1;
            if let (true, Some(limit)) = (ok, fog_limit) {
                ok = z / ray_through(xs[u], y)[2] <= limit;
            }
            if ok && m.invalid_band && (u as f64) < invalid_band_width(k.fx, m.baseline, z) {
                ok = false;
            }
            if ok && m.edge_ratio > 0.0 {
                let limit = z * (1.0 - m.edge_ratio);
                let nearer = |j: usize| {
                    let zn = zt[j] as f64;
                    zn > 0.0 && zn < limit
                };
                if (u > 0 && nearer(i - 1))
                    || (u + 1 < w && nearer(i + 1))
                    || (v > 0 && nearer(i - w))
                    || (v + 1 < h && nearer(i + w))
                {
                    ok = false;
                }
            }
            out[i - v0 * w] = if ok {
                let sigma = m.noise.sigma(z, k.fx, m.baseline);
                let zm =
                    if sigma == 0.0 { z } else { z + sigma * Rng::new(mix64(key ^ mix64(i as u64))).normal_ziggurat() };
                if zm > 0.0 {
                    valid += 1;
                    zm as f32
                } else {
                    0.0
                }
            } else {
                0.0
            };
        }
    }
    valid
}
