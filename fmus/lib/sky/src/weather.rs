//! From an [`Environment`] to what sensors need: the sun's direction in the map, the direct
//! and diffuse irradiance outside the greenhouse, the cover's transmittance, and the
//! atmosphere's extinction coefficient.
//!
//! Models and figures (chosen for being standard and simple, not fitted to a site):
//! - clear sky: direct normal irradiance DNI = 1353 x 0.7^(AM^0.678) W/m2 (Meinel & Meinel,
//!   "Applied Solar Energy", 1976) with the Kasten-Young air mass AM, and global horizontal
//!   GHI = 1098 cos z exp(-0.057 / cos z) (Haurwitz 1945); diffuse DHI = GHI - DNI cos z (at
//!   least 10 % of GHI). Both fall with air mass, so dusk is darker at a fixed exposure; with
//!   the sun below the horizon there is no light (twilight is not modelled);
//! - overcast: no direct beam, GHI = clear GHI x (1 - 0.75) (Kasten & Czeplak 1980 at 8/8
//!   cloud cover), all diffuse; rain: no direct beam, 15 % of clear GHI (a darker cloud deck:
//!   our choice); fog: no direct beam, 40 % of clear GHI scattered down (our choice);
//! - cover: horticultural float glass transmits about 0.90 of direct light at near-normal
//!   incidence and 0.82 of diffuse (hemispherical); polyethylene film 0.88 and 0.78 (typical
//!   catalogue figures);
//! - extinction beta [1/m] from the meteorological visibility V by Koschmieder's law,
//!   beta = 3.912 / V (2 % contrast threshold). Clear and overcast air: haze with a dry
//!   visibility of 40 km, thickened by humidity through hygroscopic growth of the aerosol,
//!   beta = beta_dry (1 - RH)^-0.5 (Haenel's growth law, exponent 0.5 a typical value; RH
//!   capped at 99 %); rain: 1.076 R^0.67 dB/km for rain rate R in mm/h (the free-space optics
//!   rain attenuation law, Carbonneau 1998), plus the haze; fog: V = 40 m unless `visibility`
//!   is given. A rain preset models a sensor in the rain; inside a closed greenhouse rain
//!   only darkens the sky.

use crate::environment::{Covering, Environment, Quality, Weather};
use crate::solar::{air_mass, solar_position, SolarPosition};

/// Koschmieder's constant: ln(1 / 0.02).
pub const KOSCHMIEDER: f64 = 3.912;

#[derive(Clone, Debug, PartialEq)]
pub struct Conditions {
    pub sun: SolarPosition,
    /// Direction toward the sun in the map frame: counter-clockwise from +x [deg].
    pub sun_map_azimuth: f64,
    /// Direct normal irradiance outside [W/m2].
    pub dni: f64,
    /// Diffuse horizontal irradiance outside [W/m2].
    pub dhi: f64,
    /// Cover transmittance for direct and diffuse light.
    pub tau_direct: f64,
    pub tau_diffuse: f64,
    /// Extinction coefficient of the air [1/m].
    pub extinction: f64,
    /// Meteorological visibility [m] (3.912 / extinction).
    pub visibility: f64,
    pub weather: Weather,
    pub quality: Quality,
}

/// Clear-sky (DNI, GHI) for an apparent zenith angle [deg].
pub fn clear_sky(zenith: f64) -> (f64, f64) {
    if zenith >= 90.0 {
        return (0.0, 0.0);
    }
    let cz = zenith.to_radians().cos();
    let dni = 1353.0 * 0.7f64.powf(air_mass(zenith).powf(0.678));
    let ghi = 1098.0 * cz * (-0.057 / cz).exp();
    (dni, ghi)
}

/// Extinction of clear air with haze at relative humidity `rh` [%].
pub fn haze_extinction(rh: f64) -> f64 {
    let dry = KOSCHMIEDER / 40_000.0;
    dry * (1.0 - (rh / 100.0).min(0.99)).powf(-0.5)
}

/// Extinction of rain at `rate` mm/h [1/m] (dB/km -> 1/m: / (10 log10 e) / 1000).
pub fn rain_extinction(rate: f64) -> f64 {
    1.076 * rate.max(0.0).powf(0.67) / 4.342_944_8 / 1000.0
}

impl Conditions {
    pub fn of(env: &Environment) -> Conditions {
        let sun = solar_position(&env.solar);
        let (dni_clear, ghi_clear) = clear_sky(sun.zenith);
        let cz = sun.zenith.to_radians().cos().max(0.0);
        let (dni, dhi) = match env.weather {
            Weather::Clear => (dni_clear, (ghi_clear - dni_clear * cz).max(0.1 * ghi_clear)),
            Weather::Overcast => (0.0, 0.25 * ghi_clear),
            Weather::Rain => (0.0, 0.15 * ghi_clear),
            Weather::Fog => (0.0, 0.40 * ghi_clear),
        };
        let extinction = match (env.visibility, env.weather) {
            (Some(v), _) => KOSCHMIEDER / v,
            (None, Weather::Fog) => KOSCHMIEDER / 40.0,
            (None, Weather::Rain) => haze_extinction(env.humidity) + rain_extinction(env.rain_rate),
            (None, _) => haze_extinction(env.humidity),
        };
        let (tau_direct, tau_diffuse) = match env.covering {
            Covering::Glass => (0.90, 0.82),
            Covering::Film => (0.88, 0.78),
        };
        Conditions {
            sun,
            sun_map_azimuth: (env.map_x_bearing - sun.azimuth).rem_euclid(360.0),
            dni,
            dhi,
            tau_direct,
            tau_diffuse,
            extinction,
            visibility: KOSCHMIEDER / extinction,
            weather: env.weather,
            quality: env.quality,
        }
    }

    /// Unit vector toward the sun in the map frame (z up).
    pub fn sun_direction(&self) -> [f64; 3] {
        let (a, e) = (self.sun_map_azimuth.to_radians(), self.sun.elevation.to_radians());
        [e.cos() * a.cos(), e.cos() * a.sin(), e.sin()]
    }

    /// Fraction of a return's power left after the two-way path of length `range` [m].
    pub fn two_way_transmittance(&self, range: f64) -> f64 {
        (-2.0 * self.extinction * range).exp()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(text: &str) -> Conditions {
        Conditions::of(&Environment::from_toml_str(text).unwrap())
    }

    #[test]
    fn light_falls_at_dusk_and_under_cloud() {
        let noon = at("date = \"2025-06-21\"\ntime = \"13:40\"");
        let dusk = at("date = \"2025-06-21\"\ntime = \"21:15\"");
        let overcast = at("date = \"2025-06-21\"\ntime = \"13:40\"\nweather = \"overcast\"");
        assert!(noon.sun.elevation > 60.0 && dusk.sun.elevation < 8.0 && dusk.sun.elevation > 0.0);
        let ghi = |c: &Conditions| c.dni * c.sun.zenith.to_radians().cos().max(0.0) + c.dhi;
        assert!(ghi(&dusk) < 0.15 * ghi(&noon), "{} {}", ghi(&dusk), ghi(&noon));
        assert!(ghi(&overcast) < 0.5 * ghi(&noon) && overcast.dni == 0.0);
        // Noon sun in the Netherlands is due south: map -y with x east.
        let s = noon.sun_direction();
        assert!(s[1] < 0.0 && s[0].abs() < 0.2, "{s:?}");
    }

    #[test]
    fn fog_and_humidity_shorten_visibility() {
        assert!((at("weather = \"fog\"").visibility - 40.0).abs() < 1e-9);
        assert!(at("humidity = 95.0").visibility < 0.5 * at("humidity = 30.0").visibility);
        assert!(at("weather = \"rain\"").visibility < at("weather = \"clear\"").visibility);
    }
}
