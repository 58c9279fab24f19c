//! The algorithm layer's nodes: small units that speak only ROS 2 messages (and the
//! system's scalar inputs), like ROS 2 nodes, so real ROS 2 nodes can later take their place.

mod command_script;
mod fault_injector;
mod goal_publisher;
mod map_server;
mod odom_tf;
mod robot_state;

pub use command_script::CommandScript;
pub use fault_injector::FaultInjector;
pub use goal_publisher::GoalPublisher;
pub use map_server::{grid_message, MapServer};
pub use odom_tf::OdomTf;
pub use robot_state::RobotStatePublisher;

use crate::bus::Bus;
use crate::error::Result;

/// A node runs at every message exchange instant.
pub trait Node {
    fn name(&self) -> &str;
    /// Reads what it needs from the bus and publishes its outputs at time `t_ns`.
    fn step(&mut self, t_ns: i64, bus: &mut Bus) -> Result<()>;
}
