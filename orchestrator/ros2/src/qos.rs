//! The QoS a ROS 2 user expects of each topic (rclcpp's profiles): sensor streams best
//! effort (as camera and LiDAR drivers publish them; a reliable subscriber will not match,
//! use SensorDataQoS), latched topics (`/tf_static`, `/map`) reliable and transient local,
//! everything else reliable, volatile, keep last 10 (the ROS 2 default). Subscriptions to
//! commands are reliable.

use rustdds::policy::{Durability, History, Reliability};
use rustdds::{Duration, QosPolicies, QosPolicyBuilder};

/// What kind of stream a topic is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Best effort, keep last 5 (rclcpp SensorDataQoS).
    Sensor,
    /// Reliable, transient local, keep last 1: late joiners get the last message.
    Latched,
    /// Reliable, volatile, keep last 10 (rclcpp's default).
    Default,
}

/// The kind of `topic` carrying `ros_type`.
pub fn kind_of(topic: &str, ros_type: &str) -> Kind {
    if agrisim_bus::is_latched(topic) {
        return Kind::Latched;
    }
    match ros_type {
        "sensor_msgs/msg/Image"
        | "sensor_msgs/msg/PointCloud2"
        | "sensor_msgs/msg/Imu"
        | "sensor_msgs/msg/LaserScan" => Kind::Sensor,
        _ => Kind::Default,
    }
}

fn reliable() -> Reliability {
    Reliability::Reliable { max_blocking_time: Duration::from_millis(100) }
}

/// The writer QoS of a topic of kind `kind`.
pub fn writer(kind: Kind) -> QosPolicies {
    let b = QosPolicyBuilder::new();
    match kind {
        Kind::Sensor => b
            .reliability(Reliability::BestEffort)
            .durability(Durability::Volatile)
            .history(History::KeepLast { depth: 5 }),
        Kind::Latched => {
            b.reliability(reliable()).durability(Durability::TransientLocal).history(History::KeepLast { depth: 1 })
        }
        Kind::Default => {
            b.reliability(reliable()).durability(Durability::Volatile).history(History::KeepLast { depth: 10 })
        }
    }
    .build()
}

/// The reader QoS of a command topic: reliable, volatile, keep all (each command counts).
pub fn reader() -> QosPolicies {
    QosPolicyBuilder::new().reliability(reliable()).durability(Durability::Volatile).history(History::KeepAll).build()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kinds() {
        assert_eq!(kind_of("/points", "sensor_msgs/msg/PointCloud2"), Kind::Sensor);
        assert_eq!(kind_of("/camera/color/image_raw", "sensor_msgs/msg/Image"), Kind::Sensor);
        assert_eq!(kind_of("/tf_static", "tf2_msgs/msg/TFMessage"), Kind::Latched);
        assert_eq!(kind_of("/tf", "tf2_msgs/msg/TFMessage"), Kind::Default);
        assert_eq!(kind_of("/cmd_vel", "geometry_msgs/msg/Twist"), Kind::Default);
        assert!(!writer(Kind::Sensor).is_reliable());
        assert!(writer(Kind::Latched).is_reliable() && !writer(Kind::Latched).is_volatile());
        assert!(reader().is_reliable());
    }
}
