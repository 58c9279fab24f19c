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

ros_message! {
    /// `agrisim_msgs/msg/GripperState`: the parallel gripper's measured gap and force.
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct GripperState = "agrisim_msgs/msg/GripperState" {
        pub header: Header,
        /// Finger gap in m.
        pub position: f64,
        /// Grip force in N.
        pub effort: f64,
        pub stalled: bool,
        pub reached_goal: bool,
    }
}

ros_message! {
    /// `agrisim_msgs/msg/TrajectoryStatus`: the arm's trajectory executor state, counters,
    /// the reason of the last rejection and tracking error of the last/current trajectory.
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct TrajectoryStatus = "agrisim_msgs/msg/TrajectoryStatus" {
        pub header: Header,
        pub state: u8,
        pub trajectory_count: u64,
        pub rejected_count: u64,
        pub reason: String,
        pub rms_tracking_error: f64,
        pub max_tracking_error: f64,
    }
}

impl TrajectoryStatus {
    pub const IDLE: u8 = 0;
    pub const EXECUTING: u8 = 1;
    pub const SUCCEEDED: u8 = 2;
    pub const REJECTED: u8 = 3;
}

ros_message! {
    /// `agrisim_msgs/msg/CollisionObject`: one primitive obstacle of a planning scene;
    /// `kind` is floor, post, stem, leaf, fruit, ...
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct CollisionObject = "agrisim_msgs/msg/CollisionObject" {
        pub id: String,
        pub kind: String,
        pub primitive: crate::shape_msgs::SolidPrimitive,
        pub pose: crate::geometry_msgs::Pose,
    }
}

ros_message! {
    /// `agrisim_msgs/msg/PlanningScene`: the obstacles the planner avoids, in
    /// `header.frame_id`.
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct PlanningScene = "agrisim_msgs/msg/PlanningScene" {
        pub header: Header,
        pub objects: Vec<CollisionObject>,
    }
}

ros_message! {
    /// `agrisim_msgs/msg/HarvestStatus`: stage and outcome of the harvest state machine;
    /// `failure_category` is "", planning, grasp, handover, placement, timeout or collision.
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct HarvestStatus = "agrisim_msgs/msg/HarvestStatus" {
        pub header: Header,
        pub stage: String,
        pub target_id: i32,
        pub target_name: String,
        pub outcome: String,
        pub failure_category: String,
        pub detail: String,
        /// Motions planned so far (wall times stay out of the log: byte-identical runs).
        pub plans: u32,
    }
}

ros_message! {
    /// `agrisim_msgs/msg/MovedObjects`: ground truth of the scene objects away from where the
    /// greenhouse grew them (pushed leaves, picked fruit), all at one instant: what the sensor
    /// FMUs render in place of their grown placement. Never for algorithm nodes.
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct MovedObjects = "agrisim_msgs/msg/MovedObjects" {
        pub header: Header,
        /// Scene object ids, ascending.
        pub ids: Vec<u32>,
        /// Each object's placement (its shape's frame) in the map frame.
        pub poses: Vec<crate::geometry_msgs::Pose>,
    }
}

ros_message! {
    /// `agrisim_msgs/msg/PlantDamage`: ground truth of what the harvest did to the crop,
    /// cumulative since the start (counts per kind) and the last pedicel break. For the
    /// judge only: algorithm nodes never read it.
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct PlantDamage = "agrisim_msgs/msg/PlantDamage" {
        pub header: Header,
        pub bruised_by_grip: u32,
        pub bruised_by_impact: u32,
        pub unripe_detached: u32,
        pub stems_broken: u32,
        pub detached_by_pull: u32,
        pub detached_by_bend: u32,
        pub detached_by_twist: u32,
        /// "" (none yet), pull, bend or twist.
        pub last_detach_mode: String,
        /// Pedicel force on the fruit when it broke [N].
        pub last_detach_force: f64,
        /// Larger of the bending and twisting moment at the abscission zone then [N m].
        pub last_detach_moment: f64,
        /// Leaves the robot pressed aside from rest: not damage, the cost of passing.
        pub leaf_pushes: u32,
        /// Largest force the robot spent holding a leaf aside [N] (to 0.1 N).
        pub peak_leaf_force: f64,
        /// Largest bending moment a robot part put on a main stem over its strength (to 0.01;
        /// 1: broken).
        pub peak_stem_load: f64,
    }
}

ros_message! {
    /// `agrisim_msgs/msg/PlanResult`: one motion plan a task node asked for and its result;
    /// `optional` plans have a fallback, so their failure does not fail the task.
    /// `planning_time`: the simulated time the plan took [s] (the node's own account; a
    /// trajectory it produced starts no earlier than that after the request).
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct PlanResult = "agrisim_msgs/msg/PlanResult" {
        pub header: Header,
        pub stage: String,
        pub arm: String,
        pub kind: String,
        pub ok: bool,
        pub optional: bool,
        pub detail: String,
        pub planning_time: f64,
    }
}
