//! The local costmap: a rolling window around the robot holding obstacles that the LiDAR sees
//! and the static map does not have (boxes, people, a cart closing an aisle).
//!
//! Marking: points in a height band above the floor, not on the robot itself and not within a
//! tolerance of a mapped obstacle (those are the map, seen with localization error).
//! Clearing: ray tracing on the grid from the sensor to the nearest in-band return in each
//! bearing bin, done before marking so a cell hit in this scan stays marked. Only in-band
//! returns clear, and a marked cell is cleared only where the ray passes it no higher than the
//! highest point that marked it: a ray passing over a low obstacle (one the LiDAR's lowest
//! beam no longer sees from close by) towards a plant behind it does not erase it.

use super::distance::distance_transform;
use super::footprint::Footprint;
use super::map::{GridGeom, StaticMap};
use agrisim_math::pose2::Pose2;
use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct LocalCostmapConfig {
    /// Edge of the square window centred on the robot [m].
    pub size: f64,
    /// Height band above the floor in which points are obstacles [m].
    pub min_z: f64,
    pub max_z: f64,
    /// Points farther from the sensor than this neither mark nor clear [m].
    pub max_range: f64,
    /// Points this close to a mapped obstacle belong to the map [m] (≥ localization error) ...
    pub map_tolerance: f64,
    /// ... plus this much per metre of range [m/m] (the heading error's lateral reach).
    pub map_tolerance_per_m: f64,
    /// Points inside the footprint grown by this are the robot's own body [m].
    pub self_filter_margin: f64,
    /// Bearing bins used for clearing.
    pub clearing_bins: usize,
}

impl Default for LocalCostmapConfig {
    fn default() -> Self {
        LocalCostmapConfig {
            size: 32.0,
            min_z: 0.05,
            max_z: 1.5,
            max_range: 15.0,
            map_tolerance: 0.15,
            map_tolerance_per_m: 0.01,
            self_filter_margin: 0.1,
            clearing_bins: 720,
        }
    }
}

/// How far above a cell's highest marking point a ray may pass and still clear it [m]
/// (the ray's height is taken at the cell centre).
const TOP_TOLERANCE: f64 = 0.05;

/// The nearest in-band return of a bearing bin: map position, height above the floor and
/// horizontal range from the sensor.
#[derive(Debug, Clone, Copy)]
struct Ray {
    x: f64,
    y: f64,
    z: f64,
    range: f64,
}

const UNKNOWN: u8 = 0;
const FREE: u8 = 1;
const OCCUPIED: u8 = 2;

#[derive(Debug, Clone)]
pub struct LocalCostmap {
    pub cfg: LocalCostmapConfig,
    /// Current window; its origin stays on the static map's cell lattice so cells transfer
    /// one to one to the global costmap.
    pub geom: GridGeom,
    anchor: (f64, f64),
    state: Vec<u8>,
    /// Height above the floor of the highest point that marked each occupied cell [m].
    top: Vec<f32>,
    /// Distance from each cell centre to the nearest sensed obstacle [m].
    distance: Vec<f32>,
    occupied_count: usize,
}

impl LocalCostmap {
    /// An empty window on the lattice of `map_geom` (same resolution, aligned cells).
    pub fn new(cfg: LocalCostmapConfig, map_geom: &GridGeom) -> LocalCostmap {
        let res = map_geom.resolution;
        let n = (cfg.size / res).round().max(2.0) as usize;
        let geom =
            GridGeom { origin_x: map_geom.origin_x, origin_y: map_geom.origin_y, resolution: res, width: n, height: n };
        LocalCostmap {
            cfg,
            geom,
            anchor: (map_geom.origin_x, map_geom.origin_y),
            state: vec![UNKNOWN; n * n],
            top: vec![0.0; n * n],
            distance: vec![f32::INFINITY; n * n],
            occupied_count: 0,
        }
    }

    /// Forgets everything (a recovery's "clear costmap").
    pub fn clear(&mut self) {
        self.state.iter_mut().for_each(|s| *s = UNKNOWN);
        self.distance.iter_mut().for_each(|d| *d = f32::INFINITY);
        self.occupied_count = 0;
    }

    pub fn occupied_count(&self) -> usize {
        self.occupied_count
    }

    /// Moves the window so it is centred on (x, y), keeping the cells both windows share.
    pub fn recentre(&mut self, x: f64, y: f64) {
        let res = self.geom.resolution;
        let n = self.geom.width as i64;
        let ox = self.anchor.0 + (((x - self.anchor.0) / res).floor() as i64 - n / 2) as f64 * res;
        let oy = self.anchor.1 + (((y - self.anchor.1) / res).floor() as i64 - n / 2) as f64 * res;
        let dx = ((ox - self.geom.origin_x) / res).round() as i64;
        let dy = ((oy - self.geom.origin_y) / res).round() as i64;
        if dx == 0 && dy == 0 {
            return;
        }
        let mut state = vec![UNKNOWN; self.state.len()];
        let mut top = vec![0.0; self.top.len()];
        for ny in 0..n {
            let sy = ny + dy;
            if sy < 0 || sy >= n {
                continue;
            }
            for nx in 0..n {
                let sx = nx + dx;
                if sx >= 0 && sx < n {
                    state[(ny * n + nx) as usize] = self.state[(sy * n + sx) as usize];
                    top[(ny * n + nx) as usize] = self.top[(sy * n + sx) as usize];
                }
            }
        }
        self.state = state;
        self.top = top;
        self.geom.origin_x = ox;
        self.geom.origin_y = oy;
        self.recompute_distance();
    }

    /// Integrates one scan. `points` are in base_link (z above base_link), `robot` the map pose
    /// of base_link, `sensor` the base-frame position of the LiDAR, `base_height` the height of
    /// base_link above the floor.
    pub fn update(
        &mut self,
        robot: &Pose2,
        sensor: [f64; 3],
        base_height: f64,
        points: &[[f32; 3]],
        map: &StaticMap,
        footprint: &Footprint,
    ) {
        self.recentre(robot.x, robot.y);
        let (sx, sy) = robot.apply(sensor[0], sensor[1]);
        let sz = sensor[2] + base_height;
        let bins = self.cfg.clearing_bins.max(1);
        let mut nearest: Vec<Option<Ray>> = vec![None; bins];
        let mut marks: Vec<(f64, f64, f64)> = Vec::new();
        for p in points {
            let (bx, by, z) = (p[0] as f64, p[1] as f64, p[2] as f64 + base_height);
            if z < self.cfg.min_z || z > self.cfg.max_z || footprint.contains(bx, by, self.cfg.self_filter_margin) {
                continue;
            }
            let (mx, my) = robot.apply(bx, by);
            let r = (mx - sx).hypot(my - sy);
            if r > self.cfg.max_range || r < 1e-3 {
                continue;
            }
            let bearing = (my - sy).atan2(mx - sx);
            let b = (((bearing + std::f64::consts::PI) / std::f64::consts::TAU * bins as f64) as usize).min(bins - 1);
            if nearest[b].is_none_or(|n| r < n.range) {
                nearest[b] = Some(Ray { x: mx, y: my, z, range: r });
            }
            if map.distance_at(mx, my) > self.cfg.map_tolerance + self.cfg.map_tolerance_per_m * r {
                marks.push((mx, my, z));
            }
        }
        for ray in nearest.into_iter().flatten() {
            self.clear_ray((sx, sy, sz), &ray);
        }
        for (mx, my, z) in marks {
            if let Some(i) = self.geom.index_of(mx, my) {
                self.top[i] = if self.state[i] == OCCUPIED { self.top[i].max(z as f32) } else { z as f32 };
                self.state[i] = OCCUPIED;
            }
        }
        self.recompute_distance();
    }

    /// Marks cells from the sensor up to, not including, the cell of the return free
    /// (Bresenham's line on the cell lattice), stopping at the window's edge. An occupied cell
    /// stays occupied where the ray passes above the highest point seen in it.
    fn clear_ray(&mut self, sensor: (f64, f64, f64), ray: &Ray) {
        let (x0, y0, z0) = sensor;
        let (x1, y1) = (ray.x, ray.y);
        let g = &self.geom;
        let c = |x: f64, y: f64| {
            (((x - g.origin_x) / g.resolution).floor() as i64, ((y - g.origin_y) / g.resolution).floor() as i64)
        };
        let (mut cx, mut cy) = c(x0, y0);
        let (ex, ey) = c(x1, y1);
        let (w, h) = (g.width as i64, g.height as i64);
        let (dx, dy) = ((ex - cx).abs(), -(ey - cy).abs());
        let (stx, sty) = ((ex - cx).signum(), (ey - cy).signum());
        let mut err = dx + dy;
        while (cx, cy) != (ex, ey) {
            if cx >= 0 && cy >= 0 && cx < w && cy < h {
                let i = (cy * w + cx) as usize;
                // The ray's height over the cell centre matters only for a marked cell.
                let passes_through = || {
                    let (px, py) = g.center(cx as usize, cy as usize);
                    let t = ((px - x0).hypot(py - y0) / ray.range).min(1.0);
                    z0 + t * (ray.z - z0) <= self.top[i] as f64 + TOP_TOLERANCE
                };
                if self.state[i] != OCCUPIED || passes_through() {
                    self.state[i] = FREE;
                }
            } else if (cx < 0 && stx <= 0) || (cy < 0 && sty <= 0) || (cx >= w && stx >= 0) || (cy >= h && sty >= 0) {
                break;
            }
            let e2 = 2 * err;
            if e2 >= dy {
                err += dy;
                cx += stx;
            }
            if e2 <= dx {
                err += dx;
                cy += sty;
            }
        }
    }

    fn recompute_distance(&mut self) {
        let occ: Vec<bool> = self.state.iter().map(|&s| s == OCCUPIED).collect();
        self.occupied_count = occ.iter().filter(|&&o| o).count();
        if self.occupied_count == 0 {
            self.distance.iter_mut().for_each(|d| *d = f32::INFINITY);
            return;
        }
        let res = self.geom.resolution as f32;
        self.distance =
            distance_transform(&occ, self.geom.width, self.geom.height).into_iter().map(|d| d * res).collect();
    }

    /// Distance to the nearest sensed obstacle, from the cell centre minus half a cell;
    /// infinite outside the window (nothing known there).
    pub fn distance_at(&self, x: f64, y: f64) -> f64 {
        match self.geom.index_of(x, y) {
            Some(i) => (self.distance[i] as f64 - 0.5 * self.geom.resolution).max(0.0),
            None => f64::INFINITY,
        }
    }

    /// [`distance_at`](Self::distance_at) of cell (cx, cy) of the window.
    pub fn cell_distance(&self, cx: usize, cy: usize) -> f64 {
        (self.distance[cy * self.geom.width + cx] as f64 - 0.5 * self.geom.resolution).max(0.0)
    }

    /// Distance from the containing cell's centre to the nearest sensed obstacle cell's
    /// centre (the measure inflation uses); infinite outside the window.
    pub fn center_distance_at(&self, x: f64, y: f64) -> f64 {
        self.geom.index_of(x, y).map_or(f64::INFINITY, |i| self.distance[i] as f64)
    }

    pub fn is_occupied(&self, x: f64, y: f64) -> bool {
        self.geom.index_of(x, y).is_some_and(|i| self.state[i] == OCCUPIED)
    }

    /// Every cell seen occupied or seen free, as (map x, map y, occupied), row by row.
    pub fn observed_cells(&self) -> impl Iterator<Item = (f64, f64, bool)> + '_ {
        let w = self.geom.width;
        self.state.iter().enumerate().filter(|(_, &s)| s != UNKNOWN).map(move |(i, &s)| {
            let (x, y) = self.geom.center(i % w, i / w);
            (x, y, s == OCCUPIED)
        })
    }

    /// As an OccupancyGrid for visualization (-1 unknown, 0 free, 100 occupied).
    pub fn to_msg(
        &self,
        frame_id: &str,
        stamp: agrisim_msgs::builtin_interfaces::Time,
    ) -> agrisim_msgs::nav_msgs::OccupancyGrid {
        let mut g = super::map::occupancy_grid(&self.geom, &[], frame_id, stamp);
        g.data = self
            .state
            .iter()
            .map(|&s| match s {
                UNKNOWN => -1,
                FREE => 0,
                _ => 100,
            })
            .collect();
        g
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn empty_map() -> StaticMap {
        let geom = GridGeom { origin_x: -10.0, origin_y: -10.0, resolution: 0.05, width: 400, height: 400 };
        StaticMap::from_cells(geom, vec![false; 400 * 400], "map".into())
    }

    /// An empty map, a `size` m window on it, the default footprint and the robot at the origin.
    fn window(size: f64) -> (StaticMap, LocalCostmap, Footprint, Pose2) {
        let map = empty_map();
        let lc = LocalCostmap::new(LocalCostmapConfig { size, ..LocalCostmapConfig::default() }, &map.geom);
        (map, lc, Footprint::default(), Pose2::new(0.0, 0.0, 0.0))
    }

    #[test]
    fn marks_clears_and_rolls() {
        let (map, mut lc, fp, robot) = window(8.0);
        // A post 2 m ahead, floor and self hits ignored.
        let pts = [[2.0f32, 0.0, 0.5], [3.0, 1.0, -0.5], [0.3, 0.0, 0.5], [1.0, 1.0, 2.5]];
        lc.update(&robot, [0.0; 3], 0.0, &pts, &map, &fp);
        assert!(lc.is_occupied(2.0, 0.0));
        assert_eq!(lc.occupied_count(), 1);
        assert!(lc.distance_at(1.5, 0.0) > 0.4 && lc.distance_at(1.5, 0.0) < 0.5);
        // The post moves away: a return farther along the same bearing clears it.
        lc.update(&robot, [0.0; 3], 0.0, &[[3.5, 0.0, 0.5]], &map, &fp);
        assert!(!lc.is_occupied(2.0, 0.0) && lc.is_occupied(3.5, 0.0));
        // Rolling 1 m keeps the obstacle at the same map position.
        let robot = Pose2::new(1.0, 0.0, 0.0);
        lc.update(&robot, [0.0; 3], 0.0, &[], &map, &fp);
        assert!(lc.is_occupied(3.5, 0.0));
        assert!(lc.geom.index_of(-3.5, 0.0).is_none());
    }

    /// Regression (blocked-aisles trial 26): a 0.69 m box the LiDAR (1.3 m up, lowest beam
    /// 7 deg down) saw from afar was erased once the robot came so close that every beam of
    /// its bearing passed over it to a plant behind, and the robot clipped it.
    #[test]
    fn rays_passing_over_a_low_obstacle_keep_it() {
        let (map, mut lc, fp, robot) = window(12.0);
        let sensor = [0.0, 0.0, 1.3];
        lc.update(&robot, sensor, 0.0, &[[3.0f32, 0.0, 0.6]], &map, &fp);
        assert!(lc.is_occupied(3.0, 0.0));
        // Beams over the box to foliage 5 m away (at 1.0 m and at 0.4 m high) keep it.
        lc.update(&robot, sensor, 0.0, &[[5.0f32, 0.0, 1.0]], &map, &fp);
        lc.update(&robot, sensor, 0.0, &[[5.0f32, 0.0, 0.4]], &map, &fp);
        assert!(lc.is_occupied(3.0, 0.0) && lc.is_occupied(5.0, 0.0));
        // A beam through the box's height (to the floor band just behind it) clears it.
        lc.update(&robot, sensor, 0.0, &[[3.6f32, 0.0, 0.1]], &map, &fp);
        assert!(!lc.is_occupied(3.0, 0.0));
        // Cells it never marked are cleared by any in-band beam.
        assert!(!lc.is_occupied(2.0, 0.0));
    }
}
