//! The light a frame is rendered under ([`Lighting`]): the sun's direction and beam, diffuse
//! sky and floor light, the cover's transmittance, shadows (by render quality) and fog, from
//! fixed parameters or from the environment's conditions; and the irradiance sum on a surface
//! ([`irradiance`]). Colours, albedos and the exposure are [`shading`]'s.

use crate::optics::Vec3;
use crate::shading::{self, Palette};
use agrisim_sky::environment::{Quality, Weather};
use agrisim_sky::weather::Conditions;

/// How shadows of the direct beam are computed (render quality).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shadows {
    /// No shadow rays: every surface facing the sun gets the beam (through one cover layer).
    None,
    /// One shadow ray toward the sun's centre.
    Hard,
    /// `n` shadow rays spread over the sun's disc (angular radius 0.2666 deg): penumbrae.
    Soft(u32),
}

/// Fog or haze between the camera and a surface (Koschmieder): the surface's colour fades
/// toward the airlight with transmittance exp(-beta d); stereo matching needs contrast, so
/// depth is lost beyond `depth_limit` (10 % contrast left: ln(10) / beta).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fog {
    pub beta: f64,
    /// Linear RGB of the airlight (the fog lit by the diffuse light).
    pub colour: [f64; 3],
    pub depth_limit: f64,
}

impl Fog {
    pub fn new(beta: f64, colour: [f64; 3]) -> Fog {
        Fog { beta, colour, depth_limit: 10f64.ln() / beta }
    }
}

/// Irradiances are relative to the camera's fixed exposure: a white Lambertian surface under
/// irradiance 1 shows white. See [`irradiance`] for the sum.
#[derive(Clone, Debug)]
pub struct Lighting {
    /// Unit vector toward the sun in the map frame.
    pub sun: Vec3,
    /// The sun is above the horizon.
    pub sun_up: bool,
    /// Direct beam on a surface facing the sun, before the cover.
    pub direct: f64,
    /// Diffuse light on an upward surface (inside the cover).
    pub diffuse: f64,
    /// Light reflected by the floor onto downward surfaces.
    pub ground: f64,
    /// Diffuse light weighted by the sky view factor (1 + n_z) / 2; false = from all around.
    pub sky_view: bool,
    /// Transmittance of each glass or film layer a shadow ray crosses.
    pub cover_tau: f64,
    pub shadows: Shadows,
    /// 2x2 supersampled colour (depth and labels stay one ray per pixel centre).
    pub supersample: bool,
    /// Linear RGB of rays that hit nothing.
    pub sky: [f64; 3],
    /// Primary rays see through glass and film (colour only; depth and labels keep the first
    /// hit): the radiance behind, times this transmittance per layer. None = opaque cover.
    pub cover_see_through: Option<f64>,
    pub fog: Option<Fog>,
}

impl Lighting {
    /// Without an environment: the sun at a fixed azimuth (counter-clockwise from map +x) and
    /// elevation, `ambient` diffuse light relative to the beam, exposed so that a surface
    /// facing the sun shows its albedo; hard shadows, glass passes all light.
    pub fn new(azimuth_deg: f64, elevation_deg: f64, ambient: f64) -> Lighting {
        let (a, e) = (azimuth_deg.to_radians(), elevation_deg.to_radians());
        let p = Palette::default();
        Lighting {
            sun: [e.cos() * a.cos(), e.cos() * a.sin(), e.sin()],
            sun_up: elevation_deg > 0.0,
            direct: 1.0 / (1.0 + ambient),
            diffuse: ambient / (1.0 + ambient),
            ground: 0.0,
            sky_view: false,
            cover_tau: 1.0,
            shadows: Shadows::Hard,
            supersample: false,
            sky: shading::SKY.map(|c| p.linear(c)),
            cover_see_through: None,
            fog: None,
        }
    }

    /// From the environment's sun, weather and cover at the fixed exposure
    /// [`shading::EXPOSURE`] (W/m2 that render white).
    pub fn from_conditions(c: &Conditions) -> Lighting {
        let e = shading::EXPOSURE;
        let sun = c.sun_direction();
        let cos_z = sun[2].max(0.0);
        let direct = c.dni / e;
        let diffuse = c.tau_diffuse * c.dhi / e;
        let global_inside = c.tau_direct * direct * cos_z + diffuse;
        let p = Palette::default();
        let floor = p.albedo(agrisim_scene::Kind::Floor);
        let floor_albedo = (floor[0] + floor[1] + floor[2]) / 3.0;
        // The sky outside, seen through the cover: an isotropic sky of diffuse irradiance DHI
        // has radiance DHI / pi, which a white Lambertian surface under the whole sky matches:
        // in exposure units its luminance is DHI / EXPOSURE. Blue when clear, grey otherwise.
        let tint = match c.weather {
            Weather::Clear => shading::SKY.map(|v| p.linear(v)),
            _ => [1.0, 1.0, 1.0],
        };
        let y = 0.2126 * tint[0] + 0.7152 * tint[1] + 0.0722 * tint[2];
        let sky = tint.map(|v| v / y * c.dhi / e);
        let (shadows, supersample) = match c.quality {
            Quality::Low => (Shadows::None, false),
            Quality::Medium => (Shadows::Hard, false),
            Quality::High => (Shadows::Soft(5), true),
        };
        Lighting {
            sun,
            sun_up: c.sun.elevation > 0.0,
            direct,
            diffuse,
            ground: floor_albedo * global_inside,
            sky_view: true,
            cover_tau: c.tau_direct,
            shadows,
            supersample,
            sky,
            cover_see_through: Some(c.tau_diffuse),
            fog: (c.extinction > 0.0).then(|| Fog::new(c.extinction, [0.9 * global_inside; 3])),
        }
    }

    /// Shadow rays per lit point (directions by `render`'s sun disc samples); None: no
    /// shadows.
    pub fn sun_samples(&self) -> Option<u32> {
        match self.shadows {
            Shadows::None => None,
            Shadows::Hard => Some(1),
            Shadows::Soft(n) => Some(n.max(1)),
        }
    }
}

/// Relative irradiance on a surface with normal z-component `n_z`: the beam (`beam` = its
/// unblocked fraction, after cover layers) times cos(incidence), diffuse sky light (weighted
/// by the sky view factor (1 + n_z) / 2 when `sky_view`), and light from the floor on
/// downward faces ((1 - n_z) / 2).
pub fn irradiance(l: &Lighting, cos_sun: f64, beam: f64, n_z: f64) -> f64 {
    let direct = l.direct * beam * cos_sun.max(0.0);
    let sky = if l.sky_view { 0.5 * (1.0 + n_z) } else { 1.0 };
    direct + l.diffuse * sky + l.ground * 0.5 * (1.0 - n_z)
}
