//! ROS 2 names on DDS, as the rmw layers map them (ROS 2 design article "Topic and Service
//! name mapping to DDS"): topic `/cmd_vel` is DDS topic `rt/cmd_vel`; type
//! `geometry_msgs/msg/Twist` is DDS type `geometry_msgs::msg::dds_::Twist_`.

/// The DDS topic of ROS 2 topic `ros` (absolute, `/a/b`).
pub fn dds_topic(ros: &str) -> String {
    format!("rt/{}", ros.trim_start_matches('/'))
}

/// The DDS type name of ROS 2 type `pkg/msg/Type` (shared with the Zenoh link, whose keys
/// carry it too).
pub use agrisim_link::dds_type;

/// Topic remapping, shared with the Zenoh link.
pub use agrisim_link::Remap;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_follow_the_rmw_mapping() {
        assert_eq!(dds_topic("/cmd_vel"), "rt/cmd_vel");
        assert_eq!(dds_topic("/camera/color/image_raw"), "rt/camera/color/image_raw");
        assert_eq!(dds_type("sensor_msgs/msg/PointCloud2").as_deref(), Some("sensor_msgs::msg::dds_::PointCloud2_"));
        assert_eq!(dds_type("Twist"), None);
    }
}
