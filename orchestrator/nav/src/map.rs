//! The static map: a nav_msgs/OccupancyGrid (from a map_server-like node on `/map`) read into
//! a grid of occupied cells plus its distance field. Everything else in the stack (costmaps,
//! planner, localizer) works in this grid's geometry.

use super::distance::distance_transform;
use agrisim_error::err;
use agrisim_error::Result;
use agrisim_msgs::nav_msgs::OccupancyGrid;

/// Placement and size of a regular grid in the map frame (axis-aligned).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridGeom {
    /// Map-frame position of the outer corner of cell (0, 0) [m].
    pub origin_x: f64,
    pub origin_y: f64,
    /// Cell edge [m].
    pub resolution: f64,
    pub width: usize,
    pub height: usize,
}

impl GridGeom {
    pub fn len(&self) -> usize {
        self.width * self.height
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Cell containing a map point, if inside the grid.
    pub fn cell(&self, x: f64, y: f64) -> Option<(usize, usize)> {
        let cx = ((x - self.origin_x) / self.resolution).floor();
        let cy = ((y - self.origin_y) / self.resolution).floor();
        (cx >= 0.0 && cy >= 0.0 && (cx as usize) < self.width && (cy as usize) < self.height)
            .then_some((cx as usize, cy as usize))
    }

    pub fn index_of(&self, x: f64, y: f64) -> Option<usize> {
        self.cell(x, y).map(|(cx, cy)| cy * self.width + cx)
    }

    pub fn center(&self, cx: usize, cy: usize) -> (f64, f64) {
        (self.origin_x + (cx as f64 + 0.5) * self.resolution, self.origin_y + (cy as f64 + 0.5) * self.resolution)
    }
}

/// Occupancy values at or above this are obstacles (map_server's occupied_thresh 0.65).
pub const OCCUPIED_THRESHOLD: i8 = 65;

/// The static map as obstacles and their distance field.
#[derive(Debug, Clone)]
pub struct StaticMap {
    pub geom: GridGeom,
    pub frame_id: String,
    /// Occupied (or unknown, when unknown counts as obstacle) cells.
    pub occupied: Vec<bool>,
    /// Distance from each cell centre to the nearest occupied cell's centre [m].
    pub distance: Vec<f32>,
}

impl StaticMap {
    /// Reads an OccupancyGrid; `unknown_is_obstacle` decides what -1 cells are.
    /// Rotated map origins are not supported (map_server maps are axis-aligned in practice).
    pub fn from_msg(msg: &OccupancyGrid, unknown_is_obstacle: bool) -> Result<StaticMap> {
        let info = &msg.info;
        let (w, h) = (info.width as usize, info.height as usize);
        if w == 0 || h == 0 || info.resolution.is_nan() || info.resolution <= 0.0 {
            return Err(err!("/map: empty grid or non-positive resolution ({w} x {h}, {} m)", info.resolution));
        }
        if msg.data.len() != w * h {
            return Err(err!("/map: {} cells for a {w} x {h} grid", msg.data.len()));
        }
        let yaw = info.origin.orientation.yaw();
        if yaw.abs() > 1e-6 {
            return Err(err!("/map: rotated map origins (yaw {yaw:.3} rad) are not supported"));
        }
        // The f32 resolution read back as the decimal it was written as (0.05, not 0.0500000007),
        // so cell boundaries land where the map's author put them.
        let resolution = info.resolution.to_string().parse::<f64>().unwrap_or(info.resolution as f64);
        let geom = GridGeom {
            origin_x: info.origin.position.x,
            origin_y: info.origin.position.y,
            resolution,
            width: w,
            height: h,
        };
        let occupied: Vec<bool> =
            msg.data.iter().map(|&v| v >= OCCUPIED_THRESHOLD || (v < 0 && unknown_is_obstacle)).collect();
        Ok(StaticMap::from_cells(geom, occupied, msg.header.frame_id.clone()))
    }

    pub fn from_cells(geom: GridGeom, occupied: Vec<bool>, frame_id: String) -> StaticMap {
        let res = geom.resolution as f32;
        let distance = distance_transform(&occupied, geom.width, geom.height).into_iter().map(|d| d * res).collect();
        StaticMap { geom, frame_id, occupied, distance }
    }

    /// Distance to the nearest mapped obstacle at a map point (0 outside the map: the
    /// outside is treated as a wall).
    pub fn distance_at(&self, x: f64, y: f64) -> f64 {
        self.geom.index_of(x, y).map_or(0.0, |i| self.distance[i] as f64)
    }
}

/// Builds an OccupancyGrid message (0 free, 100 occupied) from cells, e.g. for tests or a
/// map server that rasterized a scene itself.
pub fn occupancy_grid(
    geom: &GridGeom,
    occupied: &[bool],
    frame_id: &str,
    stamp: agrisim_msgs::builtin_interfaces::Time,
) -> OccupancyGrid {
    let mut g = OccupancyGrid::default();
    g.header.frame_id = frame_id.to_string();
    g.header.stamp = stamp;
    g.info.map_load_time = stamp;
    g.info.resolution = geom.resolution as f32;
    g.info.width = geom.width as u32;
    g.info.height = geom.height as u32;
    g.info.origin.position.x = geom.origin_x;
    g.info.origin.position.y = geom.origin_y;
    g.data = occupied.iter().map(|&o| if o { 100 } else { 0 }).collect();
    g
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_grid_and_distances() {
        let geom = GridGeom { origin_x: -1.0, origin_y: 2.0, resolution: 0.1, width: 10, height: 5 };
        let mut occ = vec![false; 50];
        occ[2 * 10 + 3] = true;
        let msg = occupancy_grid(&geom, &occ, "map", Default::default());
        let m = StaticMap::from_msg(&msg, true).unwrap();
        assert_eq!(m.geom, geom);
        let (x, y) = geom.center(3, 2);
        assert_eq!(m.distance_at(x, y), 0.0);
        assert!((m.distance_at(x + 0.3, y) - 0.3).abs() < 1e-6);
        assert_eq!(geom.cell(-1.0 + 0.95, 2.05), Some((9, 0)));
        assert_eq!(geom.cell(-1.01, 2.05), None);
    }
}
