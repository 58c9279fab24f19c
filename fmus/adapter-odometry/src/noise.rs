//! The odometry error model: what a base controller's odometry would read for a true body
//! twist. A constant scale error (miscalibrated wheel radius or track) plus white noise per
//! step, drawn from one seeded generator in a fixed order (vx, vy, wz), so the same seed
//! gives the same readings. With every parameter 0 the reading is the true twist, bit for bit.

use agrisim_chassis::se2::Twist2;
use agrisim_math::Rng;

#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct OdometryNoise {
    /// 1 sigma per step on vx and vy [m/s].
    pub v_noise: f64,
    /// 1 sigma per step on wz [rad/s].
    pub wz_noise: f64,
    /// Relative scale error of vx and vy.
    pub v_scale_error: f64,
    /// Relative scale error of wz.
    pub wz_scale_error: f64,
}

impl OdometryNoise {
    /// The twist read without the random part (at initialization, before any step).
    pub fn scaled(&self, t: Twist2) -> Twist2 {
        Twist2 {
            vx: t.vx * (1.0 + self.v_scale_error),
            vy: t.vy * (1.0 + self.v_scale_error),
            wz: t.wz * (1.0 + self.wz_scale_error),
        }
    }

    /// One step's reading of the true twist `t`. `Rng::gauss` draws nothing for a sigma of 0.
    pub fn read(&self, t: Twist2, rng: &mut Rng) -> Twist2 {
        let s = self.scaled(t);
        Twist2 {
            vx: s.vx + rng.gauss(self.v_noise),
            vy: s.vy + rng.gauss(self.v_noise),
            wz: s.wz + rng.gauss(self.wz_noise),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_noise_reads_the_true_twist_exactly() {
        let t = Twist2 { vx: 0.3, vy: -0.1, wz: 0.7 };
        let mut rng = Rng::new(3);
        let before = rng.clone().next_u64();
        assert_eq!(OdometryNoise::default().read(t, &mut rng), t);
        assert_eq!(rng.next_u64(), before, "nothing drawn");
    }

    #[test]
    fn noise_has_the_given_sigma_and_the_scale_error_its_bias() {
        let n = OdometryNoise { v_noise: 0.02, wz_noise: 0.01, v_scale_error: 0.05, wz_scale_error: -0.1 };
        let t = Twist2 { vx: 1.0, vy: 0.0, wz: 0.5 };
        let mut rng = Rng::new(9);
        let k = 20_000;
        let reads: Vec<Twist2> = (0..k).map(|_| n.read(t, &mut rng)).collect();
        let mean = |f: fn(&Twist2) -> f64| reads.iter().map(f).sum::<f64>() / k as f64;
        let sd =
            |f: fn(&Twist2) -> f64, m: f64| (reads.iter().map(|r| (f(r) - m).powi(2)).sum::<f64>() / k as f64).sqrt();
        let (mx, mw) = (mean(|r| r.vx), mean(|r| r.wz));
        assert!((mx - 1.05).abs() < 1e-3, "{mx}");
        assert!((mw - 0.45).abs() < 1e-3, "{mw}");
        assert!((sd(|r| r.vx, mx) - 0.02).abs() < 1e-3);
        assert!((sd(|r| r.vy, 0.0) - 0.02).abs() < 1e-3);
        assert!((sd(|r| r.wz, mw) - 0.01).abs() < 5e-4);
    }
}
