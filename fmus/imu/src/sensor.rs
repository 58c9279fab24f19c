//! The IMU without FMI: sample clock, mount, noise state. The FMU wraps it; long statistical
//! tests (Allan variance over hours of samples) drive it directly.

use crate::frame::{Quat, Vec3};
use crate::motion::{Mount, Truth};
use crate::noise::{NoiseParams, TriadNoise};
use agrisim_math::Rng;

/// Most samples computed in one communication step. Beyond it the step jumps to its last
/// sample: the noise processes are advanced exactly over the gap, so the published sample has
/// the same statistics, and an absurd step (1e6 s at 200 Hz) stays cheap.
pub const MAX_SAMPLES_PER_STEP: i64 = 100_000;

/// One IMU reading.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sample {
    pub stamp_ns: i64,
    pub angular_velocity: Vec3,
    pub linear_acceleration: Vec3,
    pub orientation: Quat,
}

#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct ImuSensor {
    pub mount: Mount,
    pub gravity: f64,
    period_ns: i64,
    gyro: TriadNoise,
    accel: TriadNoise,
    gyro_white: f64,
    accel_white: f64,
    rng: Rng,
    /// Time the noise processes are at (the latest sample's stamp).
    noise_ns: i64,
}

impl ImuSensor {
    /// A sensor whose noise starts at `start_ns`. Draws the turn-on biases from `seed`.
    pub fn new(
        rate: f64,
        mount: Mount,
        gravity: f64,
        gyro: &NoiseParams,
        accel: &NoiseParams,
        seed: u64,
        start_ns: i64,
    ) -> Result<ImuSensor, String> {
        if !(rate.is_finite() && rate > 0.0) {
            return Err(format!("parameter rate must be positive and finite, got {rate}"));
        }
        gyro.validate("gyro")?;
        accel.validate("accel")?;
        let mut rng = Rng::new(seed);
        Ok(ImuSensor {
            mount,
            gravity,
            period_ns: ((1e9 / rate).round() as i64).max(1),
            gyro: TriadNoise::new(gyro, rate, &mut rng),
            accel: TriadNoise::new(accel, rate, &mut rng),
            gyro_white: gyro.white_stddev(rate),
            accel_white: accel.white_stddev(rate),
            rng,
            noise_ns: start_ns,
        })
    }

    pub fn period_ns(&self) -> i64 {
        self.period_ns
    }

    /// Per-sample white-noise standard deviations (gyro, accel), for message covariances.
    pub fn white_stddev(&self) -> (f64, f64) {
        (self.gyro_white, self.accel_white)
    }

    /// Sample instants k * period in (from_ns, to_ns], at most [`MAX_SAMPLES_PER_STEP`] of
    /// them (the last ones).
    pub fn instants(&self, from_ns: i64, to_ns: i64) -> impl Iterator<Item = i64> {
        let p = self.period_ns;
        let last = to_ns.div_euclid(p);
        let first = (from_ns.div_euclid(p) + 1).max(last - MAX_SAMPLES_PER_STEP + 1);
        (first..=last).map(move |k| k.saturating_mul(p))
    }

    /// Reads `truth` at `stamp_ns` (not before the previous sample): bias processes advance to
    /// the stamp, then each axis gets its bias and a fresh white-noise draw.
    pub fn sample(&mut self, stamp_ns: i64, truth: &Truth) -> Sample {
        let dt = (stamp_ns.saturating_sub(self.noise_ns)) as f64 * 1e-9;
        if dt > 0.0 {
            self.gyro.advance(dt, &mut self.rng);
            self.accel.advance(dt, &mut self.rng);
            self.noise_ns = stamp_ns;
        }
        Sample {
            stamp_ns,
            angular_velocity: self.gyro.apply(truth.angular_velocity, &mut self.rng),
            linear_acceleration: self.accel.apply(truth.specific_force, &mut self.rng),
            orientation: truth.orientation,
        }
    }
}
