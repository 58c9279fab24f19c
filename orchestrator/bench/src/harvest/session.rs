//! The harvest system of a trial: the nodes around the harvest node under test.

use super::setup::HarvestSetup;
use crate::framework::Trial;
use crate::initial_pose::initial_estimate;
use crate::map::grid_message;
use agrisim_bus::Node;
use agrisim_error::Result;
use agrisim_nav::{Localizer, NavConfig};
use agrisim_nodes::{FaultInjector, MapServer, OdomTf, RobotStatePublisher, TaskPublisher};
use agrisim_session::{prepare, RunOptions};
use std::path::Path;

/// Trial `t`'s harvest system, ready to run from `start` (x, y, yaw of base_link): the map
/// server, odometry TF, the localizer started from a seeded estimate of the start pose (never
/// the true one), the robot state publisher, `harvest` (the node under test), the fault
/// injector, and `task` (what tells an external node its task), recording into `mcap`.
pub fn harvest_session(
    t: &Trial<HarvestSetup>,
    start: [f64; 3],
    mcap: &Path,
    harvest: Box<dyn Node>,
    task: Option<TaskPublisher>,
) -> Result<agrisim_session::Session> {
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
    prepare(&s, &RunOptions { seed: Some(seed), ..t.run.clone() }, mcap, nodes)
}
