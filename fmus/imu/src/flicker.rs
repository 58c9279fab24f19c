//! Bias instability: flicker (1/f) noise as a bank of Gauss-Markov processes.
//!
//! The flat bottom of a MEMS Allan deviation curve ("bias instability" B, read as the minimum
//! divided by sqrt(2 ln 2 / pi) = 0.664, IEEE Std 952-1997 annex C) comes from 1/f noise,
//! which no single Gauss-Markov process reproduces: one GM gives a hump, not a floor. A sum of
//! GM processes with correlation times spaced evenly in log T and equal variances has a PSD
//! proportional to 1/f between the shortest and longest time (the classic construction of
//! 1/f noise from relaxation processes). With a ratio r between neighbouring times, each
//! stationary variance B^2 ln(r) / pi matches the one-sided PSD B^2 / (2 pi f) of IEEE 952.
//! Two processes per decade from 1 s to 1e4 s keep the Allan deviation within 1.5 % of 0.664 B
//! for averaging times of 50-1000 s and within 4 % for 10-3000 s (analytic check below).

use crate::gauss_markov::GaussMarkov;
use agrisim_math::Rng;

/// Shortest and longest correlation time of the bank [s], and processes per decade.
pub const SHORTEST: f64 = 1.0;
pub const LONGEST: f64 = 1.0e4;
pub const PER_DECADE: usize = 2;
/// Each process updates after 1 % of its correlation time (see [`GaussMarkov::hold`]).
pub const HOLD_FRACTION: f64 = 0.01;

#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct FlickerBias {
    processes: Vec<GaussMarkov>,
}

impl FlickerBias {
    /// A bank whose Allan floor is 0.664 `instability`, started stationary. Empty when 0.
    pub fn new(instability: f64, rng: &mut Rng) -> FlickerBias {
        if instability <= 0.0 {
            return FlickerBias::default();
        }
        let ratio = 10f64.powf(1.0 / PER_DECADE as f64);
        let stddev = instability * (ratio.ln() / std::f64::consts::PI).sqrt();
        let count = ((LONGEST / SHORTEST).log10() * PER_DECADE as f64).round() as usize + 1;
        let processes = (0..count)
            .map(|i| {
                let mut p = GaussMarkov::stationary(stddev, SHORTEST * ratio.powi(i as i32), rng);
                p.hold = p.correlation_time * HOLD_FRACTION;
                p
            })
            .collect();
        FlickerBias { processes }
    }

    pub fn advance(&mut self, dt: f64, rng: &mut Rng) {
        for p in &mut self.processes {
            p.advance(dt, rng);
        }
    }

    pub fn value(&self) -> f64 {
        self.processes.iter().map(|p| p.value).sum()
    }

    /// Analytic Allan variance of the bank at averaging time `tau` (for checks and docs).
    pub fn allan_variance(&self, tau: f64) -> f64 {
        self.processes
            .iter()
            .map(|p| {
                // Allan variance of a GM with driving density q, correlation time T.
                let (q2, t) = (p.drive * p.drive, p.correlation_time);
                let x = tau / t;
                q2 * t * t / tau * (1.0 - (3.0 - 4.0 * (-x).exp() + (-2.0 * x).exp()) / (2.0 * x))
            })
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn analytic_allan_floor_is_flat_at_0_664_b() {
        let b = 2.0e-5;
        let bank = FlickerBias::new(b, &mut Rng::new(1));
        let floor = b * (2.0 * std::f64::consts::LN_2 / std::f64::consts::PI).sqrt();
        for k in 0..=40 {
            let tau = 10f64.powf(1.0 + 2.5 * k as f64 / 40.0); // 10 .. 3162 s
            let r = bank.allan_variance(tau).sqrt() / floor;
            let tol = if (50.0..=1000.0).contains(&tau) { 0.015 } else { 0.04 };
            assert!((r - 1.0).abs() < tol, "tau {tau}: {r}");
        }
    }

    #[test]
    fn zero_instability_is_silent_and_draws_nothing() {
        let mut rng = Rng::new(9);
        let mut bank = FlickerBias::new(0.0, &mut rng);
        bank.advance(0.005, &mut rng);
        assert_eq!(bank.value(), 0.0);
        assert_eq!(rng.next_u64(), Rng::new(9).next_u64());
    }
}
