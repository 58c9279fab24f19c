//! The localizer's initial pose estimate in a trial: the true start pose plus a seeded
//! error, as an operator's estimate would have (the robot must converge from it), never the
//! true pose itself.

use agrisim_math::pose2::wrap_angle;
use agrisim_math::Rng;

/// Label of the initial-error stream under a trial's seed (independent of its other draws,
/// so targets stay the same whatever the error).
const STREAM: u64 = 0x1A17_1A1E_5707;

/// (estimate, error) for a robot truly at `start`: each of x, y, yaw off by a normal
/// deviate of standard deviation `std` [m, m, rad], drawn from the trial's `seed`.
pub fn initial_estimate(start: [f64; 3], std: [f64; 3], seed: u64) -> ([f64; 3], [f64; 3]) {
    let mut rng = Rng::stream(seed, &[STREAM]);
    let error = std.map(|s| rng.gauss(s));
    let estimate = [start[0] + error[0], start[1] + error[1], wrap_angle(start[2] + error[2])];
    (estimate, error)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_are_seeded_and_have_the_asked_spread() {
        let std = [0.1, 0.1, 3f64.to_radians()];
        assert_eq!(initial_estimate([1.0, 2.0, 0.0], std, 7), initial_estimate([1.0, 2.0, 0.0], std, 7));
        let n = 4000;
        let mut sq = [0.0; 3];
        for seed in 0..n {
            let (est, err) = initial_estimate([0.0, 0.0, 0.0], std, seed);
            assert!((est[0] - err[0]).abs() < 1e-12);
            for k in 0..3 {
                sq[k] += err[k] * err[k];
            }
        }
        for k in 0..3 {
            let rms = (sq[k] / n as f64).sqrt();
            assert!((rms / std[k] - 1.0).abs() < 0.05, "axis {k}: rms {rms} vs std {}", std[k]);
        }
    }

    #[test]
    fn zero_spread_is_the_true_pose() {
        assert_eq!(initial_estimate([1.0, 2.0, 0.5], [0.0; 3], 3).0, [1.0, 2.0, 0.5]);
    }
}
