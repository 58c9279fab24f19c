//! `agrisim_msgs`: agrisim's own record types. The module is named `agrisim`, not
//! `agrisim_msgs`, so that `use agrisim_msgs::*` does not make the crate name ambiguous.
//! They are not ROS standard; their .msg files ship in models/msgs/agrisim_msgs so MCAP
//! readers can still decode them.

use crate::message::ros_message;
use crate::std_msgs::Header;

ros_message! {
    /// `agrisim_msgs/msg/Signals`: an FMU's scalar outputs at one step, so plain
    /// Float64/Int/Boolean ports end up in the same MCAP as the messages.
    /// `names[i]` labels `values[i]`; `header.frame_id` is the FMU instance name.
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct Signals = "agrisim_msgs/msg/Signals" {
        pub header: Header,
        pub names: Vec<String>,
        pub values: Vec<f64>,
    }
}

ros_message! {
    /// `agrisim_msgs/msg/FmuStatus`: a status change or error of one FMU instance, so a
    /// recording shows why a run stopped.
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct FmuStatus = "agrisim_msgs/msg/FmuStatus" {
        pub header: Header,
        pub instance: String,
        pub status: String,
        pub message: String,
    }
}

ros_message! {
    /// `agrisim_msgs/msg/Contact`: one robot-scene contact, in the map frame.
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct Contact = "agrisim_msgs/msg/Contact" {
        pub object_id: u32,
        pub object_name: String,
        pub object_kind: String,
        pub robot_link: String,
        pub position: crate::geometry_msgs::Point,
        pub normal: crate::geometry_msgs::Vector3,
        pub depth: f64,
    }
}

ros_message! {
    /// `agrisim_msgs/msg/CollisionState`: all robot-scene contacts at one instant.
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct CollisionState = "agrisim_msgs/msg/CollisionState" {
        pub header: Header,
        pub in_collision: bool,
        pub count: u32,
        pub contacts: Vec<Contact>,
    }
}

ros_message! {
    /// `agrisim_msgs/msg/NavigationStatus`: what the navigation executor is doing.
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct NavigationStatus = "agrisim_msgs/msg/NavigationStatus" {
        pub header: Header,
        pub state: String,
        pub detail: String,
        pub goal: crate::geometry_msgs::PoseStamped,
    }
}
