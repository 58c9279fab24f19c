//! `[environment]` of a scenario: when and where the greenhouse is, the weather and the render
//! quality. Sensors get its keys as TOML text (the String parameter `environment`, like
//! `scene`) and derive light and visibility from it ([`crate::weather`]). It never changes
//! geometry: the scene depends on `[greenhouse]` and its seed only.
//!
//! What each key affects:
//! - `date`, `time`, `utc_offset`, `latitude`, `longitude`, `elevation`, `season`: the sun's
//!   position (NREL SPA, [`crate::solar`]) and so the direct beam's direction and strength;
//! - `weather`: direct and diffuse light, and the extinction of fog, rain or haze;
//! - `visibility`: overrides the weather's meteorological visibility (Koschmieder);
//! - `humidity`: the haze of clear weather (hygroscopic growth of aerosols, see
//!   [`crate::weather`]); nothing else (no condensation on the cover, no fog by itself);
//! - `temperature`, `pressure`: atmospheric refraction of the sun's elevation (SPA); nothing
//!   else (no thermal effects on sensors, no plant changes);
//! - `rain_rate`: the rain preset's LiDAR dropouts;
//! - `covering`: transmittance of the roof for direct and diffuse light;
//! - `map_x_bearing`: compass bearing of the map's +x axis (90 = east, ENU);
//! - `render_quality`: low = no shadows; medium = hard shadows; high = soft shadows (sun-disc
//!   samples) and 2x2 supersampled colour.

use crate::solar::{delta_t_estimate, SolarInput};
use serde::Deserialize;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Weather {
    Clear,
    Overcast,
    Rain,
    Fog,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Season {
    Spring,
    Summer,
    Autumn,
    Winter,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Quality {
    Low,
    Medium,
    High,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Covering {
    /// Horticultural float glass.
    Glass,
    /// Polyethylene film.
    Film,
}

/// The table as written (all keys optional).
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct Raw {
    date: Option<String>,
    time: Option<String>,
    utc_offset: Option<f64>,
    latitude: Option<f64>,
    longitude: Option<f64>,
    elevation: Option<f64>,
    season: Option<Season>,
    year: Option<i32>,
    weather: Option<Weather>,
    visibility: Option<f64>,
    rain_rate: Option<f64>,
    temperature: Option<f64>,
    humidity: Option<f64>,
    pressure: Option<f64>,
    covering: Option<Covering>,
    map_x_bearing: Option<f64>,
    render_quality: Option<Quality>,
}

/// A validated environment with defaults filled in.
#[derive(Clone, Debug, PartialEq)]
pub struct Environment {
    /// When and where, as SPA takes it: date, local time, UTC offset, place, and the
    /// temperature and pressure that bend the sun's elevation (Delta T estimated from the
    /// date). One struct, so the sun's input is not a second copy of these keys.
    pub solar: SolarInput,
    pub weather: Weather,
    /// Meteorological visibility [m] if given (else the weather's).
    pub visibility: Option<f64>,
    /// [mm/h]
    pub rain_rate: f64,
    /// Relative humidity [%].
    pub humidity: f64,
    pub covering: Covering,
    pub map_x_bearing: f64,
    pub quality: Quality,
}

/// The default place: the Westland greenhouse district, the Netherlands (52.0 N, 4.2 E), on
/// summer time (UTC+2), at midsummer noon of 2025.
impl Default for Environment {
    fn default() -> Self {
        Environment::from_toml_str("").expect("defaults are valid")
    }
}

fn range(key: &str, v: f64, lo: f64, hi: f64) -> Result<f64, String> {
    if v.is_finite() && (lo..=hi).contains(&v) {
        Ok(v)
    } else {
        Err(format!("environment.{key} must be in [{lo}, {hi}], got {v}"))
    }
}

fn parse_date(s: &str) -> Result<(i32, u32, u32), String> {
    let bad = || format!("environment.date must be \"YYYY-MM-DD\", got {s:?}");
    let p: Vec<&str> = s.split('-').collect();
    if p.len() != 3 || p[0].len() != 4 || p[1].len() != 2 || p[2].len() != 2 {
        return Err(bad());
    }
    let y: i32 = p[0].parse().map_err(|_| bad())?;
    let m: u32 = p[1].parse().map_err(|_| bad())?;
    let d: u32 = p[2].parse().map_err(|_| bad())?;
    let leap = (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
    let days = [31, if leap { 29 } else { 28 }, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31];
    if !(1..=12).contains(&m) || d < 1 || d > days[m as usize - 1] {
        return Err(format!("environment.date {s:?} is not a calendar date"));
    }
    Ok((y, m, d))
}

fn parse_time(s: &str) -> Result<(u32, u32, f64), String> {
    let bad = || format!("environment.time must be \"HH:MM\" or \"HH:MM:SS\" (local time), got {s:?}");
    let p: Vec<&str> = s.split(':').collect();
    if !(2..=3).contains(&p.len()) {
        return Err(bad());
    }
    let h: u32 = p[0].parse().map_err(|_| bad())?;
    let m: u32 = p[1].parse().map_err(|_| bad())?;
    let sec: f64 = if p.len() == 3 { p[2].parse().map_err(|_| bad())? } else { 0.0 };
    if h > 23 || m > 59 || !(0.0..60.0).contains(&sec) {
        return Err(bad());
    }
    Ok((h, m, sec))
}

/// Equinoxes and solstices (approximate dates) of the observer's hemisphere.
fn season_date(season: Season, latitude: f64) -> (u32, u32) {
    let north = match season {
        Season::Spring => (3, 20),
        Season::Summer => (6, 21),
        Season::Autumn => (9, 22),
        Season::Winter => (12, 21),
    };
    if latitude >= 0.0 {
        north
    } else {
        match north {
            (3, _) => (9, 22),
            (6, _) => (12, 21),
            (9, _) => (3, 20),
            _ => (6, 21),
        }
    }
}

impl Environment {
    /// Parses the keys of `[environment]` (no header). Errors name the key.
    pub fn from_toml_str(text: &str) -> Result<Environment, String> {
        let r: Raw = toml::from_str(text).map_err(|e| {
            // The message names the value, the snippet the key: keep both, on one line.
            let text = e.to_string();
            let one_line: Vec<&str> = text.lines().map(str::trim).filter(|l| !l.is_empty() && *l != "|").collect();
            format!("environment: {}", one_line.join(" "))
        })?;
        let latitude = range("latitude", r.latitude.unwrap_or(52.0), -90.0, 90.0)?;
        let longitude = range("longitude", r.longitude.unwrap_or(4.2), -180.0, 180.0)?;
        let (year, month, day) = match (&r.date, r.season) {
            (Some(_), Some(_)) => return Err("environment: give either date or season, not both".into()),
            (Some(d), None) => parse_date(d)?,
            (None, s) => {
                let year = r.year.unwrap_or(2025);
                range("year", year as f64, 1.0, 9999.0)?;
                let (m, d) = season_date(s.unwrap_or(Season::Summer), latitude);
                (year, m, d)
            }
        };
        if r.year.is_some() && r.date.is_some() {
            return Err("environment.year is only for season (date carries its own year)".into());
        }
        let (hour, minute, second) = parse_time(r.time.as_deref().unwrap_or("13:30"))?;
        let elevation = range("elevation", r.elevation.unwrap_or(0.0), -500.0, 9000.0)?;
        // Barometric formula of the standard atmosphere.
        let p_std = 1013.25 * (1.0 - 2.25577e-5 * elevation).powf(5.25588);
        let weather = r.weather.unwrap_or(Weather::Clear);
        let visibility = match r.visibility {
            Some(v) => Some(range("visibility", v, 1.0, 1.0e6)?),
            None => None,
        };
        let utc_offset = range("utc_offset", r.utc_offset.unwrap_or(2.0), -12.0, 14.0)?;
        let rain_rate =
            range("rain_rate", r.rain_rate.unwrap_or(if weather == Weather::Rain { 8.0 } else { 0.0 }), 0.0, 500.0)?;
        let temperature = range("temperature", r.temperature.unwrap_or(20.0), -60.0, 60.0)?;
        let humidity = range("humidity", r.humidity.unwrap_or(70.0), 0.0, 100.0)?;
        let pressure = range("pressure", r.pressure.unwrap_or(p_std), 300.0, 1100.0)?;
        Ok(Environment {
            solar: SolarInput {
                year,
                month,
                day,
                hour,
                minute,
                second,
                utc_offset,
                latitude,
                longitude,
                elevation,
                pressure,
                temperature,
                delta_t: delta_t_estimate(year, month),
            },
            weather,
            visibility,
            rain_rate,
            humidity,
            covering: r.covering.unwrap_or(Covering::Glass),
            map_x_bearing: range("map_x_bearing", r.map_x_bearing.unwrap_or(90.0), -360.0, 360.0)?,
            quality: r.render_quality.unwrap_or(Quality::Medium),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_name_the_key() {
        for (text, key) in [
            ("latitude = 95.0", "latitude"),
            ("humidity = -1.0", "humidity"),
            ("date = \"2025-02-30\"", "date"),
            ("time = \"25:00\"", "time"),
            ("weather = \"snow\"", "weather"),
            ("render_quality = \"ultra\"", "render_quality"),
            ("wether = \"fog\"", "wether"),
            ("visibility = 0.0", "visibility"),
        ] {
            let e = Environment::from_toml_str(text).unwrap_err();
            assert!(e.contains(key), "{text}: {e}");
        }
    }

    #[test]
    fn season_picks_a_date_by_hemisphere() {
        let n = Environment::from_toml_str("season = \"winter\"").unwrap();
        assert_eq!((n.solar.month, n.solar.day), (12, 21));
        let s = Environment::from_toml_str("season = \"winter\"\nlatitude = -33.9").unwrap();
        assert_eq!((s.solar.month, s.solar.day), (6, 21));
        assert!(Environment::from_toml_str("season = \"winter\"\ndate = \"2025-01-01\"").is_err());
    }
}
