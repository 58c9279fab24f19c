//! The global costmap: the static map plus obstacles learnt while driving ("blocked" cells,
//! reported by the local costmap when they close the planned path), inflated with a smooth
//! gradient so that the cheapest path runs down the middle of an aisle.
//!
//! Cost semantics follow the convention ROS costmaps use (own code): 254 lethal (an obstacle
//! cell), 253 inscribed (the robot centre here means the footprint touches an obstacle), then
//! an exponential decay `252 exp(-k (d - r_inscribed))` out to the inflation radius, 0 beyond.

use super::distance::distance_transform;
use super::map::{GridGeom, StaticMap};
use agrisim_msgs::nav_msgs::OccupancyGrid;
use serde::{Deserialize, Serialize};

pub const LETHAL: u8 = 254;
pub const INSCRIBED: u8 = 253;
/// Highest cost of a cell the robot centre may occupy.
pub const MAX_NON_OBSTACLE: u8 = 252;

/// Inflation parameters (the inscribed radius comes from the footprint).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct InflationConfig {
    /// Distance from obstacles beyond which cells cost nothing [m]. At least half the aisle
    /// width, so the aisle centre is the single cost minimum.
    pub inflation_radius: f64,
    /// Decay rate k of the cost beyond the inscribed radius [1/m].
    pub cost_scaling: f64,
}

impl Default for InflationConfig {
    fn default() -> Self {
        InflationConfig { inflation_radius: 1.25, cost_scaling: 3.0 }
    }
}

/// The cost of a cell at distance `d` [m] from the nearest obstacle cell (centre to centre).
/// Non-increasing in `d`.
pub fn inflation_cost(d: f64, inscribed_radius: f64, cfg: &InflationConfig) -> u8 {
    if d <= 0.0 {
        LETHAL
    } else if d <= inscribed_radius {
        INSCRIBED
    } else if d <= cfg.inflation_radius {
        let c = (MAX_NON_OBSTACLE as f64 * (-cfg.cost_scaling * (d - inscribed_radius)).exp()).round();
        c.clamp(1.0, MAX_NON_OBSTACLE as f64) as u8
    } else {
        0
    }
}

/// Static + blocked obstacles, their distance field and inflated costs.
#[derive(Debug, Clone)]
pub struct GlobalCostmap {
    pub geom: GridGeom,
    static_occupied: Vec<bool>,
    blocked: Vec<bool>,
    blocked_count: usize,
    /// Distance to the nearest obstacle (static or blocked), cell centres [m].
    pub distance: Vec<f32>,
    pub cost: Vec<u8>,
    inscribed_radius: f64,
    inflation: InflationConfig,
    dirty: bool,
}

impl GlobalCostmap {
    pub fn new(map: &StaticMap, inscribed_radius: f64, inflation: InflationConfig) -> GlobalCostmap {
        let n = map.geom.len();
        let mut c = GlobalCostmap {
            geom: map.geom,
            static_occupied: map.occupied.clone(),
            blocked: vec![false; n],
            blocked_count: 0,
            distance: map.distance.clone(),
            cost: vec![0; n],
            inscribed_radius,
            inflation,
            dirty: false,
        };
        c.recompute_costs();
        c
    }

    /// Marks a cell as an obstacle seen by the sensors. Returns whether it changed.
    pub fn add_blocked(&mut self, index: usize) -> bool {
        if index >= self.blocked.len() || self.blocked[index] || self.static_occupied[index] {
            return false;
        }
        self.blocked[index] = true;
        self.blocked_count += 1;
        self.dirty = true;
        true
    }

    /// Forgets a sensed obstacle (the sensors now see the cell free). Returns whether it changed.
    pub fn clear_blocked(&mut self, index: usize) -> bool {
        if index >= self.blocked.len() || !self.blocked[index] {
            return false;
        }
        self.blocked[index] = false;
        self.blocked_count -= 1;
        self.dirty = true;
        true
    }

    pub fn clear_all_blocked(&mut self) {
        if self.blocked_count > 0 {
            self.blocked.iter_mut().for_each(|b| *b = false);
            self.blocked_count = 0;
            self.dirty = true;
        }
    }

    pub fn is_blocked(&self, index: usize) -> bool {
        self.blocked[index]
    }

    pub fn blocked_count(&self) -> usize {
        self.blocked_count
    }

    /// Recomputes distances and costs after blocked cells changed (a full exact distance
    /// transform: a few ms for a 6-row greenhouse, done only on change).
    pub fn update(&mut self) -> bool {
        if !self.dirty {
            return false;
        }
        self.dirty = false;
        let obst: Vec<bool> = self.static_occupied.iter().zip(&self.blocked).map(|(&s, &b)| s || b).collect();
        let res = self.geom.resolution as f32;
        self.distance =
            distance_transform(&obst, self.geom.width, self.geom.height).into_iter().map(|d| d * res).collect();
        self.recompute_costs();
        true
    }

    fn recompute_costs(&mut self) {
        let (r, inf) = (self.inscribed_radius, self.inflation);
        self.cost = self.distance.iter().map(|&d| inflation_cost(d as f64, r, &inf)).collect();
    }

    /// Cost at a map point; outside the map is lethal.
    pub fn cost_at(&self, x: f64, y: f64) -> u8 {
        self.geom.index_of(x, y).map_or(LETHAL, |i| self.cost[i])
    }

    /// Obstacle distance at a map point, from the cell centre minus half a cell (≈ to the
    /// obstacle's edge); 0 outside the map.
    pub fn distance_at(&self, x: f64, y: f64) -> f64 {
        self.geom.index_of(x, y).map_or(0.0, |i| (self.distance[i] as f64 - 0.5 * self.geom.resolution).max(0.0))
    }

    /// As an OccupancyGrid for visualization (the costmap publishers' 0..100 scaling:
    /// lethal 100, inscribed 99, else 1..98).
    pub fn to_msg(&self, frame_id: &str, stamp: agrisim_msgs::builtin_interfaces::Time) -> OccupancyGrid {
        let mut g = super::map::occupancy_grid(&self.geom, &[], frame_id, stamp);
        g.data = self.cost.iter().map(|&c| cost_to_occupancy(c)).collect();
        g
    }
}

pub fn cost_to_occupancy(c: u8) -> i8 {
    match c {
        LETHAL => 100,
        INSCRIBED => 99,
        0 => 0,
        c => (1 + (c as u32 * 97) / MAX_NON_OBSTACLE as u32) as i8,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inflation_is_monotone_and_bounded() {
        let cfg = InflationConfig::default();
        let mut prev = LETHAL;
        for i in 0..400 {
            let c = inflation_cost(i as f64 * 0.005, 0.45, &cfg);
            assert!(c <= prev, "cost rises at d = {}", i as f64 * 0.005);
            prev = c;
        }
        assert_eq!(inflation_cost(0.0, 0.45, &cfg), LETHAL);
        assert_eq!(inflation_cost(0.45, 0.45, &cfg), INSCRIBED);
        assert!(inflation_cost(0.46, 0.45, &cfg) <= MAX_NON_OBSTACLE);
        assert_eq!(inflation_cost(1.3, 0.45, &cfg), 0);
    }

    #[test]
    fn blocked_cells_inflate() {
        let geom = GridGeom { origin_x: 0.0, origin_y: 0.0, resolution: 0.1, width: 40, height: 40 };
        let map = StaticMap::from_cells(geom, vec![false; 1600], "map".into());
        let mut c = GlobalCostmap::new(&map, 0.45, InflationConfig::default());
        assert_eq!(c.cost_at(2.0, 2.0), 0);
        let i = geom.index_of(2.0, 2.0).unwrap();
        assert!(c.add_blocked(i) && !c.add_blocked(i));
        assert!(c.update());
        assert_eq!(c.cost_at(2.0, 2.0), LETHAL);
        assert_eq!(c.cost_at(2.3, 2.0), INSCRIBED);
        assert!(c.cost_at(2.7, 2.0) > 0 && c.cost_at(2.7, 2.0) < INSCRIBED);
        assert!(c.clear_blocked(i) && c.update());
        assert_eq!(c.cost_at(2.0, 2.0), 0);
    }
}

/// The controller's view of obstacles: the smaller of the global and the local obstacle
/// distance, resampled once per control period onto the local window, so the thousands of
/// footprint lookups of one DWA step cost one multiply-and-index each.
#[derive(Debug, Clone)]
pub struct ClearanceGrid {
    geom: GridGeom,
    inv_res: f64,
    dist: Vec<f32>,
}

impl ClearanceGrid {
    /// From the two costmaps directly (the local window lies on the global lattice).
    pub fn from_costmaps(global: &GlobalCostmap, local: &super::local_costmap::LocalCostmap) -> ClearanceGrid {
        let (g, l) = (&global.geom, &local.geom);
        let ox = ((l.origin_x - g.origin_x) / g.resolution).round() as i64;
        let oy = ((l.origin_y - g.origin_y) / g.resolution).round() as i64;
        let half = 0.5 * g.resolution;
        let mut dist = Vec::with_capacity(l.len());
        for cy in 0..l.height {
            let gy = cy as i64 + oy;
            for cx in 0..l.width {
                let gx = cx as i64 + ox;
                let dg = if gx < 0 || gy < 0 || gx as usize >= g.width || gy as usize >= g.height {
                    0.0
                } else {
                    (global.distance[gy as usize * g.width + gx as usize] as f64 - half).max(0.0)
                };
                let dl = local.cell_distance(cx, cy);
                dist.push(dg.min(dl) as f32);
            }
        }
        ClearanceGrid { geom: *l, inv_res: 1.0 / l.resolution, dist }
    }

    /// Obstacle distance at a map point, `None` outside the window.
    #[inline]
    pub fn get(&self, x: f64, y: f64) -> Option<f64> {
        let fx = (x - self.geom.origin_x) * self.inv_res;
        let fy = (y - self.geom.origin_y) * self.inv_res;
        if fx >= 0.0 && fy >= 0.0 && fx < self.geom.width as f64 && fy < self.geom.height as f64 {
            Some(self.dist[fy as usize * self.geom.width + fx as usize] as f64)
        } else {
            None
        }
    }
}
