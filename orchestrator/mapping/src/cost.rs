//! The mapper's compute, charged in simulated time as the harvest node charges its planning
//! (`agrisim_manip::CostModel`): each depth frame's work is counted ([`MapWork`], from the
//! scan's [`ScanStats`]) and a [`CostModel`] turns the counts into seconds, so a run's results
//! never depend on a clock.

use crate::map::ScanStats;

/// The work of integrating depth frames.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct MapWork {
    /// Depth pixels decoded (the whole image, whatever the stride).
    pub pixels: u64,
    /// Points integrated (valid pixels at the stride, moved into the map frame).
    pub points: u64,
    /// Voxels stepped through by the rays' walks.
    pub ray_steps: u64,
    /// Cells of the dense mark grids.
    pub dense_cells: u64,
    /// Voxels updated (hits and misses).
    pub updates: u64,
    /// Self-filter bound tests (in-range points times links in view).
    pub self_tests: u64,
}

impl MapWork {
    /// The work of one scan of a `pixels`-pixel depth image.
    pub fn of_scan(pixels: u64, s: &ScanStats) -> MapWork {
        MapWork {
            pixels,
            points: s.points as u64,
            ray_steps: s.ray_steps as u64,
            dense_cells: s.dense_cells as u64,
            updates: (s.hits + s.misses) as u64,
            self_tests: s.self_tests as u64,
        }
    }
}

impl std::ops::AddAssign for MapWork {
    fn add_assign(&mut self, o: MapWork) {
        self.pixels += o.pixels;
        self.points += o.points;
        self.ray_steps += o.ray_steps;
        self.dense_cells += o.dense_cells;
        self.updates += o.updates;
        self.self_tests += o.self_tests;
    }
}

impl std::ops::Sub for MapWork {
    type Output = MapWork;
    fn sub(self, o: MapWork) -> MapWork {
        MapWork {
            pixels: self.pixels - o.pixels,
            points: self.points - o.points,
            ray_steps: self.ray_steps - o.ray_steps,
            dense_cells: self.dense_cells - o.dense_cells,
            updates: self.updates - o.updates,
            self_tests: self.self_tests - o.self_tests,
        }
    }
}

/// Seconds per unit of the mapper's work.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CostModel {
    pub per_pixel: f64,
    pub per_point: f64,
    pub per_ray_step: f64,
    pub per_dense_cell: f64,
    pub per_update: f64,
    pub per_self_test: f64,
}

impl CostModel {
    /// Calibrated once on this project's 2-core machine (one thread, release build, other
    /// builds running beside it): a non-negative least-squares fit of measured wall time against
    /// the counted work of the node steps that integrated frames in a recorded harvest-by-sight
    /// trial (both row cameras, 203 520-pixel depth images, max range 1.2 m), at the benchmark's
    /// pixel stride 4 and at stride 8 (219 steps each, the least time of 3 passes),
    /// `cargo run --release -p agrisim-mapping --example mapping_cost -- RUN.mcap` (see the
    /// example for the recording). Fitted: 3.3e-8 s per depth pixel (halves of the set
    /// 3.24-3.29; it also carries the per-frame overheads, which scale with it), 8.7e-9 s per
    /// ray step (halves 8.4-8.8); points, dense cells, updates and self-filter tests fit 0
    /// (their time moves with the ray steps). A stride-4 step (two frames) measured 39 ms on
    /// average; per step the model is within -22 % .. +28 % (p5..p95) of the measured time, in
    /// total within 0.1 %. A real robot's computer may be slower: see [`CostModel::scaled`].
    pub const CALIBRATED: CostModel = CostModel {
        per_pixel: 3.3e-8,
        per_point: 0.0,
        per_ray_step: 8.7e-9,
        per_dense_cell: 0.0,
        per_update: 0.0,
        per_self_test: 0.0,
    };

    /// Free compute: every frame in the scene at the step it arrives (the behaviour before
    /// mapping latency was modelled).
    pub const FREE: CostModel = CostModel {
        per_pixel: 0.0,
        per_point: 0.0,
        per_ray_step: 0.0,
        per_dense_cell: 0.0,
        per_update: 0.0,
        per_self_test: 0.0,
    };

    /// Every cost multiplied by `k` (e.g. 3 for a computer three times slower).
    pub fn scaled(self, k: f64) -> CostModel {
        CostModel {
            per_pixel: self.per_pixel * k,
            per_point: self.per_point * k,
            per_ray_step: self.per_ray_step * k,
            per_dense_cell: self.per_dense_cell * k,
            per_update: self.per_update * k,
            per_self_test: self.per_self_test * k,
        }
    }

    /// Seconds `w` costs.
    pub fn seconds(&self, w: &MapWork) -> f64 {
        w.pixels as f64 * self.per_pixel
            + w.points as f64 * self.per_point
            + w.ray_steps as f64 * self.per_ray_step
            + w.dense_cells as f64 * self.per_dense_cell
            + w.updates as f64 * self.per_update
            + w.self_tests as f64 * self.per_self_test
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn work_is_counted_and_priced() {
        let s = ScanStats {
            points: 2,
            hits: 3,
            misses: 4,
            ray_steps: 5,
            dense_cells: 6,
            self_tests: 7,
            ..Default::default()
        };
        let w = MapWork::of_scan(1, &s);
        assert_eq!(w, MapWork { pixels: 1, points: 2, ray_steps: 5, dense_cells: 6, updates: 7, self_tests: 7 });
        let c = CostModel {
            per_pixel: 1.0,
            per_point: 10.0,
            per_ray_step: 100.0,
            per_dense_cell: 1000.0,
            per_update: 10000.0,
            per_self_test: 100000.0,
        };
        assert_eq!(c.seconds(&w), 776_521.0);
        assert_eq!(c.scaled(2.0).seconds(&w), 2.0 * 776_521.0);
        assert_eq!(CostModel::FREE.seconds(&w), 0.0);
        let mut twice = w;
        twice += w;
        assert_eq!(twice - w, w);
    }
}
