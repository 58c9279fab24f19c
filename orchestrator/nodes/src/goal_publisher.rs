//! Sends one navigation goal (geometry_msgs/PoseStamped on /goal_pose, frame map) at a
//! given time, as RViz's "2D Goal Pose" tool or a mission planner would.

use super::Node;
use agrisim_bus::Bus;
use agrisim_error::Result;
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::geometry_msgs::{Point, Pose, PoseStamped, Quaternion};
use agrisim_msgs::std_msgs::Header;

pub const GOAL: &str = "/goal_pose";

pub struct GoalPublisher {
    goal: Option<(i64, [f64; 3])>,
}

impl GoalPublisher {
    /// Goal (x, y, yaw) in the map frame, sent at `t_ns`.
    pub fn new(t_ns: i64, goal: [f64; 3]) -> GoalPublisher {
        GoalPublisher { goal: Some((t_ns, goal)) }
    }
}

impl Node for GoalPublisher {
    fn name(&self) -> &str {
        "goal_publisher"
    }

    fn step(&mut self, t_ns: i64, bus: &mut Bus) -> Result<()> {
        if let Some((t, [x, y, yaw])) = self.goal {
            if t_ns >= t {
                let (s, c) = (yaw / 2.0).sin_cos();
                let msg = PoseStamped {
                    header: Header { stamp: Time::from_nanos(t_ns), frame_id: "map".into() },
                    pose: Pose {
                        position: Point { x, y, z: 0.0 },
                        orientation: Quaternion { x: 0.0, y: 0.0, z: s, w: c },
                    },
                };
                bus.publish(GOAL, t_ns, &msg);
                self.goal = None;
            }
        }
        Ok(())
    }
}
