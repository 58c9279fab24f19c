//! Decoding check by type name: lets the orchestrator verify a message crossing a connection
//! against the ROS 2 type its port declares, without knowing the type at compile time.

use crate::cdr::CdrError;
use crate::message::Message;
use crate::{
    agrisim, builtin_interfaces, control_msgs, geometry_msgs, nav_msgs, rosgraph_msgs, sensor_msgs, shape_msgs,
    std_msgs, tf2_msgs, trajectory_msgs, vision_msgs, visualization_msgs,
};

/// `Some(Ok(()))` when `bytes` decode as `type_name` (`pkg/msg/Type`), `Some(Err)` when they
/// do not, `None` when the type is not one this crate defines.
pub fn check_cdr(type_name: &str, bytes: &[u8]) -> Option<Result<(), CdrError>> {
    fn ok<M: Message>(b: &[u8]) -> Option<Result<(), CdrError>> {
        Some(M::check_cdr(b))
    }
    match type_name {
        "agrisim_msgs/msg/Signals" => ok::<agrisim::Signals>(bytes),
        "agrisim_msgs/msg/FmuStatus" => ok::<agrisim::FmuStatus>(bytes),
        "builtin_interfaces/msg/Time" => ok::<builtin_interfaces::Time>(bytes),
        "geometry_msgs/msg/Vector3" => ok::<geometry_msgs::Vector3>(bytes),
        "geometry_msgs/msg/Point" => ok::<geometry_msgs::Point>(bytes),
        "geometry_msgs/msg/Quaternion" => ok::<geometry_msgs::Quaternion>(bytes),
        "geometry_msgs/msg/Pose" => ok::<geometry_msgs::Pose>(bytes),
        "geometry_msgs/msg/PoseStamped" => ok::<geometry_msgs::PoseStamped>(bytes),
        "geometry_msgs/msg/PoseWithCovariance" => ok::<geometry_msgs::PoseWithCovariance>(bytes),
        "geometry_msgs/msg/Twist" => ok::<geometry_msgs::Twist>(bytes),
        "geometry_msgs/msg/TwistStamped" => ok::<geometry_msgs::TwistStamped>(bytes),
        "geometry_msgs/msg/TwistWithCovariance" => ok::<geometry_msgs::TwistWithCovariance>(bytes),
        "geometry_msgs/msg/Transform" => ok::<geometry_msgs::Transform>(bytes),
        "geometry_msgs/msg/TransformStamped" => ok::<geometry_msgs::TransformStamped>(bytes),
        "nav_msgs/msg/Odometry" => ok::<nav_msgs::Odometry>(bytes),
        "nav_msgs/msg/Path" => ok::<nav_msgs::Path>(bytes),
        "rosgraph_msgs/msg/Clock" => ok::<rosgraph_msgs::Clock>(bytes),
        "sensor_msgs/msg/JointState" => ok::<sensor_msgs::JointState>(bytes),
        "std_msgs/msg/Header" => ok::<std_msgs::Header>(bytes),
        "std_msgs/msg/Float64" => ok::<std_msgs::Float64>(bytes),
        "tf2_msgs/msg/TFMessage" => ok::<tf2_msgs::TFMessage>(bytes),
        "sensor_msgs/msg/PointField" => ok::<sensor_msgs::PointField>(bytes),
        "sensor_msgs/msg/PointCloud2" => ok::<sensor_msgs::PointCloud2>(bytes),
        "sensor_msgs/msg/Imu" => ok::<sensor_msgs::Imu>(bytes),
        "geometry_msgs/msg/PoseArray" => ok::<geometry_msgs::PoseArray>(bytes),
        "nav_msgs/msg/MapMetaData" => ok::<nav_msgs::MapMetaData>(bytes),
        "nav_msgs/msg/OccupancyGrid" => ok::<nav_msgs::OccupancyGrid>(bytes),
        "agrisim_msgs/msg/Contact" => ok::<agrisim::Contact>(bytes),
        "agrisim_msgs/msg/CollisionState" => ok::<agrisim::CollisionState>(bytes),
        "agrisim_msgs/msg/NavigationStatus" => ok::<agrisim::NavigationStatus>(bytes),
        "sensor_msgs/msg/Image" => ok::<sensor_msgs::Image>(bytes),
        "sensor_msgs/msg/RegionOfInterest" => ok::<sensor_msgs::RegionOfInterest>(bytes),
        "sensor_msgs/msg/CameraInfo" => ok::<sensor_msgs::CameraInfo>(bytes),
        "builtin_interfaces/msg/Duration" => ok::<builtin_interfaces::Duration>(bytes),
        "trajectory_msgs/msg/JointTrajectoryPoint" => ok::<trajectory_msgs::JointTrajectoryPoint>(bytes),
        "trajectory_msgs/msg/JointTrajectory" => ok::<trajectory_msgs::JointTrajectory>(bytes),
        "control_msgs/msg/GripperCommand" => ok::<control_msgs::GripperCommand>(bytes),
        "geometry_msgs/msg/Point32" => ok::<geometry_msgs::Point32>(bytes),
        "geometry_msgs/msg/Polygon" => ok::<geometry_msgs::Polygon>(bytes),
        "shape_msgs/msg/SolidPrimitive" => ok::<shape_msgs::SolidPrimitive>(bytes),
        "agrisim_msgs/msg/GripperState" => ok::<agrisim::GripperState>(bytes),
        "agrisim_msgs/msg/TrajectoryStatus" => ok::<agrisim::TrajectoryStatus>(bytes),
        "agrisim_msgs/msg/CollisionObject" => ok::<agrisim::CollisionObject>(bytes),
        "agrisim_msgs/msg/PlanningScene" => ok::<agrisim::PlanningScene>(bytes),
        "agrisim_msgs/msg/HarvestStatus" => ok::<agrisim::HarvestStatus>(bytes),
        "agrisim_msgs/msg/PlanResult" => ok::<agrisim::PlanResult>(bytes),
        "agrisim_msgs/msg/PlantDamage" => ok::<agrisim::PlantDamage>(bytes),
        "agrisim_msgs/msg/MovedObjects" => ok::<agrisim::MovedObjects>(bytes),
        "vision_msgs/msg/ObjectHypothesis" => ok::<vision_msgs::ObjectHypothesis>(bytes),
        "vision_msgs/msg/ObjectHypothesisWithPose" => ok::<vision_msgs::ObjectHypothesisWithPose>(bytes),
        "vision_msgs/msg/BoundingBox3D" => ok::<vision_msgs::BoundingBox3D>(bytes),
        "vision_msgs/msg/Detection3D" => ok::<vision_msgs::Detection3D>(bytes),
        "vision_msgs/msg/Detection3DArray" => ok::<vision_msgs::Detection3DArray>(bytes),
        "std_msgs/msg/String" => ok::<std_msgs::String>(bytes),
        "std_msgs/msg/ColorRGBA" => ok::<std_msgs::ColorRGBA>(bytes),
        "sensor_msgs/msg/CompressedImage" => ok::<sensor_msgs::CompressedImage>(bytes),
        "visualization_msgs/msg/UVCoordinate" => ok::<visualization_msgs::UVCoordinate>(bytes),
        "visualization_msgs/msg/MeshFile" => ok::<visualization_msgs::MeshFile>(bytes),
        "visualization_msgs/msg/Marker" => ok::<visualization_msgs::Marker>(bytes),
        "visualization_msgs/msg/MarkerArray" => ok::<visualization_msgs::MarkerArray>(bytes),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_known_type_is_checkable_and_garbage_fails() {
        for name in crate::all_type_names() {
            let full = if name.contains("/msg/") { name.to_string() } else { name.replacen('/', "/msg/", 1) };
            assert!(check_cdr(&full, &[0, 1, 0, 0]).is_some(), "{full} missing from check_cdr");
        }
        assert!(check_cdr("geometry_msgs/msg/Twist", &[1, 2, 3]).unwrap().is_err());
        assert!(check_cdr("geometry_msgs/msg/Twist", &geometry_msgs::Twist::default().to_cdr()).unwrap().is_ok());
        assert!(check_cdr("nope/msg/Nope", &[]).is_none());
    }
}
