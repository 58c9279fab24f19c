//! Statistics for trial outcomes.

/// Wilson score interval for a binomial proportion (Wilson 1927): unlike the normal
/// approximation it stays inside [0, 1] and is honest near 0 and 1, where success rates of a
/// good system live. `z` = 1.959964 for 95 %.
pub fn wilson(successes: u64, trials: u64, z: f64) -> [f64; 2] {
    if trials == 0 {
        return [0.0, 1.0];
    }
    let n = trials as f64;
    let p = successes as f64 / n;
    let z2 = z * z;
    let centre = (p + z2 / (2.0 * n)) / (1.0 + z2 / n);
    let half = z * (p * (1.0 - p) / n + z2 / (4.0 * n * n)).sqrt() / (1.0 + z2 / n);
    [(centre - half).max(0.0), (centre + half).min(1.0)]
}

/// 95 % two-sided normal quantile.
pub const Z95: f64 = 1.959_963_984_540_054;

/// Percentile by linear interpolation between order statistics (`q` in [0, 1]).
pub fn percentile(sorted: &[f64], q: f64) -> Option<f64> {
    if sorted.is_empty() {
        return None;
    }
    let pos = q.clamp(0.0, 1.0) * (sorted.len() - 1) as f64;
    let (lo, hi) = (pos.floor() as usize, pos.ceil() as usize);
    Some(sorted[lo] + (sorted[hi] - sorted[lo]) * (pos - lo as f64))
}

/// 95 % interval of the pooled success rate when trials come in clusters (scenes) that share
/// their cause of success: whole clusters are resampled with replacement (the cluster
/// bootstrap; Field and Welsh 2007), `resamples` times from `seed`, and the 2.5th and 97.5th
/// percentiles of the pooled rate taken. `clusters` holds (successes, trials) per cluster.
/// With one cluster it knows nothing of between-scene spread and says so: [0, 1].
pub fn cluster_bootstrap95(clusters: &[(u64, u64)], resamples: usize, seed: u64) -> [f64; 2] {
    let k = clusters.len();
    if k < 2 || clusters.iter().all(|c| c.1 == 0) {
        return [0.0, 1.0];
    }
    let mut rng = agrisim_math::Rng::new(seed);
    let mut rates = Vec::with_capacity(resamples);
    for _ in 0..resamples {
        let (mut s, mut n) = (0u64, 0u64);
        for _ in 0..k {
            let c = clusters[rng.below(k as u64) as usize];
            s += c.0;
            n += c.1;
        }
        if n > 0 {
            rates.push(s as f64 / n as f64);
        }
    }
    rates.sort_by(f64::total_cmp);
    [percentile(&rates, 0.025).unwrap_or(0.0), percentile(&rates, 0.975).unwrap_or(1.0)]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Scenes that all succeed at the same rate give an interval around it; scenes that
    /// either all succeed or all fail (the same pooled rate) give a much wider one than
    /// Wilson's, which counts every trial as independent.
    #[test]
    fn cluster_bootstrap_widens_with_the_spread_between_scenes() {
        let even = vec![(5, 10); 10];
        let split: Vec<(u64, u64)> = (0..10).map(|i| if i % 2 == 0 { (10, 10) } else { (0, 10) }).collect();
        let [a0, a1] = cluster_bootstrap95(&even, 2000, 1);
        assert!(a0 == 0.5 && a1 == 0.5, "no spread between identical scenes: [{a0}, {a1}]");
        let [b0, b1] = cluster_bootstrap95(&split, 2000, 1);
        let [w0, w1] = wilson(50, 100, Z95);
        assert!(b0 < 0.5 && b1 > 0.5 && b1 - b0 > 1.5 * (w1 - w0), "[{b0}, {b1}] vs Wilson [{w0}, {w1}]");
        // Analytic check: the resampled rate is the mean of 10 draws of 0 or 1 (p = 1/2), a
        // binomial(10, 1/2) / 10, whose 2.5 % and 97.5 % quantiles are 0.2 and 0.8.
        assert!((b0 - 0.2).abs() <= 0.1 + 1e-12 && (b1 - 0.8).abs() <= 0.1 + 1e-12, "[{b0}, {b1}]");
        assert_eq!(cluster_bootstrap95(&split, 500, 9), cluster_bootstrap95(&split, 500, 9));
        assert_eq!(cluster_bootstrap95(&[(3, 5)], 100, 1), [0.0, 1.0]);
    }

    #[test]
    fn wilson_matches_published_values() {
        // Newcombe (1998), Table I: 81/263 -> 0.2553 .. 0.3662 (95 %).
        let [lo, hi] = wilson(81, 263, Z95);
        assert!((lo - 0.2553).abs() < 5e-4 && (hi - 0.3662).abs() < 5e-4, "{lo} {hi}");
        // All successes: upper bound 1, lower bound n/(n+z^2).
        let [lo, hi] = wilson(50, 50, Z95);
        assert!((lo - 50.0 / (50.0 + Z95 * Z95)).abs() < 1e-12 && hi == 1.0);
        assert_eq!(wilson(0, 0, Z95), [0.0, 1.0]);
    }

    #[test]
    fn percentiles_interpolate() {
        let v = [1.0, 2.0, 3.0, 4.0];
        assert_eq!(percentile(&v, 0.5), Some(2.5));
        assert_eq!(percentile(&v, 1.0), Some(4.0));
        assert_eq!(percentile(&[], 0.5), None);
    }
}
