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
    /// Every fruit of the scene by object id (the judge's ground truth for a fruit the node
    /// chose itself).
    pub fruit: std::collections::BTreeMap<u32, TrueFruit>,
}

/// A fruit as the world has it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrueFruit {
    /// USDA ripeness stage (1-6).
    pub stage: u8,
    pub center: [f64; 3],
    pub radius: f64,
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
            .filter_map(|o| match (o.kind, o.shape) {
                (agrisim_scene::Kind::Fruit { ripeness }, agrisim_scene::Shape::Sphere { radius }) => {
                    Some((o.id, TrueFruit { stage: ripeness, center: o.placement.translation, radius }))
                }
                _ => None,
            })
            .collect();
        Ok(HarvestSetup { layout: g.layout, map, candidates, fruit })
    }
}
