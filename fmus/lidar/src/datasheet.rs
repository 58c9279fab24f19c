//! Livox MID-360 figures the defaults come from.
//!
//! Livox Mid-360 User Manual v1.0 (2023-01), "Specifications": FOV 360 deg horizontal,
//! -7 deg to 52 deg vertical; detection range 40 m at 10 % reflectivity (70 m at 80 %);
//! close-proximity blind zone 0.1 m; range precision (1 sigma) <= 2 cm at 10 m; point rate
//! 200,000 points/s (first return); frame rate 10 Hz (typical).
//!
//! Scan-pattern geometry ([`crate::pattern`]): read off Livox's own MID-360 pattern table,
//! `scan_mode/mid360.csv` in github.com/Livox-SDK/livox_laser_simulation (rows of azimuth and
//! zenith per point): four beams fire together, about 2.8 deg apart; their fan turns with the
//! head, once per revolution; the head advances about 1.3 deg of azimuth per firing; the fan
//! centre drifts slowly across the vertical field of view.

pub const FOV_ELEVATION_MIN_DEG: f64 = -7.0;
pub const FOV_ELEVATION_MAX_DEG: f64 = 52.0;
pub const RANGE_MIN: f64 = 0.1;
/// At 10 % reflectivity: the conservative figure (greenhouse glass reflects little).
pub const RANGE_MAX: f64 = 40.0;
pub const RANGE_NOISE: f64 = 0.02;
pub const POINT_RATE: f64 = 200_000.0;
pub const FRAME_RATE: f64 = 10.0;

/// Beams per firing and their spacing along the fan [deg] (pattern table).
pub const BEAMS: usize = 4;
pub const BEAM_SPACING_DEG: f64 = 2.8;
/// Head azimuth advance per firing [deg] (pattern table).
pub const AZIMUTH_STEP_DEG: f64 = 1.3;
