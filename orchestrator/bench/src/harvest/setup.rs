//! What every harvest trial of a scene shares: its layout, the robot's prior map, and the
//! target candidates (ripe fruit of the scenario's visibility classes that face an aisle).

use super::targets::{eligible, HarvestTarget, Visibility};
use crate::map::prior_map;
use agrisim_error::{err, Result};
use agrisim_scene::occupancy::OccupancyMap;
use agrisim_session::Scenario;

/// Everything a trial needs that does not change between trials.
pub struct HarvestSetup {
    pub layout: agrisim_scene::Layout,
    pub map: OccupancyMap,
    pub candidates: Vec<HarvestTarget>,
    /// Every fruit of the scene by object id: USDA stage and centre (the judge's ground truth
    /// for a fruit the node chose itself).
    pub fruit: std::collections::BTreeMap<u32, (u8, [f64; 3])>,
}

impl HarvestSetup {
    pub fn new(s: &Scenario) -> Result<HarvestSetup> {
        let g = agrisim_session::scene::generate_scene(s)?;
        let map = prior_map(s, &g)?;
        let classes = &s.harvest.visibility;
        for c in classes {
            if ![Visibility::Free, Visibility::PartlyOccluded, Visibility::BehindStem].iter().any(|v| v.name() == c) {
                return Err(err!(
                    "scenario {}: [harvest] visibility: unknown class \"{c}\" (free, partly_occluded, behind_stem)",
                    s.path.display()
                ));
            }
        }
        let mut candidates = eligible(&g.objects, &g.layout);
        candidates.retain(|t| classes.iter().any(|c| c == t.visibility.name()));
        if candidates.is_empty() {
            return Err(err!("scenario {}: no ripe fruit of the visibility classes {classes:?} faces an aisle at a harvestable height", s.path.display()));
        }
        let fruit = g
            .objects
            .iter()
            .filter_map(|o| match o.kind {
                agrisim_scene::Kind::Fruit { ripeness } => Some((o.id, (ripeness, o.placement.translation))),
                _ => None,
            })
            .collect();
        Ok(HarvestSetup { layout: g.layout, map, candidates, fruit })
    }
}
