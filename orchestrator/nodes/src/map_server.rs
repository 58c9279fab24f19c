//! Publishes the static map on /map once at start, like Nav2's map_server loading a map file.
//! Where the map comes from (a building plan, a mapping run) is the caller's business: this
//! node only serves an OccupancyGrid.

use super::Node;
use agrisim_bus::Bus;
use agrisim_error::Result;
use agrisim_msgs::nav_msgs::OccupancyGrid;

pub const MAP: &str = "/map";

pub struct MapServer {
    grid: Option<OccupancyGrid>,
}

impl MapServer {
    /// Serves `grid` (e.g. a map drawn from the building plan, or recorded by a mapping run).
    pub fn new(grid: OccupancyGrid) -> MapServer {
        MapServer { grid: Some(grid) }
    }
}

impl Node for MapServer {
    fn name(&self) -> &str {
        "map_server"
    }

    fn step(&mut self, _t_ns: i64, bus: &mut Bus) -> Result<()> {
        if let Some(grid) = self.grid.take() {
            bus.publish(MAP, 0, &grid);
        }
        Ok(())
    }
}
