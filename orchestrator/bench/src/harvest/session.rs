//! The harvest system of a trial: the nodes around the harvest node under test.

use super::setup::HarvestSetup;
use crate::framework::Trial;
use crate::initial_pose::initial_estimate;
use crate::map::grid_message;
use agrisim_bus::Node;
use agrisim_error::Result;
use agrisim_mapping::{DepthMapper, MapperConfig};
use agrisim_nav::{Localizer, NavConfig};
use agrisim_nodes::{FaultInjector, MapServer, OdomTf, RobotStatePublisher, TaskPublisher};
use agrisim_perception::{Perception, PerceptionConfig};
use agrisim_session::{prepare, RunOptions};
use std::path::Path;

/// The row cameras of a harvest by sight (models/systems/harvest_sight.ssd).
pub const SIGHT_CAMERAS: [&str; 2] = ["camera_left", "camera_right"];

/// The simulated compute time the seeing nodes charged in a session [s] (none without sight).
#[derive(Clone, Debug, Default)]
pub struct SightCharges {
    perception: Option<agrisim_perception::Charged>,
    mapping: Option<agrisim_mapping::Charged>,
}

impl SightCharges {
    /// Perception's compute so far [s].
    pub fn perception(&self) -> f64 {
        self.perception.as_ref().map_or(0.0, |c| c.seconds())
    }
    /// The mapper's compute so far [s].
    pub fn mapping(&self) -> f64 {
        self.mapping.as_ref().map_or(0.0, |c| c.seconds())
    }
}

/// The nodes that see for a harvest by sight: perception (fruit map) and mapping (sensed
/// planning scene, with the robot's links filtered out and the harvest node's target allowed),
/// their compute charged in simulated time by their calibrated cost models (outputs held back
/// by it, as the harvest node's plans are by its planning), and handles on those charges.
/// `fruit_radius` (the scenario's `[harvest] fruit_radius`): the crop's fruit radii the
/// detector fits, pulled toward their middle; `None` keeps the detector's own.
pub fn sight_nodes(fruit_radius: Option<[f64; 2]>) -> Result<(Vec<Box<dyn Node>>, SightCharges)> {
    // Every 4th pixel and row: 5 mm between rays at the crop's 0.6 m, under the 1 cm voxels.
    // The scene: what the arms can reach from the base (1.5 m around base_link), once a second.
    // Rays beyond 1.2 m (through the row into the next aisle) only clear space out of reach.
    let map = agrisim_mapping::MapConfig { max_range: 1.2, ..Default::default() };
    let mapper = DepthMapper::new(MapperConfig {
        map,
        pixel_stride: 4,
        scene_period: 1.0,
        scene_around: Some(("base_link".into(), 1.5)),
        ..MapperConfig::for_cameras(&SIGHT_CAMERAS)
    })
    .map_err(|e| agrisim_error::err!("harvest by sight: mapping node: {e}"))?
    .with_cost(agrisim_mapping::CostModel::CALIBRATED);
    let mut perception = PerceptionConfig { map_period: 0.5, ..PerceptionConfig::for_cameras(&SIGHT_CAMERAS) };
    if let Some([lo, hi]) = fruit_radius {
        let sphere = &mut perception.detector.sphere;
        (sphere.min_radius, sphere.max_radius, sphere.prior_radius) = (lo, hi, 0.5 * (lo + hi));
    }
    let perception = Perception::new(perception).with_cost(agrisim_perception::CostModel::CALIBRATED);
    let charges = SightCharges { perception: Some(perception.charged()), mapping: Some(mapper.charged()) };
    Ok((vec![Box::new(perception), Box::new(mapper)], charges))
}

/// Trial `t`'s harvest system, ready to run from `start` (x, y, yaw of base_link): the map
/// server, odometry TF, the localizer started from a seeded estimate of the start pose (never
/// the true one), the robot state publisher, `harvest` (the node under test), the fault
/// injector, and `task` (what tells an external node its task), recording into `mcap`. By
/// sight (`[harvest] sight`), the perception and mapping nodes on the row cameras too, with
/// handles on their charged compute.
pub fn harvest_session(
    t: &Trial<HarvestSetup>,
    start: [f64; 3],
    mcap: &Path,
    harvest: Box<dyn Node>,
    task: Option<TaskPublisher>,
) -> Result<(agrisim_session::Session, SightCharges)> {
    let (setup, seed) = (t.setup, t.seed);
    let mut s = t.scenario.clone();
    let chassis = s.parameters.entry("chassis".into()).or_default();
    for (k, v) in ["x0", "y0", "yaw0"].iter().zip(start) {
        chassis.insert(k.to_string(), toml::Value::Float(v));
    }
    let (estimate, _) = initial_estimate(start, s.nav.initial_pose_std, seed);
    let mut nav_cfg = NavConfig::for_estimate(estimate, s.nav.initial_pose_std);
    nav_cfg.embedded_localizer = false;
    let mut nodes: Vec<Box<dyn Node>> = vec![
        Box::new(MapServer::new(grid_message(&setup.map, 0))),
        Box::new(OdomTf::default()),
        Box::new(Localizer::new(&nav_cfg)),
        Box::new(RobotStatePublisher::agrisim()),
        harvest,
        Box::new(FaultInjector::new(&s.inject)),
    ];
    if let Some(t) = task {
        nodes.push(Box::new(t));
    }
    let mut charges = SightCharges::default();
    if s.harvest.sight {
        let (sight, c) = sight_nodes(s.harvest.fruit_radius)?;
        nodes.extend(sight);
        charges = c;
    }
    let mut m = prepare(&s, &RunOptions { seed: Some(seed), ..t.run.clone() }, mcap, nodes)?;
    // By sight no node may read the world's answers: a read fails the trial, naming it.
    if s.harvest.sight {
        m.bus.seal_ground_truth();
    }
    Ok((m, charges))
}
