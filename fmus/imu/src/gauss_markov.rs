//! First-order Gauss-Markov process, discretized exactly for any time step.
//!
//! dx = -x/T dt + q dW. Over a step dt: x <- phi x + sqrt(q^2 T/2 (1 - phi^2)) n with
//! phi = exp(-dt/T) and n ~ N(0, 1) (the update gz-sensors' GaussianNoiseModel uses for its
//! dynamic bias, after RotorS). Exact for any dt, so a long communication step can jump the
//! process in one draw without changing its statistics. Stationary variance: q^2 T / 2.
//!
//! A process may hold its value for a while ([`GaussMarkov::hold`]): it then updates only once
//! `hold` seconds have accumulated, exactly over that interval. A hold of T/100 changes
//! nothing visible (the process moves about 1 % of its spread in that time) and makes the
//! slow processes of the flicker bank nearly free at a 200 Hz sample rate.

use agrisim_math::Rng;

#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct GaussMarkov {
    /// Driving noise density q [unit/sqrt(s)].
    pub drive: f64,
    /// Correlation time T [s].
    pub correlation_time: f64,
    pub value: f64,
    /// Minimum time between updates [s] (0: every step).
    pub hold: f64,
    /// Time accumulated since the last update [s].
    elapsed: f64,
    /// (dt, phi, sigma) of the last update, reused while dt stays the same.
    cache: (f64, f64, f64),
}

impl GaussMarkov {
    /// A process starting at 0 (gz's dynamic bias starts there).
    pub fn new(drive: f64, correlation_time: f64) -> GaussMarkov {
        GaussMarkov { drive, correlation_time, value: 0.0, hold: 0.0, elapsed: 0.0, cache: (f64::NAN, 0.0, 0.0) }
    }

    /// A process with stationary standard deviation `stddev`, started in its stationary
    /// distribution (so its statistics do not depend on when a run began).
    pub fn stationary(stddev: f64, correlation_time: f64, rng: &mut Rng) -> GaussMarkov {
        let drive = stddev * (2.0 / correlation_time).sqrt();
        let mut p = GaussMarkov::new(drive, correlation_time);
        p.value = rng.gauss(stddev);
        p
    }

    /// Off when either figure is zero, as in gz.
    pub fn active(&self) -> bool {
        self.drive > 0.0 && self.correlation_time > 0.0
    }

    pub fn stationary_stddev(&self) -> f64 {
        self.drive * (self.correlation_time / 2.0).sqrt()
    }

    /// Advances by `dt` seconds; draws nothing when inactive or while holding.
    pub fn advance(&mut self, dt: f64, rng: &mut Rng) {
        if !self.active() || dt <= 0.0 {
            return;
        }
        self.elapsed += dt;
        if self.elapsed < self.hold {
            return;
        }
        let dt = std::mem::take(&mut self.elapsed);
        if self.cache.0 != dt {
            let t = self.correlation_time;
            let phi = (-dt / t).exp();
            // -expm1(-2dt/T) keeps precision when dt << T.
            let sigma = (self.drive * self.drive * t / 2.0 * -(-2.0 * dt / t).exp_m1()).sqrt();
            self.cache = (dt, phi, sigma);
        }
        let (_, phi, sigma) = self.cache;
        self.value = phi * self.value + rng.gauss(sigma);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stationary_variance_and_lag_one_correlation() {
        let mut rng = Rng::new(3);
        let (sd, t, dt) = (2.0, 0.5, 0.01);
        let mut p = GaussMarkov::stationary(sd, t, &mut rng);
        let n = 400_000;
        let (mut s2, mut s11) = (0.0, 0.0);
        let mut prev = p.value;
        for _ in 0..n {
            p.advance(dt, &mut rng);
            s2 += p.value * p.value;
            s11 += p.value * prev;
            prev = p.value;
        }
        let var = s2 / n as f64;
        assert!((var / (sd * sd) - 1.0).abs() < 0.05, "variance {var}");
        let rho = s11 / s2;
        assert!((rho - (-dt / t).exp()).abs() < 0.005, "lag-1 correlation {rho}");
    }

    #[test]
    fn holding_keeps_the_statistics_at_update_instants() {
        let mut rng = Rng::new(4);
        let (sd, t) = (1.0, 1.0);
        let mut p = GaussMarkov::stationary(sd, t, &mut rng);
        p.hold = t / 100.0;
        let n = 2_000_000;
        let (mut s2, mut changes) = (0.0, 0);
        let mut prev = p.value;
        for _ in 0..n {
            p.advance(0.001, &mut rng);
            s2 += p.value * p.value;
            if p.value != prev {
                changes += 1;
            }
            prev = p.value;
        }
        assert!((s2 / n as f64 - 1.0).abs() < 0.05, "variance {}", s2 / n as f64);
        // Updates every 10 steps (11 when rounding leaves the sum a hair short).
        assert!((n / 11..=n / 10).contains(&changes), "{changes} updates");
    }

    #[test]
    fn one_long_jump_has_the_stationary_spread() {
        // From 0, after dt >> T the value is N(0, stationary variance).
        let mut rng = Rng::new(5);
        let n = 100_000;
        let mut s2 = 0.0;
        for _ in 0..n {
            let mut p = GaussMarkov::new(1.0, 2.0);
            p.advance(1e3, &mut rng);
            s2 += p.value * p.value;
        }
        assert!((s2 / n as f64 - 1.0).abs() < 0.02);
    }
}
