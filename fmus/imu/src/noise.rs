//! The error model of one sensor axis, after gz-sensors' `GaussianNoiseModel` (the parameter
//! set of SDFormat's `<noise type="gaussian">`), plus a bias-instability term:
//!
//! reading = truth + turn-on bias + dynamic bias + flicker bias + white noise
//!
//! - white noise: N(0, stddev) per sample, stddev = noise density x sqrt(rate) (the discrete
//!   equivalent of a density sampled at `rate`; gz takes the stddev directly);
//! - turn-on bias: drawn once per run from N(bias_mean, bias_stddev), sign flipped with
//!   probability 1/2 (as gz does, so bias_mean is a magnitude);
//! - dynamic bias: gz's Gauss-Markov process (driving density `dynamic_bias_stddev`,
//!   correlation time), starting at 0; with a long correlation time it is the bias random walk;
//! - flicker bias ([`crate::flicker`]): the bias instability, which gz has no term for.

use crate::flicker::FlickerBias;
use crate::gauss_markov::GaussMarkov;
use agrisim_math::Rng;

/// Noise figures of one sensor (the same for its three axes).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NoiseParams {
    /// White noise density [unit/sqrt(Hz)] (gyro rad/s/sqrt(Hz), accel m/s^2/sqrt(Hz)).
    pub noise_density: f64,
    /// Turn-on bias magnitude mean and spread [unit].
    pub bias_mean: f64,
    pub bias_stddev: f64,
    /// gz dynamic bias: driving density [unit/sqrt(s)] and correlation time [s].
    pub dynamic_bias_stddev: f64,
    pub dynamic_bias_correlation_time: f64,
    /// Bias instability B [unit]: the Allan floor is 0.664 B.
    pub bias_instability: f64,
}

impl NoiseParams {
    pub fn validate(&self, what: &str) -> Result<(), String> {
        let all = [
            ("noise_density", self.noise_density),
            ("bias_stddev", self.bias_stddev),
            ("dynamic_bias_stddev", self.dynamic_bias_stddev),
            ("dynamic_bias_correlation_time", self.dynamic_bias_correlation_time),
            ("bias_instability", self.bias_instability),
        ];
        for (name, v) in all {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!("parameter {what}_{name} must be >= 0 and finite, got {v}"));
            }
        }
        if !self.bias_mean.is_finite() {
            return Err(format!("parameter {what}_bias_mean must be finite, got {}", self.bias_mean));
        }
        Ok(())
    }

    /// Per-sample white-noise standard deviation at `rate` [Hz].
    pub fn white_stddev(&self, rate: f64) -> f64 {
        self.noise_density * rate.sqrt()
    }
}

/// Noise state of one axis.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct AxisNoise {
    white_stddev: f64,
    turn_on_bias: f64,
    dynamic: GaussMarkov,
    flicker: FlickerBias,
}

impl AxisNoise {
    /// Draws the turn-on bias and the flicker bank's starting state.
    pub fn new(p: &NoiseParams, rate: f64, rng: &mut Rng) -> AxisNoise {
        let mut turn_on_bias = p.bias_mean + rng.gauss(p.bias_stddev);
        if (p.bias_mean != 0.0 || p.bias_stddev != 0.0) && rng.uniform() < 0.5 {
            turn_on_bias = -turn_on_bias;
        }
        AxisNoise {
            white_stddev: p.white_stddev(rate),
            turn_on_bias,
            dynamic: GaussMarkov::new(p.dynamic_bias_stddev, p.dynamic_bias_correlation_time),
            flicker: FlickerBias::new(p.bias_instability, rng),
        }
    }

    /// Moves the bias processes `dt` seconds on (exact for any dt).
    pub fn advance(&mut self, dt: f64, rng: &mut Rng) {
        self.dynamic.advance(dt, rng);
        self.flicker.advance(dt, rng);
    }

    /// The current total bias.
    pub fn bias(&self) -> f64 {
        self.turn_on_bias + self.dynamic.value + self.flicker.value()
    }

    /// One reading's error: bias plus a fresh white-noise draw.
    pub fn error(&mut self, rng: &mut Rng) -> f64 {
        self.bias() + rng.gauss(self.white_stddev)
    }
}

/// Noise of a three-axis sensor.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct TriadNoise {
    pub axes: [AxisNoise; 3],
}

impl TriadNoise {
    pub fn new(p: &NoiseParams, rate: f64, rng: &mut Rng) -> TriadNoise {
        TriadNoise { axes: std::array::from_fn(|_| AxisNoise::new(p, rate, rng)) }
    }

    pub fn advance(&mut self, dt: f64, rng: &mut Rng) {
        for a in &mut self.axes {
            a.advance(dt, rng);
        }
    }

    /// `truth` plus one reading's error on each axis.
    pub fn apply(&mut self, truth: [f64; 3], rng: &mut Rng) -> [f64; 3] {
        std::array::from_fn(|i| truth[i] + self.axes[i].error(rng))
    }
}
