//! Default noise figures and where they come from.
//!
//! The Livox MID-360 carries a TDK InvenSense ICM-40609-D. Its datasheet (DS-000330 rev 1.2,
//! 2022-06-07, "Features") gives the white-noise densities and the offset temperature
//! coefficients; it gives no bias instability. That figure is taken from a measured part of the
//! same family instead: the InvenSense MPU-6000 characterised by D. R. Greenheck, "Design and
//! Characterization of a Low Cost MEMS IMU Cluster for Precision Navigation", Marquette
//! University thesis, 2009, sec. 2.2 (the values AirSim's `ImuSimpleParams` defaults cite):
//! 4.6 deg/h at tau = 500 s (gyro), 36 ug at tau = 800 s (accelerometer). An older part than
//! the ICM-40609-D, so on the pessimistic side.

use std::f64::consts::PI;

/// Standard gravity [m/s^2] (CGPM 1901), also the g of "ug".
pub const STANDARD_GRAVITY: f64 = 9.80665;

/// ICM-40609-D gyro noise 4.5 mdps/sqrt(Hz) -> rad/s/sqrt(Hz).
pub const GYRO_NOISE_DENSITY: f64 = 4.5e-3 * PI / 180.0;
/// ICM-40609-D accel noise 100 ug/sqrt(Hz) -> m/s^2/sqrt(Hz).
pub const ACCEL_NOISE_DENSITY: f64 = 100e-6 * STANDARD_GRAVITY;

/// Greenheck 2009 (MPU-6000): gyro bias instability 4.6 deg/h -> rad/s.
pub const GYRO_BIAS_INSTABILITY: f64 = 4.6 / 3600.0 * PI / 180.0;
/// Greenheck 2009 (MPU-6000): accel bias instability 36 ug -> m/s^2.
pub const ACCEL_BIAS_INSTABILITY: f64 = 36e-6 * STANDARD_GRAVITY;
/// Averaging times at which Greenheck 2009 read those minima [s].
pub const GYRO_ALLAN_MINIMUM_TAU: f64 = 500.0;
pub const ACCEL_ALLAN_MINIMUM_TAU: f64 = 800.0;

/// Bias random walk (gz "dynamic bias", rate per sqrt(s)) that puts the minimum of the Allan
/// deviation N^2/tau + K^2 tau/3 at `tau_min`: K = sqrt(3) N / tau_min. Derived, so that the
/// modelled curve bottoms out where the measured one did.
pub const fn random_walk_for_minimum(noise_density: f64, tau_min: f64) -> f64 {
    1.732_050_807_568_877_2 * noise_density / tau_min
}
pub const GYRO_RANDOM_WALK: f64 = random_walk_for_minimum(GYRO_NOISE_DENSITY, GYRO_ALLAN_MINIMUM_TAU);
pub const ACCEL_RANDOM_WALK: f64 = random_walk_for_minimum(ACCEL_NOISE_DENSITY, ACCEL_ALLAN_MINIMUM_TAU);
/// Correlation time of that walk [s]: far beyond a trial and the Allan minimum, so it acts as a
/// random walk there, yet bounded over a day-long run (gz needs a finite value to enable it).
pub const RANDOM_WALK_CORRELATION_TIME: f64 = 1.0e4;

/// Turn-on bias spread (1 sigma). ICM-40609-D offset temperature coefficients, gyro
/// +-10 mdps/degC and accel +-0.15 mg/degC, times an assumed 10 degC between the last
/// calibration and the run: 0.1 deg/s and 1.5 mg. An assumption, not a datasheet figure.
pub const GYRO_TURN_ON_BIAS_STDDEV: f64 = 10e-3 * 10.0 * PI / 180.0;
pub const ACCEL_TURN_ON_BIAS_STDDEV: f64 = 0.15e-3 * 10.0 * STANDARD_GRAVITY;
