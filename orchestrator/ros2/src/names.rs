//! ROS 2 names on DDS, as the rmw layers map them (ROS 2 design article "Topic and Service
//! name mapping to DDS"): topic `/cmd_vel` is DDS topic `rt/cmd_vel`; type
//! `geometry_msgs/msg/Twist` is DDS type `geometry_msgs::msg::dds_::Twist_`.

use std::collections::BTreeMap;

/// The DDS topic of ROS 2 topic `ros` (absolute, `/a/b`).
pub fn dds_topic(ros: &str) -> String {
    format!("rt/{}", ros.trim_start_matches('/'))
}

/// The DDS type name of ROS 2 type `pkg/msg/Type`, or None for another form.
pub fn dds_type(ros_type: &str) -> Option<String> {
    match ros_type.split('/').collect::<Vec<_>>().as_slice() {
        [pkg, "msg", ty] if !pkg.is_empty() && !ty.is_empty() => Some(format!("{pkg}::msg::dds_::{ty}_")),
        _ => None,
    }
}

/// Topic remapping (`--ros2-remap /cmd_vel:=/robot/cmd_vel`): bus name -> ROS 2 name.
#[derive(Clone, Debug, Default)]
pub struct Remap(BTreeMap<String, String>);

impl Remap {
    /// Parses `FROM:=TO` rules; both must be absolute topic names.
    pub fn parse(rules: &[String]) -> Result<Remap, String> {
        let mut map = BTreeMap::new();
        for r in rules {
            let (from, to) = r.split_once(":=").ok_or_else(|| format!("remap rule '{r}': expected FROM:=TO"))?;
            for n in [from, to] {
                if !n.starts_with('/') || n.len() < 2 || n.contains(char::is_whitespace) {
                    return Err(format!("remap rule '{r}': '{n}' is not an absolute topic name"));
                }
            }
            map.insert(from.to_string(), to.to_string());
        }
        Ok(Remap(map))
    }

    /// The ROS 2 name of bus topic `topic`.
    pub fn apply<'a>(&'a self, topic: &'a str) -> &'a str {
        self.0.get(topic).map_or(topic, |s| s.as_str())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_follow_the_rmw_mapping() {
        assert_eq!(dds_topic("/cmd_vel"), "rt/cmd_vel");
        assert_eq!(dds_topic("/camera/color/image_raw"), "rt/camera/color/image_raw");
        assert_eq!(dds_type("sensor_msgs/msg/PointCloud2").as_deref(), Some("sensor_msgs::msg::dds_::PointCloud2_"));
        assert_eq!(dds_type("Twist"), None);
        let r = Remap::parse(&["/cmd_vel:=/robot/cmd_vel".into()]).unwrap();
        assert_eq!(r.apply("/cmd_vel"), "/robot/cmd_vel");
        assert_eq!(r.apply("/odom"), "/odom");
        assert!(Remap::parse(&["cmd_vel:=/x".into()]).is_err());
        assert!(Remap::parse(&["/a=/b".into()]).is_err());
    }
}
