//! The prior map a trial's robot is given, as a real robot could have it: rasterized from
//! the building plan, never from a sensor.

use agrisim_greenhouse::occupancy::OccupancyMap;
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::geometry_msgs::{Point, Pose, Quaternion};
use agrisim_msgs::nav_msgs::{MapMetaData, OccupancyGrid};
use agrisim_msgs::std_msgs::Header;

/// Map resolution of the static map [m] (the issue asks for about 5 cm).
pub const MAP_RESOLUTION: f64 = 0.05;
/// Height band of the navigation map: what the base can hit [m].
pub const MAP_BAND: (f64, f64) = (0.05, 1.6);

/// The static map the robot is given: the building plan at [`MAP_RESOLUTION`], without
/// obstacles (those it must find with its LiDAR).
pub fn building_plan(g: &agrisim_greenhouse::Greenhouse) -> OccupancyMap {
    let planned: Vec<_> = g.objects.iter().filter(|o| o.kind != agrisim_greenhouse::Kind::Obstacle).cloned().collect();
    OccupancyMap::from_objects(&planned, MAP_RESOLUTION, MAP_BAND, g.layout.bounds)
}

/// The OccupancyGrid message of a rasterized map (frame `map`), for the map server.
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
