//! One frame: a primary ray per pixel (centre of the pixel) against the scene, then the
//! colour (shadow ray toward the sun), the instance label and the depth with the stereo
//! sensor's failure modes and noise. Single-threaded, so frames are bit-reproducible.

use crate::optics::{mat_vec, CameraPose, Intrinsics, Vec3};
use crate::scene::Scene;
use crate::shading::{self, Palette};
use agrisim_fmu_util::Rng;
use agrisim_greenhouse::Object;

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

#[derive(Clone, Debug)]
pub struct Lighting {
    /// Unit vector toward the sun in the map frame.
    pub sun: Vec3,
    /// The sun is above the horizon.
    pub sun_up: bool,
    pub ambient: f64,
}

impl Lighting {
    pub fn new(azimuth_deg: f64, elevation_deg: f64, ambient: f64) -> Lighting {
        let (a, e) = (azimuth_deg.to_radians(), elevation_deg.to_radians());
        Lighting {
            sun: [e.cos() * a.cos(), e.cos() * a.sin(), e.sin()],
            sun_up: elevation_deg > 0.0,
            ambient,
        }
    }
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

/// Renders one frame. `dynamic` are moving objects (the robot's base box); their ids must not
/// collide with scene ids. `rng` draws the depth noise.
pub fn render(
    scene: &Scene,
    dynamic: &[Object],
    k: &Intrinsics,
    pose: &CameraPose,
    light: &Lighting,
    depth: &DepthModel,
    rng: &mut Rng,
) -> Frame {
    let (w, h) = (k.width as usize, k.height as usize);
    let n = w * h;
    let palette = Palette::default();
    let mut f = Frame {
        rgb: Vec::with_capacity(3 * n),
        depth: vec![0.0; n],
        true_depth: vec![0.0; n],
        labels: vec![0; n],
        valid: 0,
    };
    for v in 0..h {
        for u in 0..w {
            let d_opt = k.ray(u as f64, v as f64);
            let d = mat_vec(&pose.rotation, d_opt);
            let i = v * w + u;
            match scene.caster.cast(pose.origin, d, 0.0, FAR, dynamic) {
                Some(hit) => {
                    f.true_depth[i] = (hit.distance * d_opt[2]) as f32;
                    f.labels[i] = hit.object as i32 + 1;
                    let mut nrm = hit.normal;
                    if nrm[0] * d[0] + nrm[1] * d[1] + nrm[2] * d[2] > 0.0 {
                        nrm = [-nrm[0], -nrm[1], -nrm[2]];
                    }
                    let cos_sun =
                        nrm[0] * light.sun[0] + nrm[1] * light.sun[1] + nrm[2] * light.sun[2];
                    let lit = light.sun_up && cos_sun > 0.0 && {
                        let p = [
                            pose.origin[0] + hit.distance * d[0] + EPS * nrm[0],
                            pose.origin[1] + hit.distance * d[1] + EPS * nrm[1],
                            pose.origin[2] + hit.distance * d[2] + EPS * nrm[2],
                        ];
                        sunlit(scene, dynamic, p, light.sun)
                    };
                    let c = shading::shade(
                        palette.albedo(scene.kind(hit.object)),
                        cos_sun,
                        lit,
                        light.ambient,
                    );
                    f.rgb.extend_from_slice(&c);
                }
                None => f.rgb.extend_from_slice(&shading::SKY),
            }
        }
    }
    apply_depth_model(&mut f, k, depth, rng);
    f
}

/// The shadow ray: nothing opaque between `p` and the sun (glass passes light).
fn sunlit(scene: &Scene, dynamic: &[Object], mut p: Vec3, s: Vec3) -> bool {
    for _ in 0..16 {
        match scene.caster.cast(p, s, EPS, FAR, dynamic) {
            None => return true,
            Some(hit) if shading::casts_shadow(scene.kind(hit.object)) => return false,
            Some(hit) => {
                let t = hit.distance + 1e-4;
                p = [p[0] + t * s[0], p[1] + t * s[1], p[2] + t * s[2]];
            }
        }
    }
    false
}

/// Range clip, discontinuities, left band, noise: true_depth -> depth.
pub fn apply_depth_model(f: &mut Frame, k: &Intrinsics, m: &DepthModel, rng: &mut Rng) {
    let (w, h) = (k.width as usize, k.height as usize);
    let zt = &f.true_depth;
    f.valid = 0;
    for v in 0..h {
        for u in 0..w {
            let i = v * w + u;
            let z = zt[i] as f64;
            let mut ok = z > 0.0 && z >= m.range.0 && z <= m.range.1;
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
            f.depth[i] = if ok {
                let zm = z + rng.gauss(m.noise.sigma(z, k.fx, m.baseline));
                if zm > 0.0 {
                    f.valid += 1;
                    zm as f32
                } else {
                    0.0
                }
            } else {
                0.0
            };
        }
    }
}
