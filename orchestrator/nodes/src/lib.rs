//! The algorithm layer's nodes: small units that speak only ROS 2 messages (and the
//! system's scalar inputs), like ROS 2 nodes, so real ROS 2 nodes can later take their place.

mod command_script;
mod fault_injector;
mod goal_publisher;
mod map_server;
mod odom_tf;
mod pacer;
mod robot_state;
mod task_publisher;

pub use command_script::{BaseCommand, CommandScript, LiftCommand};
pub use fault_injector::{FaultInjector, Injection};
pub use goal_publisher::GoalPublisher;
pub use map_server::MapServer;
pub use odom_tf::OdomTf;
pub use pacer::{Pace, RealtimePacer};
pub use robot_state::RobotStatePublisher;
pub use task_publisher::TaskPublisher;

pub use agrisim_bus::Node;
