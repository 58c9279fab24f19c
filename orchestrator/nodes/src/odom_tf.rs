//! Broadcasts the odom -> base_link transform (REP 105) from the wheel odometry on /odom,
//! as a base controller's odometry publisher does on a real robot.

use super::Node;
use agrisim_bus::Bus;
use agrisim_error::Result;
use agrisim_msgs::geometry_msgs::{Transform, TransformStamped, Vector3};
use agrisim_msgs::nav_msgs::Odometry;
use agrisim_msgs::tf2_msgs::TFMessage;

pub const ODOM: &str = "/odom";
pub const TF: &str = "/tf";

#[derive(Default)]
pub struct OdomTf {
    seen: u64,
}

impl Node for OdomTf {
    fn name(&self) -> &str {
        "odom_tf"
    }

    fn step(&mut self, t_ns: i64, bus: &mut Bus) -> Result<()> {
        if let Some(odom) = bus.take_new::<Odometry>(ODOM, &mut self.seen)? {
            let p = &odom.pose.pose;
            let tf = TransformStamped {
                header: odom.header.clone(),
                child_frame_id: odom.child_frame_id.clone(),
                transform: Transform {
                    translation: Vector3 { x: p.position.x, y: p.position.y, z: p.position.z },
                    rotation: p.orientation,
                },
            };
            bus.publish(TF, t_ns, &TFMessage { transforms: vec![tf] });
        }
        Ok(())
    }
}
