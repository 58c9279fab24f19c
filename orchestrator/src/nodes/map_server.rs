//! Publishes the static map on /map once at start, like Nav2's map_server loading a map that
//! was drawn from the building plan: here rasterized from the greenhouse scene (the same
//! geometry the world and sensor FMUs build), never from a sensor.

use super::Node;
use crate::bus::Bus;
use crate::error::Result;
use agrisim_greenhouse::occupancy::OccupancyMap;
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::geometry_msgs::{Point, Pose, Quaternion};
use agrisim_msgs::nav_msgs::{MapMetaData, OccupancyGrid};
use agrisim_msgs::std_msgs::Header;

pub const MAP: &str = "/map";

pub struct MapServer {
    grid: Option<OccupancyGrid>,
}

/// The OccupancyGrid message of a rasterized map (frame `map`).
pub fn grid_message(map: &OccupancyMap, t_ns: i64) -> OccupancyGrid {
    OccupancyGrid {
        header: Header { stamp: Time::from_nanos(t_ns), frame_id: "map".into() },
        info: MapMetaData {
            map_load_time: Time::from_nanos(t_ns),
            resolution: map.resolution as f32,
            width: map.width as u32,
            height: map.height as u32,
            origin: Pose { position: Point { x: map.origin[0], y: map.origin[1], z: 0.0 }, orientation: Quaternion { x: 0.0, y: 0.0, z: 0.0, w: 1.0 } },
        },
        data: map.data.clone(),
    }
}

impl MapServer {
    pub fn new(map: &OccupancyMap) -> MapServer {
        MapServer { grid: Some(grid_message(map, 0)) }
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
