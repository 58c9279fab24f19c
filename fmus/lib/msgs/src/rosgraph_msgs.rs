//! `rosgraph_msgs`: the `/clock` message that drives `use_sim_time` nodes.

use crate::builtin_interfaces::Time;
use crate::message::ros_message;

ros_message! {
    /// `rosgraph_msgs/msg/Clock`.
    #[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
    pub struct Clock = "rosgraph_msgs/msg/Clock" {
        pub clock: Time,
    }
}
