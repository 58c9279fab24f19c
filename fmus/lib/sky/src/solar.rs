//! Where the sun is: NREL's Solar Position Algorithm (SPA), Reda & Andreas, "Solar position
//! algorithm for solar radiation applications", Solar Energy 76 (2004) 577-589 (corrigendum
//! 2008), for years -2000..6000 with an uncertainty of +/- 0.0003 deg. Implemented step by
//! step from the paper (section 3); the periodic terms are the paper's tables
//! ([`crate::solar_terms`]).
//!
//! The camera needs the sun's direction (azimuth, refracted elevation) and the air mass the
//! direct beam crosses; SPA is the reference algorithm pvlib and NREL use, so the result can
//! be checked against both the paper's worked example and pvlib's independent code.

use crate::solar_terms::*;

/// When and where: local civil time with its offset from UTC, and the observer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolarInput {
    pub year: i32,
    pub month: u32,
    pub day: u32,
    pub hour: u32,
    pub minute: u32,
    pub second: f64,
    /// Hours east of UTC (e.g. -7 for MST, +1 for CET).
    pub utc_offset: f64,
    /// Degrees, north positive.
    pub latitude: f64,
    /// Degrees, east positive.
    pub longitude: f64,
    /// Metres above sea level.
    pub elevation: f64,
    /// Annual mean local pressure [hPa] (refraction).
    pub pressure: f64,
    /// Annual mean local temperature [deg C] (refraction).
    pub temperature: f64,
    /// TT - UT1 [s]; see [`delta_t_estimate`].
    pub delta_t: f64,
}

/// What SPA gives (topocentric, degrees).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolarPosition {
    /// Zenith angle with atmospheric refraction.
    pub zenith: f64,
    /// Elevation with refraction (90 - zenith).
    pub elevation: f64,
    /// Elevation without refraction.
    pub elevation_geometric: f64,
    /// Compass azimuth: clockwise from north (the paper's Phi).
    pub azimuth: f64,
}

fn rem360(x: f64) -> f64 {
    x.rem_euclid(360.0)
}

/// Julian day of a UT instant (paper eq. 4, Gregorian calendar); `day` may carry a fraction
/// outside 1..31, the formula is linear in it.
pub fn julian_day(year: i32, month: u32, day: f64) -> f64 {
    let (mut y, mut m) = (year as f64, month as f64);
    if m < 3.0 {
        y -= 1.0;
        m += 12.0;
    }
    let a = (y / 100.0).floor();
    let b = 2.0 - a + (a / 4.0).floor();
    (365.25 * (y + 4716.0)).floor() + (30.6001 * (m + 1.0)).floor() + day + b - 1524.5
}

/// TT - UT1 [s] from the polynomial fits of Espenak & Meeus (NASA "Five Millennium Canon of
/// Solar Eclipses", 2006) for 1941-2150; the long-term parabola outside that span.
pub fn delta_t_estimate(year: i32, month: u32) -> f64 {
    let y = year as f64 + (month as f64 - 0.5) / 12.0;
    let long_term = |y: f64| {
        let u = (y - 1820.0) / 100.0;
        -20.0 + 32.0 * u * u
    };
    if y < 1941.0 {
        long_term(y)
    } else if y < 1961.0 {
        let t = y - 1950.0;
        29.07 + 0.407 * t - t * t / 233.0 + t.powi(3) / 2547.0
    } else if y < 1986.0 {
        let t = y - 1975.0;
        45.45 + 1.067 * t - t * t / 260.0 - t.powi(3) / 718.0
    } else if y < 2005.0 {
        let t = y - 2000.0;
        63.86 + 0.3345 * t - 0.060374 * t * t
            + 0.0017275 * t.powi(3)
            + 0.000651814 * t.powi(4)
            + 0.00002373599 * t.powi(5)
    } else if y < 2050.0 {
        let t = y - 2000.0;
        62.92 + 0.32217 * t + 0.005589 * t * t
    } else if y < 2150.0 {
        long_term(y) - 0.5628 * (2150.0 - y)
    } else {
        long_term(y)
    }
}

fn series<const N: usize>(terms: &[[f64; 3]; N], x: f64) -> f64 {
    terms.iter().map(|[a, b, c]| a * (b + c * x).cos()).sum()
}

fn poly(c: &[f64], x: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &k| acc * x + k)
}

/// Earth's heliocentric longitude, latitude [deg] and radius [AU] (paper 3.2).
fn earth(jme: f64) -> (f64, f64, f64) {
    let l = poly(
        &[series(&L0, jme), series(&L1, jme), series(&L2, jme), series(&L3, jme), series(&L4, jme), series(&L5, jme)],
        jme,
    ) / 1e8;
    let b = poly(&[series(&B0, jme), series(&B1, jme)], jme) / 1e8;
    let r =
        poly(&[series(&R0, jme), series(&R1, jme), series(&R2, jme), series(&R3, jme), series(&R4, jme)], jme) / 1e8;
    (rem360(l.to_degrees()), b.to_degrees(), r)
}

/// Nutation in longitude and obliquity [deg] (paper 3.4).
fn nutation(jce: f64) -> (f64, f64) {
    let t2 = jce * jce;
    let t3 = t2 * jce;
    let x = [
        297.85036 + 445267.111480 * jce - 0.0019142 * t2 + t3 / 189474.0,
        357.52772 + 35999.050340 * jce - 0.0001603 * t2 - t3 / 300000.0,
        134.96298 + 477198.867398 * jce + 0.0086972 * t2 + t3 / 56250.0,
        93.27191 + 483202.017538 * jce - 0.0036825 * t2 + t3 / 327270.0,
        125.04452 - 1934.136261 * jce + 0.0020708 * t2 + t3 / 450000.0,
    ];
    let (mut dpsi, mut deps) = (0.0, 0.0);
    for (y, [a, b, c, d]) in NUT_Y.iter().zip(NUT_ABCD.iter()) {
        let arg: f64 = (0..5).map(|j| x[j] * y[j] as f64).sum::<f64>().to_radians();
        dpsi += (a + b * jce) * arg.sin();
        deps += (c + d * jce) * arg.cos();
    }
    (dpsi / 36_000_000.0, deps / 36_000_000.0)
}

/// The sun's topocentric position (paper section 3, steps 3.1-3.15).
pub fn solar_position(i: &SolarInput) -> SolarPosition {
    let ut_hours = i.hour as f64 + i.minute as f64 / 60.0 + i.second / 3600.0 - i.utc_offset;
    let jd = julian_day(i.year, i.month, i.day as f64 + ut_hours / 24.0);
    let jde = jd + i.delta_t / 86400.0;
    let jc = (jd - 2451545.0) / 36525.0;
    let jce = (jde - 2451545.0) / 36525.0;
    let jme = jce / 10.0;

    let (l, b, r) = earth(jme);
    let theta = rem360(l + 180.0);
    let beta = -b;
    let (dpsi, deps) = nutation(jce);
    let u = jme / 10.0;
    let eps0 = poly(&[84381.448, -4680.93, -1.55, 1999.25, -51.38, -249.67, -39.05, 7.12, 27.87, 5.79, 2.45], u);
    let eps = (eps0 / 3600.0 + deps).to_radians();
    let lambda = (theta + dpsi - 20.4898 / (3600.0 * r)).to_radians();
    let nu0 =
        rem360(280.46061837 + 360.98564736629 * (jd - 2451545.0) + 0.000387933 * jc * jc - jc.powi(3) / 38710000.0);
    let nu = nu0 + dpsi * eps.cos();
    let beta_r = beta.to_radians();
    let alpha = rem360((lambda.sin() * eps.cos() - beta_r.tan() * eps.sin()).atan2(lambda.cos()).to_degrees());
    let delta = (beta_r.sin() * eps.cos() + beta_r.cos() * eps.sin() * lambda.sin()).asin();
    let h = rem360(nu + i.longitude - alpha).to_radians();

    // Parallax (3.12).
    let xi = (8.794 / (3600.0 * r)).to_radians();
    let phi = i.latitude.to_radians();
    let uu = (0.99664719 * phi.tan()).atan();
    let x = uu.cos() + i.elevation / 6378140.0 * phi.cos();
    let y = 0.99664719 * uu.sin() + i.elevation / 6378140.0 * phi.sin();
    let dalpha = (-x * xi.sin() * h.sin()).atan2(delta.cos() - x * xi.sin() * h.cos());
    let delta_p = ((delta.sin() - y * xi.sin()) * dalpha.cos()).atan2(delta.cos() - x * xi.sin() * h.cos());
    let hp = h - dalpha;

    // Elevation, refraction, zenith, azimuth (3.14-3.15).
    let e0 = (phi.sin() * delta_p.sin() + phi.cos() * delta_p.cos() * hp.cos()).asin().to_degrees();
    let de = if e0 >= -(0.26667 + 0.5667) {
        (i.pressure / 1010.0) * (283.0 / (273.0 + i.temperature)) * 1.02
            / (60.0 * (e0 + 10.3 / (e0 + 5.11)).to_radians().tan())
    } else {
        0.0
    };
    let e = e0 + de;
    let gamma = rem360(hp.sin().atan2(hp.cos() * phi.sin() - delta_p.tan() * phi.cos()).to_degrees());
    SolarPosition { zenith: 90.0 - e, elevation: e, elevation_geometric: e0, azimuth: rem360(gamma + 180.0) }
}

/// Relative optical air mass at an apparent zenith angle [deg]: Kasten & Young, "Revised
/// optical air mass tables and approximation formula", Applied Optics 28 (1989) 4735.
/// Infinite for the sun below the horizon.
pub fn air_mass(zenith_deg: f64) -> f64 {
    if zenith_deg >= 90.0 {
        return f64::INFINITY;
    }
    1.0 / (zenith_deg.to_radians().cos() + 0.50572 * (96.07995 - zenith_deg).powf(-1.6364))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The paper's worked example (Table A5.1): Golden, Colorado, 17 Oct 2003 12:30:30 MST.
    #[test]
    fn reda_andreas_worked_example() {
        let i = SolarInput {
            year: 2003,
            month: 10,
            day: 17,
            hour: 12,
            minute: 30,
            second: 30.0,
            utc_offset: -7.0,
            latitude: 39.742476,
            longitude: -105.1786,
            elevation: 1830.14,
            pressure: 820.0,
            temperature: 11.0,
            delta_t: 67.0,
        };
        assert!((julian_day(2003, 10, 17.0 + (12.5 + 30.0 / 3600.0 + 7.0) / 24.0) - 2452930.312847).abs() < 1e-6);
        let p = solar_position(&i);
        assert!((p.zenith - 50.11162).abs() < 1e-5, "zenith {}", p.zenith);
        assert!((p.azimuth - 194.34024).abs() < 1e-5, "azimuth {}", p.azimuth);
    }

    #[test]
    fn julian_day_examples_of_the_paper() {
        // Table 4 of Reda & Andreas.
        assert_eq!(julian_day(2000, 1, 1.5), 2451545.0);
        assert_eq!(julian_day(1987, 6, 19.5), 2446966.0);
        assert_eq!(julian_day(1600, 12, 31.0), 2305812.5);
    }

    #[test]
    fn air_mass_is_one_overhead_and_grows_toward_the_horizon() {
        assert!((air_mass(0.0) - 1.0).abs() < 1e-3);
        assert!((air_mass(60.0) - 2.0).abs() < 0.01);
        assert!(air_mass(89.0) > 20.0 && air_mass(90.0).is_infinite());
    }
}
