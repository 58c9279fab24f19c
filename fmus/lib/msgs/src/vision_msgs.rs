//! `vision_msgs` (ROS 2 Humble and later, vision_msgs 4.x): object detections with class
//! hypotheses and 3-D boxes, as a perception node publishes them and Foxglove shows them.

use crate::geometry_msgs::{Pose, PoseWithCovariance, Vector3};
use crate::message::ros_message;
use crate::std_msgs::Header;

ros_message! {
    /// `vision_msgs/msg/ObjectHypothesis`: a class and its score (by convention in [0, 1]).
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct ObjectHypothesis = "vision_msgs/msg/ObjectHypothesis" {
        pub class_id: String,
        pub score: f64,
    }
}

ros_message! {
    /// `vision_msgs/msg/ObjectHypothesisWithPose`: a hypothesis and the pose of the object
    /// under it (frame from the parent message).
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct ObjectHypothesisWithPose = "vision_msgs/msg/ObjectHypothesisWithPose" {
        pub hypothesis: ObjectHypothesis,
        pub pose: PoseWithCovariance,
    }
}

ros_message! {
    /// `vision_msgs/msg/BoundingBox3D`: a box about its centre pose, `size` the full side
    /// lengths in metres.
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct BoundingBox3D = "vision_msgs/msg/BoundingBox3D" {
        pub center: Pose,
        pub size: Vector3,
    }
}

ros_message! {
    /// `vision_msgs/msg/Detection3D`: one detected object, its class hypotheses, its box and
    /// an id that stays the same across messages for the same object (may be empty).
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct Detection3D = "vision_msgs/msg/Detection3D" {
        pub header: Header,
        pub results: Vec<ObjectHypothesisWithPose>,
        pub bbox: BoundingBox3D,
        pub id: String,
    }
}

ros_message! {
    /// `vision_msgs/msg/Detection3DArray`: every detection of one input (or a map of them).
    #[derive(Debug, Default, Clone, PartialEq)]
    pub struct Detection3DArray = "vision_msgs/msg/Detection3DArray" {
        pub header: Header,
        pub detections: Vec<Detection3D>,
    }
}
