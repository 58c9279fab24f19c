//! `tf2_msgs`: the `/tf` and `/tf_static` message.

use crate::geometry_msgs::TransformStamped;
use crate::message::ros_message;

ros_message! {
    /// `tf2_msgs/msg/TFMessage`.
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct TFMessage = "tf2_msgs/msg/TFMessage" {
        pub transforms: Vec<TransformStamped>,
    }
}
