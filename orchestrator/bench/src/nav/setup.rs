//! What every nav trial of a scene shares: the scene, the robot's prior map and the full map
//! targets are kept clear in.

use crate::map::{prior_map, MAP_BAND, MAP_RESOLUTION};
use agrisim_error::Result;
use agrisim_scene::occupancy::OccupancyMap;
use agrisim_session::Scenario;

/// Everything a trial needs that does not change between trials.
pub struct NavSetup {
    pub layout: agrisim_scene::Layout,
    pub objects: Vec<agrisim_scene::Object>,
    /// The static map the robot is given: the building plan, without obstacles (those it
    /// must find with its LiDAR and plan around).
    pub map: OccupancyMap,
    /// Everything, obstacles included: only to keep targets out of obstacles.
    pub truth: OccupancyMap,
    /// The global planner and controller the scenario's `[nav]` table names.
    pub plugins: agrisim_nav::Plugins,
}

impl NavSetup {
    pub fn new(s: &Scenario) -> Result<NavSetup> {
        let plugins = agrisim_nav::Plugins::from_names(&s.nav.planner, &s.nav.controller)
            .map_err(|e| agrisim_error::err!("scenario {}: [nav] {e}", s.path.display()))?;
        let g = agrisim_session::scene::generate_scene(s)?;
        let map = prior_map(s, &g)?;
        let truth = OccupancyMap::from_objects(&g.objects, MAP_RESOLUTION, MAP_BAND, g.layout.bounds);
        Ok(NavSetup { layout: g.layout, objects: g.objects, map, truth, plugins })
    }
}
