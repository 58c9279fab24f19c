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

/// The static map the robot is given: the building plan at [`MAP_RESOLUTION`]. The
/// structure is in it (walls, posts, gutters, heating pipes: what the builder drew), and
/// each crop row as its foliage envelope, a solid band along the row, because a grower knows
/// where the rows are but not where this week's leaves hang. Not in it: the trial's own
/// stems, leaves, trusses and fruit (a scan matcher would otherwise match the LiDAR against
/// the very plants it sees), and obstacles (the robot must find them with its LiDAR).
pub fn building_plan(g: &agrisim_greenhouse::Greenhouse) -> OccupancyMap {
    use agrisim_greenhouse::Kind;
    let structure: Vec<_> =
        g.objects.iter().filter(|o| matches!(o.kind, Kind::Wall | Kind::Roof | Kind::Post | Kind::Gutter | Kind::HeatingPipe)).cloned().collect();
    let mut map = OccupancyMap::from_objects(&structure, MAP_RESOLUTION, MAP_BAND, g.layout.bounds);
    for r in &g.layout.rows {
        map.fill_rect(r.x_start, r.y - 0.5 * r.width, r.x_end, r.y + 0.5 * r.width);
    }
    map
}

/// The map of a mapping run: everything it saw but obstacles (moved since), from
/// [`mapping_run_scene`](agrisim_session::scene::mapping_run_scene).
pub fn mapping_run(seen: &agrisim_greenhouse::Greenhouse) -> OccupancyMap {
    let kept: Vec<_> = seen.objects.iter().filter(|o| o.kind != agrisim_greenhouse::Kind::Obstacle).cloned().collect();
    OccupancyMap::from_objects(&kept, MAP_RESOLUTION, MAP_BAND, seen.layout.bounds)
}

/// The scenario's prior map (`[nav] prior_map`) for a trial in scene `g`.
pub fn prior_map(s: &agrisim_session::Scenario, g: &agrisim_greenhouse::Greenhouse) -> agrisim_error::Result<OccupancyMap> {
    Ok(match s.nav.prior_map {
        agrisim_session::PriorMap::Plan => building_plan(g),
        agrisim_session::PriorMap::MappingRun => mapping_run(&agrisim_session::scene::mapping_run_scene(s)?),
    })
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

#[cfg(test)]
mod tests {
    use super::*;
    use agrisim_greenhouse::{config::GreenhouseConfig, generate, Kind};

    fn small() -> GreenhouseConfig {
        GreenhouseConfig::from_toml_str("rows = 4\nactive_rows = 3\nrow_length = 12.0\nlength = 20.0\nwidth = 14.0").unwrap()
    }

    /// The plan knows the rows, not the plants: two crops (plant seeds) give the same map.
    #[test]
    fn the_plan_does_not_depend_on_the_plants() {
        let cfg = small();
        let (a, b) = (generate(&cfg, 1), generate(&cfg, 2));
        let leaves = |g: &agrisim_greenhouse::Greenhouse| g.objects.iter().filter(|o| o.kind == Kind::Leaf).map(|o| o.placement.translation).collect::<Vec<_>>();
        assert_ne!(leaves(&a), leaves(&b), "the two seeds must grow different plants");
        assert_eq!(building_plan(&a).data, building_plan(&b).data);
    }

    /// Every plant part in the base's height band lies inside a mapped row envelope, and the
    /// aisles between envelopes are free.
    #[test]
    fn row_envelopes_cover_the_plants_and_leave_the_aisles_free() {
        let g = generate(&small(), 3);
        let map = building_plan(&g);
        let mut plants = 0;
        for o in g.objects.iter().filter(|o| matches!(o.kind, Kind::Stem | Kind::Leaf | Kind::Truss | Kind::Fruit { .. })) {
            let c = o.placement.translation;
            if c[2] > MAP_BAND.0 && c[2] < MAP_BAND.1 {
                assert!(map.is_occupied_at(c[0], c[1]), "{} at ({:.2}, {:.2}) outside the mapped envelopes", o.name, c[0], c[1]);
                plants += 1;
            }
        }
        assert!(plants > 100, "{plants} plant parts checked");
        for a in &g.layout.aisles {
            let mid = 0.5 * (a.x_start + a.x_end);
            assert!(!map.is_occupied_at(mid, a.y), "aisle {} blocked in the plan", a.index);
        }
    }
}
