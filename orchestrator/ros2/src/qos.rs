//! The QoS a ROS 2 user expects of each topic (rclcpp's profiles): sensor streams best
//! effort (as camera and LiDAR drivers publish them; a reliable subscriber will not match,
//! use SensorDataQoS), latched topics (`/tf_static`, `/map`) reliable and transient local,
//! everything else reliable, volatile, keep last 10 (the ROS 2 default). Subscriptions to
//! commands are reliable.

use rustdds::policy::{Durability, History, Reliability};
use rustdds::{Duration, QosPolicies, QosPolicyBuilder};

/// Topic kinds, shared with the Zenoh link.
pub use agrisim_link::{kind_of, Kind};

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
        assert!(!writer(Kind::Sensor).is_reliable());
        assert!(writer(Kind::Latched).is_reliable() && !writer(Kind::Latched).is_volatile());
        assert!(reader().is_reliable());
    }
}
