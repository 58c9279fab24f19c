//! Perception's compute, charged in simulated time as the harvest node charges its planning
//! (`agrisim_manip::CostModel`): the detector counts its work per frame ([`DetectWork`]) and a
//! [`CostModel`] turns the counts into seconds, so a run's results never depend on a clock.

use crate::detect::DetectWork;

/// Seconds per unit of a frame's work.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CostModel {
    pub per_pixel: f64,
    pub per_conversion: f64,
    pub per_candidate: f64,
    pub per_fit_point: f64,
    pub per_surface_test: f64,
    /// Fog: per pixel sampled for the estimate, per pixel cleared ([`crate::haze`]).
    pub per_haze_sample: f64,
    pub per_cleared: f64,
}

/// Fog ([`crate::haze`]), calibrated apart with `cargo run --release -p agrisim-perception
/// --example haze_cost -- RUN.mcap --repeat 30` on the frames of a perception benchmark in fog
/// (see the example; four recordings, the median of their figures, beside a harvest
/// benchmark on the same 2 cores): seconds per pixel sampled for the estimate (1.9-2.7e-8:
/// 0.4-0.5 ms a 640x480 frame), per pixel cleared (7.4-7.9e-8: 3.4-4.9 ms a foggy frame).
const HAZE_SAMPLE: f64 = 2.4e-8;
const CLEARED: f64 = 7.7e-8;

impl CostModel {
    /// Calibrated once on this project's 2-core machine (one thread, release build, other
    /// builds running beside it): a non-negative least-squares fit of measured wall time against
    /// the counted work of every frame of a recorded harvest-by-sight trial (both row cameras),
    /// `cargo run --release -p agrisim-perception --example perception_cost -- RUN.mcap`
    /// (see the example for the recording), 3 passes (the least time of each step): 220
    /// node steps of two 203 520-pixel frames (29.8 ms each measured), and the same steps with black
    /// colour images, which pin the scan's own cost. Fitted: 7.0e-9 s per pixel (halves
    /// 6.9-7.1), 3.3e-7 s per colour conversion, 8.2e-7 s per candidate pixel, 1.2e-7 s per
    /// fitted point, 0 per surface test. The last four are collinear on real frames (a frame
    /// with more fruit has more of each) and share the time differently in the halves of the
    /// set (conversion 0-5.4e-7, candidate 6.0-9.8e-7, fitted point 0-2.3e-7, surface test
    /// 0-1.1e-8); their sum per frame holds: per step the model is within -19 % .. +36 %
    /// (p5..p95) of the measured time, in total within 0.3 %. A real robot's computer may be
    /// slower: see [`CostModel::scaled`].
    pub const CALIBRATED: CostModel = CostModel {
        per_pixel: 7.0e-9,
        per_conversion: 3.3e-7,
        per_candidate: 8.2e-7,
        per_fit_point: 1.2e-7,
        per_surface_test: 0.0,
        per_haze_sample: HAZE_SAMPLE,
        per_cleared: CLEARED,
    };

    /// Free compute: every frame's outputs at the step it arrives (the behaviour before
    /// perception latency was modelled).
    pub const FREE: CostModel = CostModel {
        per_pixel: 0.0,
        per_conversion: 0.0,
        per_candidate: 0.0,
        per_fit_point: 0.0,
        per_surface_test: 0.0,
        per_haze_sample: 0.0,
        per_cleared: 0.0,
    };

    /// Every cost multiplied by `k` (e.g. 3 for a computer three times slower).
    pub fn scaled(self, k: f64) -> CostModel {
        CostModel {
            per_pixel: self.per_pixel * k,
            per_conversion: self.per_conversion * k,
            per_candidate: self.per_candidate * k,
            per_fit_point: self.per_fit_point * k,
            per_surface_test: self.per_surface_test * k,
            per_haze_sample: self.per_haze_sample * k,
            per_cleared: self.per_cleared * k,
        }
    }

    /// Seconds `w` costs.
    pub fn seconds(&self, w: &DetectWork) -> f64 {
        w.pixels as f64 * self.per_pixel
            + w.conversions as f64 * self.per_conversion
            + w.candidates as f64 * self.per_candidate
            + w.fit_points as f64 * self.per_fit_point
            + w.surface_tests as f64 * self.per_surface_test
            + w.haze_samples as f64 * self.per_haze_sample
            + w.cleared as f64 * self.per_cleared
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn work_is_priced() {
        let w = DetectWork {
            pixels: 10,
            conversions: 2,
            candidates: 3,
            fit_points: 4,
            surface_tests: 5,
            haze_samples: 6,
            cleared: 7,
        };
        let c = CostModel {
            per_pixel: 1.0,
            per_conversion: 10.0,
            per_candidate: 100.0,
            per_fit_point: 1000.0,
            per_surface_test: 10000.0,
            per_haze_sample: 100_000.0,
            per_cleared: 1_000_000.0,
        };
        assert_eq!(c.seconds(&w), 7_654_330.0);
        assert_eq!(c.scaled(2.0).seconds(&w), 15_308_660.0);
        assert_eq!(CostModel::FREE.seconds(&w), 0.0);
    }
}
