//! The prior map a trial's robot is given, as a real robot could have it: rasterized from
//! the building plan, never from a sensor.

use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::geometry_msgs::{Point, Pose, Quaternion};
use agrisim_msgs::nav_msgs::{MapMetaData, OccupancyGrid};
use agrisim_msgs::std_msgs::Header;
use agrisim_scene::occupancy::OccupancyMap;

/// Map resolution of the static map [m] (the issue asks for about 5 cm).
pub const MAP_RESOLUTION: f64 = 0.05;
/// Height band of the navigation map: what the base can hit [m].
pub const MAP_BAND: (f64, f64) = (0.05, 1.6);

/// The area a prior map covers: the hall's floor and one cell beyond each wall's inner face,
/// so the walls (which stand outside the floor's bounds) are drawn as the LiDAR sees them, a
/// surface. With the floor's bounds alone no wall reached into a cell: the maps had no walls,
/// and in the headland the envelopes' end faces were the only feature along x (one-sided: a
/// scan's points may sink into a solid envelope), which biased the building plan's matches
/// 0.07-0.1 m toward the rows from the true pose (0.25-0.4 m iterated). A whole wall's
/// thickness would let scan points sink into it the same way (0.04-0.08 m toward it).
pub fn map_bounds(layout: &agrisim_scene::Layout) -> [f64; 4] {
    let [x0, y0, x1, y1] = layout.bounds;
    [x0 - MAP_RESOLUTION, y0 - MAP_RESOLUTION, x1 + MAP_RESOLUTION, y1 + MAP_RESOLUTION]
}

/// The static map the robot is given: the building plan at [`MAP_RESOLUTION`] over
/// [`map_bounds`]. The structure is in it (walls, posts, gutters, heating pipes: what the
/// builder drew), and
/// each crop row as its foliage envelope, a solid band along the row, because a grower knows
/// where the rows are but not where this week's leaves hang. Not in it: the trial's own
/// stems, leaves, trusses and fruit (a scan matcher would otherwise match the LiDAR against
/// the very plants it sees), and obstacles (the robot must find them with its LiDAR).
pub fn building_plan(g: &agrisim_scene::Greenhouse) -> OccupancyMap {
    use agrisim_scene::Kind;
    let structure: Vec<_> = g
        .objects
        .iter()
        .filter(|o| matches!(o.kind, Kind::Wall | Kind::Roof | Kind::Post | Kind::Gutter | Kind::HeatingPipe))
        .cloned()
        .collect();
    let mut map = OccupancyMap::from_objects(&structure, MAP_RESOLUTION, MAP_BAND, map_bounds(&g.layout));
    for r in &g.layout.rows {
        map.fill_rect(r.x_start, r.y - 0.5 * r.width, r.x_end, r.y + 0.5 * r.width);
    }
    map
}

/// The map of a mapping run: everything it saw but obstacles (moved since), from
/// [`mapping_run_scene`](agrisim_session::scene::mapping_run_scene).
pub fn mapping_run(seen: &agrisim_scene::Greenhouse) -> OccupancyMap {
    let kept: Vec<_> = seen.objects.iter().filter(|o| o.kind != agrisim_scene::Kind::Obstacle).cloned().collect();
    OccupancyMap::from_objects(&kept, MAP_RESOLUTION, MAP_BAND, map_bounds(&seen.layout))
}

/// The scenario's prior map (`[nav] prior_map`) for a trial in scene `g`.
pub fn prior_map(s: &agrisim_session::Scenario, g: &agrisim_scene::Greenhouse) -> agrisim_error::Result<OccupancyMap> {
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
            origin: Pose {
                position: Point { x: map.origin[0], y: map.origin[1], z: 0.0 },
                orientation: Quaternion { x: 0.0, y: 0.0, z: 0.0, w: 1.0 },
            },
        },
        data: map.data.clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use agrisim_scene::{config::GreenhouseConfig, generate, Kind};

    fn small() -> GreenhouseConfig {
        GreenhouseConfig::from_toml_str("rows = 4\nactive_rows = 3\nrow_length = 12.0\nlength = 20.0\nwidth = 14.0")
            .unwrap()
    }

    /// The plan knows the rows, not the plants: two crops (plant seeds) give the same map.
    #[test]
    fn the_plan_does_not_depend_on_the_plants() {
        let cfg = small();
        let (a, b) = (generate(&cfg, 1), generate(&cfg, 2));
        let leaves = |g: &agrisim_scene::Greenhouse| {
            g.objects.iter().filter(|o| o.kind == Kind::Leaf).map(|o| o.placement.translation).collect::<Vec<_>>()
        };
        assert_ne!(leaves(&a), leaves(&b), "the two seeds must grow different plants");
        assert_eq!(building_plan(&a).data, building_plan(&b).data);
    }

    /// The walls' inner faces are in both maps, all round (one cell beyond the floor), and the
    /// floor itself is rasterized as before the maps reached beyond it.
    #[test]
    fn the_maps_draw_the_walls_inner_faces() {
        let cfg = small();
        let g = generate(&cfg, 3);
        for (name, map) in [("plan", building_plan(&g)), ("mapping run", mapping_run(&generate(&cfg, 4)))] {
            let [x0, y0, x1, y1] = g.layout.bounds;
            let h = 0.5 * MAP_RESOLUTION;
            for k in 0..=100 {
                let (x, y) = (x0 + (x1 - x0) * k as f64 / 100.0, y0 + (y1 - y0) * k as f64 / 100.0);
                for (px, py) in [(x, y0 - h), (x, y1 + h), (x0 - h, y), (x1 + h, y)] {
                    assert!(map.is_occupied_at(px, py), "{name}: no wall at ({px:.3}, {py:.3})");
                }
            }
            // The headland in front of the start pose is free up to the wall's face.
            let [_, sy, _] = g.layout.start_pose;
            assert!(!map.is_occupied_at(x0 + h, sy), "{name}: the wall is thicker than its face");
            let floor = if name == "plan" {
                let structure: Vec<_> = g
                    .objects
                    .iter()
                    .filter(|o| {
                        matches!(o.kind, Kind::Wall | Kind::Roof | Kind::Post | Kind::Gutter | Kind::HeatingPipe)
                    })
                    .cloned()
                    .collect();
                let mut m = OccupancyMap::from_objects(&structure, MAP_RESOLUTION, MAP_BAND, g.layout.bounds);
                for r in &g.layout.rows {
                    m.fill_rect(r.x_start, r.y - 0.5 * r.width, r.x_end, r.y + 0.5 * r.width);
                }
                m
            } else {
                let seen = generate(&cfg, 4);
                let kept: Vec<_> = seen.objects.iter().filter(|o| o.kind != Kind::Obstacle).cloned().collect();
                OccupancyMap::from_objects(&kept, MAP_RESOLUTION, MAP_BAND, g.layout.bounds)
            };
            assert_eq!((map.width, map.height), (floor.width + 2, floor.height + 2), "{name}");
            for j in 0..floor.height {
                assert_eq!(
                    &map.data[(j + 1) * map.width + 1..(j + 1) * map.width + 1 + floor.width],
                    &floor.data[j * floor.width..(j + 1) * floor.width],
                    "{name}: row {j}"
                );
            }
        }
    }

    /// A horizontal LiDAR slice of the true scene (plants included) from `pose`: rays at three
    /// heights in the localizer's band, every 0.5 deg, base-frame points, one per 0.1 m voxel
    /// (as the localizer downsamples).
    fn slice(g: &agrisim_scene::Greenhouse, pose: [f64; 3]) -> Vec<(f64, f64)> {
        let caster = agrisim_raycast::RayCaster::new(&g.objects);
        let mut pts = std::collections::BTreeMap::new();
        for (k, z) in [0.4, 0.8, 1.2].into_iter().enumerate() {
            for i in 0..720 {
                let a = (i as f64 + k as f64 / 3.0) * std::f64::consts::TAU / 720.0;
                let (s, c) = (pose[2] + a).sin_cos();
                if let Some(hit) = caster.cast([pose[0], pose[1], z], [c, s, 0.0], 0.3, 25.0, &[]) {
                    let (x, y) = (hit.distance * a.cos(), hit.distance * a.sin());
                    pts.entry(((x / 0.1).floor() as i64, (y / 0.1).floor() as i64)).or_insert((x, y));
                }
            }
        }
        pts.into_values().collect()
    }

    /// Where the localizer's map match settles, standing at `pose`: matched from an estimate
    /// 0.1 m / 0.1 m / 0.03 rad off, then again from each match (a standing robot's filter
    /// trusts repeated matches). Returns the position error [m] and the matches made.
    fn settled_error(map: &OccupancyMap, pts: &[(f64, f64)], pose: [f64; 3]) -> (f64, usize) {
        use agrisim_nav::map::StaticMap;
        use agrisim_nav::scan_match::{correlative_match, LikelihoodField, ScanMatchConfig};
        let cfg = ScanMatchConfig::default();
        let field = LikelihoodField::new(&StaticMap::from_msg(&grid_message(map, 0), false).unwrap(), &cfg);
        let mut est = agrisim_nav::Pose2::new(pose[0] + 0.1, pose[1] - 0.1, pose[2] + 0.03);
        let mut matches = 0;
        for _ in 0..10 {
            if let Some(m) = correlative_match(&field, pts, &est, &cfg) {
                est = m.pose;
                matches += 1;
            }
        }
        ((est.x - pose[0]).hypot(est.y - pose[1]), matches)
    }

    /// Regression: in the headland, the building plan pins the robot's position. Before the
    /// maps reached the walls' faces, the only feature along x there was the envelopes' end
    /// faces, which a scan's points may sink into, and matches walked toward the rows (0.25-0.4
    /// m in the default greenhouse, the final localization errors of headland trials 0.13-0.2
    /// m). The default greenhouse (6 rows of 30 m in a 70 x 55 m hall).
    #[test]
    fn the_plan_pins_the_pose_in_the_headland() {
        let g = generate(&GreenhouseConfig::default(), 3);
        let [sx, sy, _] = g.layout.start_pose;
        let structure: Vec<_> = g
            .objects
            .iter()
            .filter(|o| matches!(o.kind, Kind::Wall | Kind::Roof | Kind::Post | Kind::Gutter | Kind::HeatingPipe))
            .cloned()
            .collect();
        let mut floor_only = OccupancyMap::from_objects(&structure, MAP_RESOLUTION, MAP_BAND, g.layout.bounds);
        for r in &g.layout.rows {
            floor_only.fill_rect(r.x_start, r.y - 0.5 * r.width, r.x_end, r.y + 0.5 * r.width);
        }
        let plan = building_plan(&g);
        for yaw in [0.0, 1.5, 3.0] {
            let pose = [sx, sy + 0.4, yaw];
            let pts = slice(&g, pose);
            let ((now, n_now), (before, n_before)) =
                (settled_error(&plan, &pts, pose), settled_error(&floor_only, &pts, pose));
            println!("yaw {yaw}: settled {now:.3} m with the walls' faces ({n_now} matches), {before:.3} m without ({n_before})");
            assert!(now < 0.05 && n_now == 10, "yaw {yaw}: {now:.3} m, {n_now} matches");
            assert_eq!(n_before, 10, "yaw {yaw}");
            assert!(before > 0.1, "yaw {yaw}: the test no longer sees the bias it guards against ({before:.3} m)");
        }
    }

    /// Every plant part in the base's height band lies inside a mapped row envelope, and the
    /// aisles between envelopes are free.
    #[test]
    fn row_envelopes_cover_the_plants_and_leave_the_aisles_free() {
        let g = generate(&small(), 3);
        let map = building_plan(&g);
        let mut plants = 0;
        for o in
            g.objects.iter().filter(|o| matches!(o.kind, Kind::Stem | Kind::Leaf | Kind::Truss | Kind::Fruit { .. }))
        {
            let c = o.placement.translation;
            if c[2] > MAP_BAND.0 && c[2] < MAP_BAND.1 {
                assert!(
                    map.is_occupied_at(c[0], c[1]),
                    "{} at ({:.2}, {:.2}) outside the mapped envelopes",
                    o.name,
                    c[0],
                    c[1]
                );
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
