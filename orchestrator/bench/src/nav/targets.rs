//! Seeded navigation targets: a point on an aisle's centre line or in the headland, away from
//! the aisle ends and from anything the static map marks occupied.

use agrisim_math::Rng;
use agrisim_scene::occupancy::OccupancyMap;
use agrisim_scene::Layout;

/// Draws a target (x, y, yaw) for a trial. Aisles are chosen in proportion to their length,
/// the headland with probability 1/4 when allowed; the yaw is uniform (the base is omni).
pub fn draw_target(
    layout: &Layout,
    map: &OccupancyMap,
    rng: &mut Rng,
    headland: bool,
    margin: f64,
    clearance: f64,
) -> Option<[f64; 3]> {
    let lengths: Vec<f64> = layout.aisles.iter().map(|a| (a.x_end - a.x_start - 2.0 * margin).max(0.0)).collect();
    let total: f64 = lengths.iter().sum();
    for _ in 0..1000 {
        let (x, y) = if headland && (total == 0.0 || rng.uniform() < 0.25) {
            let [x0, y0, x1, y1] = layout.headland;
            (
                x0 + margin + rng.uniform() * (x1 - x0 - 2.0 * margin).max(0.0),
                y0 + margin + rng.uniform() * (y1 - y0 - 2.0 * margin).max(0.0),
            )
        } else {
            if total == 0.0 {
                return None;
            }
            let mut pick = rng.uniform() * total;
            let mut i = 0;
            while i + 1 < lengths.len() && pick > lengths[i] {
                pick -= lengths[i];
                i += 1;
            }
            let a = &layout.aisles[i];
            (a.x_start + margin + rng.uniform() * lengths[i], a.y)
        };
        let yaw = (rng.uniform() * 2.0 - 1.0) * std::f64::consts::PI;
        if free_around(map, x, y, clearance) {
            return Some([x, y, yaw]);
        }
    }
    None
}

/// No occupied cell within `r` of (x, y).
pub fn free_around(map: &OccupancyMap, x: f64, y: f64, r: f64) -> bool {
    let n = (r / map.resolution).ceil() as i64;
    for i in -n..=n {
        for j in -n..=n {
            let (dx, dy) = (i as f64 * map.resolution, j as f64 * map.resolution);
            if dx * dx + dy * dy <= r * r && map.is_occupied_at(x + dx, y + dy) {
                return false;
            }
        }
    }
    true
}
