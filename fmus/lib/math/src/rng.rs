//! Seeded, platform-independent random numbers: the workspace's one generator.
//!
//! One SplitMix64 core (Steele, Lea, Flood 2014): tiny, fully specified and bit-reproducible
//! everywhere, which is what byte-identical logs need. It is owned here so that no result
//! changes because a dependency changed its algorithm.
//!
//! # Two flavours
//!
//! The workspace grew two generators on this core, and existing scenes and sensor noise are
//! pinned to their exact sequences, so both are kept bit-for-bit. They differ in seeding and
//! in how raw bits become numbers:
//!
//! | | noise flavour | scene flavour |
//! | --- | --- | --- |
//! | constructors | [`Rng::new`] | [`Rng::scene`], [`Rng::stream`] |
//! | uniform | [`Rng::uniform`], in (0, 1] | [`Rng::scene_uniform`], in [0, 1) |
//! | integer in 0..n | [`Rng::below`] (modulo) | [`Rng::scene_below`] (multiply-shift) |
//! | standard normal | [`Rng::normal`] (Box-Muller, caches the second deviate), [`Rng::normal_ziggurat`] | [`Rng::scene_normal`] (Box-Muller, one deviate per two draws) |
//! | more | [`Rng::gauss`] | [`Rng::range`], [`Rng::weighted`] |
//!
//! **Noise flavour**: sensor and slip noise in the FMUs (IMU, LiDAR, chassis), samplers and
//! benchmarks in the orchestrator, test harnesses. One generator per noise source, seeded from
//! a model parameter; [`Rng::gauss`] draws nothing for `sigma == 0` so that switching one
//! source off leaves the others' sequences unchanged.
//!
//! **Scene flavour**: procedural scene generation (the greenhouse). [`Rng::stream`] derives an
//! independent sub-stream from (seed, labels), so e.g. adding an obstacle does not move every
//! fruit.
//!
//! Use the methods of the flavour a generator was constructed for. Nothing prevents mixing
//! them (they share the state), but a new sequence is only reproducible if it stays the same;
//! new code should pick one flavour and keep it.

use rand_distr::{Distribution, StandardNormal};
use std::convert::Infallible;
use std::f64::consts::{PI, TAU};

/// Added to the state before every output (the golden-ratio increment of SplitMix64).
const GOLDEN: u64 = 0x9E37_79B9_7F4A_7C15;

/// SplitMix64 generator; see the [module docs](self) for the two flavours of methods.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Rng {
    state: u64,
    /// Second Box-Muller deviate of [`Rng::normal`] (noise flavour only).
    spare: Option<f64>,
}

/// SplitMix64 finaliser (Steele, Lea, Flood 2014): a strong 64-bit mix.
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

impl Rng {
    // ------------------------------------------------------------------ shared core

    /// Next 64 uniform bits (both flavours).
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(GOLDEN);
        mix(self.state)
    }

    // ------------------------------------------------------------------ noise flavour

    /// Noise flavour: the generator for `seed` (sensor noise, samplers, tests).
    pub fn new(seed: u64) -> Rng {
        Rng { state: seed ^ 0x6A09_E667_F3BC_C909, spare: None }
    }

    /// Noise flavour: uniform in (0, 1]; never 0, so `ln` in [`Rng::normal`] is finite.
    pub fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 1.0) * (1.0 / (1u64 << 53) as f64)
    }

    /// Noise flavour: uniform integer in 0..n (n > 0) by modulo (the bias is below 2^-40 for
    /// the small n of tests and samplers).
    pub fn below(&mut self, n: u64) -> u64 {
        self.next_u64() % n
    }

    /// Noise flavour: standard normal deviate (Box-Muller; every second call returns the
    /// cached partner deviate without drawing).
    pub fn normal(&mut self) -> f64 {
        if let Some(z) = self.spare.take() {
            return z;
        }
        let (u1, u2) = (self.uniform(), self.uniform());
        let r = (-2.0 * u1.ln()).sqrt();
        let (s, c) = (2.0 * PI * u2).sin_cos();
        self.spare = Some(r * s);
        r * c
    }

    /// Noise flavour: a standard normal deviate by the ziggurat method (Marsaglia and Tsang
    /// 2000; rand_distr's `StandardNormal`, with its fixed tables), usually from one draw. A
    /// fraction of the cost of Box-Muller's logarithm and cosine, for the camera's
    /// per-pixel depth noise; a different sequence from [`Rng::normal`].
    pub fn normal_ziggurat(&mut self) -> f64 {
        StandardNormal.sample(self)
    }

    /// Noise flavour: normal with standard deviation `sigma`; draws nothing when
    /// `sigma == 0` so that turning one noise source off leaves the others' sequences
    /// unchanged.
    pub fn gauss(&mut self, sigma: f64) -> f64 {
        if sigma == 0.0 {
            0.0
        } else {
            sigma * self.normal()
        }
    }

    // ------------------------------------------------------------------ scene flavour

    /// Scene flavour: the generator for `seed` (a whole scene from one seed).
    pub fn scene(seed: u64) -> Rng {
        Rng { state: mix(seed ^ 0x5EED_6A11_0F00_D5EE), spare: None }
    }

    /// Scene flavour: an independent stream for `labels` under `seed`.
    pub fn stream(seed: u64, labels: &[u64]) -> Rng {
        let mut h = mix(seed.wrapping_add(GOLDEN));
        for &l in labels {
            h = mix(h ^ mix(l.wrapping_add(0x632B_E59B_D9B4_E019)));
        }
        Rng { state: h, spare: None }
    }

    /// Scene flavour: uniform in [0, 1).
    pub fn scene_uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Scene flavour: uniform in [lo, hi) (from [`Rng::scene_uniform`]).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.scene_uniform()
    }

    /// Scene flavour: uniform integer in 0..n (n > 0) by multiply-shift (no modulo bias).
    pub fn scene_below(&mut self, n: u64) -> u64 {
        ((self.next_u64() as u128 * n as u128) >> 64) as u64
    }

    /// Scene flavour: standard normal (Box-Muller, two draws per deviate, nothing cached).
    pub fn scene_normal(&mut self) -> f64 {
        let u1 = 1.0 - self.scene_uniform();
        let u2 = self.scene_uniform();
        (-2.0 * u1.ln()).sqrt() * (TAU * u2).cos()
    }

    /// Scene flavour: index drawn from non-negative `weights` (not all zero), from
    /// [`Rng::scene_uniform`].
    pub fn weighted(&mut self, weights: &[f64]) -> usize {
        let total: f64 = weights.iter().sum();
        let mut u = self.scene_uniform() * total;
        for (i, &w) in weights.iter().enumerate() {
            if u < w {
                return i;
            }
            u -= w;
        }
        weights.iter().rposition(|&w| w > 0.0).unwrap_or(0)
    }
}

/// The raw bits of [`Rng::next_u64`], so rand_distr's samplers can draw from this generator.
impl rand_core::TryRng for Rng {
    type Error = Infallible;

    fn try_next_u32(&mut self) -> Result<u32, Infallible> {
        Ok((self.next_u64() >> 32) as u32)
    }

    fn try_next_u64(&mut self) -> Result<u64, Infallible> {
        Ok(self.next_u64())
    }

    fn try_fill_bytes(&mut self, dst: &mut [u8]) -> Result<(), Infallible> {
        for chunk in dst.chunks_mut(8) {
            chunk.copy_from_slice(&self.next_u64().to_le_bytes()[..chunk.len()]);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_moments() {
        for (name, mut r, draw) in [
            ("noise", Rng::new(42), Rng::normal as fn(&mut Rng) -> f64),
            ("scene", Rng::scene(42), Rng::scene_normal),
            ("ziggurat", Rng::new(42), Rng::normal_ziggurat),
        ] {
            let n = 200_000;
            let xs: Vec<f64> = (0..n).map(|_| draw(&mut r)).collect();
            let mean = xs.iter().sum::<f64>() / n as f64;
            let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n as f64;
            assert!(mean.abs() < 0.01, "{name}: mean {mean}");
            assert!((var - 1.0).abs() < 0.01, "{name}: var {var}");
        }
    }

    /// The ziggurat's deviates against the normal distribution's bin probabilities (Simpson's
    /// rule on the density): a chi-square test over 42 bins, the outer two the tails beyond
    /// 5 sigma, which the ziggurat reaches only through its tail sampler (past 3.654).
    #[test]
    fn ziggurat_deviates_follow_the_normal_distribution() {
        let edges: Vec<f64> = (0..=40).map(|k| -5.0 + 0.25 * k as f64).collect();
        let pdf = |x: f64| (-0.5 * x * x).exp() / (2.0 * PI).sqrt();
        let mass = |a: f64, b: f64| {
            let n = 200;
            let h = (b - a) / n as f64;
            (0..=n)
                .map(|i| {
                    pdf(a + i as f64 * h) * h / 3.0
                        * if i == 0 || i == n {
                            1.0
                        } else if i % 2 == 1 {
                            4.0
                        } else {
                            2.0
                        }
                })
                .sum::<f64>()
        };
        let mut p: Vec<f64> = edges.windows(2).map(|w| mass(w[0], w[1])).collect();
        let tail = 0.5 * (1.0 - p.iter().sum::<f64>());
        p.insert(0, tail);
        p.push(tail);
        let n = 2_000_000;
        let mut count = vec![0u64; p.len()];
        let mut r = Rng::new(7);
        let mut beyond_r = 0;
        for _ in 0..n {
            let x = r.normal_ziggurat();
            beyond_r += (x.abs() > 3.654_152_885_361_009) as u64;
            count[edges.partition_point(|&e| e <= x)] += 1;
        }
        let chi2: f64 = count.iter().zip(&p).map(|(&c, &q)| (c as f64 - n as f64 * q).powi(2) / (n as f64 * q)).sum();
        // 41 degrees of freedom: P(chi2 > 80) is about 2e-4.
        assert!(chi2 < 80.0, "chi-square {chi2} over {} bins: {count:?}", p.len());
        // P(|x| > 3.654) = 2.58e-4: about 516 of 2 M.
        assert!((400..650).contains(&beyond_r), "{beyond_r} deviates beyond the ziggurat's base");
    }

    #[test]
    fn same_seed_same_sequence_other_seed_differs() {
        let seq = |mut r: Rng| -> Vec<u64> { (0..8).map(|_| r.next_u64()).collect() };
        assert_eq!(seq(Rng::new(7)), seq(Rng::new(7)));
        assert_ne!(seq(Rng::new(7)), seq(Rng::new(8)));
        assert_eq!(seq(Rng::scene(7)), seq(Rng::scene(7)));
        assert_ne!(seq(Rng::scene(7)), seq(Rng::scene(8)));
        assert_ne!(seq(Rng::stream(7, &[1, 2])), seq(Rng::stream(7, &[2, 1])));
    }

    #[test]
    fn uniform_ranges() {
        let mut r = Rng::new(1);
        let mut s = Rng::scene(1);
        for _ in 0..10_000 {
            let u = r.uniform();
            assert!(u > 0.0 && u <= 1.0);
            let v = s.scene_uniform();
            assert!((0.0..1.0).contains(&v));
            assert!(r.below(7) < 7 && s.scene_below(7) < 7);
        }
    }

    #[test]
    fn gauss_with_zero_sigma_draws_nothing() {
        let mut a = Rng::new(5);
        let b = a.clone();
        assert_eq!(a.gauss(0.0), 0.0);
        assert_eq!(a.next_u64(), b.clone().next_u64());
    }

    #[test]
    fn weighted_skips_zero_weights() {
        let mut r = Rng::scene(3);
        for _ in 0..1000 {
            assert_ne!(r.weighted(&[1.0, 0.0, 2.0]), 1);
        }
    }
}
