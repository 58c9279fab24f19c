//! Publishes the robot's link frames from the URDF and the joint states, as ROS 2's
//! robot_state_publisher does: fixed joints once on `/tf_static`, movable joints on `/tf` at
//! every exchange (arms and fingers from `/{left,right}_arm/joint_states`, the lift from the
//! `/lift/position` signal; joints nobody reports, such as wheels, stay at 0). With the
//! odometry and localization transforms this gives the full map -> ... -> hand TCP tree, so
//! Foxglove shows the robot and any node can look a frame up.

use super::Node;
use agrisim_bus::Bus;
use agrisim_error::Result;
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::geometry_msgs::{Quaternion, Transform, TransformStamped, Vector3};
use agrisim_msgs::sensor_msgs::JointState;
use agrisim_msgs::std_msgs::Header;
use agrisim_msgs::tf2_msgs::TFMessage;
use agrisim_robot::{Joint, Pose, Robot};
use nalgebra::{Matrix3, Rotation3, UnitQuaternion};
use std::collections::BTreeMap;

pub const TF: &str = "/tf";
pub const TF_STATIC: &str = "/tf_static";
/// Topics with sensor_msgs/JointState read by the publisher.
pub const JOINT_STATES: [&str; 2] = ["/left_arm/joint_states", "/right_arm/joint_states"];
/// Scalar signal with the lift's position, and the URDF joint it drives.
pub const LIFT: (&str, &str) = ("/lift/position", "lift_joint");

pub struct RobotStatePublisher {
    joints: Vec<Joint>,
    positions: BTreeMap<String, f64>,
    seen: [u64; 2],
    static_sent: bool,
}

impl RobotStatePublisher {
    pub fn new(robot: &Robot) -> RobotStatePublisher {
        let joints = robot.joints().to_vec();
        let positions = robot.movable_joints().map(|j| (j.name.clone(), 0.0)).collect();
        RobotStatePublisher { joints, positions, seen: [0; 2], static_sent: false }
    }

    /// The robot of models/robot/agrisim_robot.urdf (compiled in).
    pub fn agrisim() -> RobotStatePublisher {
        let robot = Robot::from_urdf_str(include_str!("../../../models/robot/agrisim_robot.urdf"))
            .expect("the project's URDF loads (tested in agrisim-robot)");
        RobotStatePublisher::new(&robot)
    }

    fn transforms(&self, t_ns: i64, movable: bool) -> TFMessage {
        let transforms = self
            .joints
            .iter()
            .filter(|j| j.kind.is_movable() == movable)
            .map(|j| {
                stamped(t_ns, &j.parent, &j.child, &j.transform(self.positions.get(&j.name).copied().unwrap_or(0.0)))
            })
            .collect();
        TFMessage { transforms }
    }
}

fn stamped(t_ns: i64, parent: &str, child: &str, p: &Pose) -> TransformStamped {
    let m = Matrix3::from_fn(|i, k| p.rot[i][k]);
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(m));
    TransformStamped {
        header: Header { stamp: Time::from_nanos(t_ns), frame_id: parent.to_string() },
        child_frame_id: child.to_string(),
        transform: Transform {
            translation: Vector3 { x: p.trans[0], y: p.trans[1], z: p.trans[2] },
            rotation: Quaternion { x: q.i, y: q.j, z: q.k, w: q.w },
        },
    }
}

impl Node for RobotStatePublisher {
    fn name(&self) -> &str {
        "robot_state_publisher"
    }

    fn step(&mut self, t_ns: i64, bus: &mut Bus) -> Result<()> {
        for (topic, seen) in JOINT_STATES.iter().zip(self.seen.iter_mut()) {
            if let Some(js) = bus.take_new::<JointState>(topic, seen)? {
                for (name, q) in js.name.iter().zip(&js.position) {
                    if let Some(v) = self.positions.get_mut(name) {
                        *v = *q;
                    }
                }
            }
        }
        if let (Some(x), Some(v)) = (bus.scalar(LIFT.0), self.positions.get_mut(LIFT.1)) {
            *v = x;
        }
        if !self.static_sent {
            let msg = self.transforms(t_ns, false);
            bus.publish(TF_STATIC, t_ns, &msg);
            self.static_sent = true;
        }
        let msg = self.transforms(t_ns, true);
        bus.publish(TF, t_ns, &msg);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use agrisim_msgs::Message;

    /// Chaining the published transforms from base_link reproduces the URDF's forward
    /// kinematics of the hand TCP for the joint states given.
    #[test]
    fn published_tree_matches_forward_kinematics() {
        let robot = Robot::from_urdf_str(include_str!("../../../models/robot/agrisim_robot.urdf")).unwrap();
        let mut node = RobotStatePublisher::new(&robot);
        let mut bus = Bus::default();
        let q = [0.3, -0.5, 0.2, -2.0, 0.4, 1.8, -0.6];
        let names: Vec<String> = (1..=7)
            .map(|i| format!("left_joint{i}"))
            .chain(["left_finger_joint1".into(), "left_finger_joint2".into()])
            .collect();
        let mut pos = q.to_vec();
        pos.extend([0.02, 0.02]);
        bus.publish(
            JOINT_STATES[0],
            0,
            &JointState { name: names.clone(), position: pos.clone(), ..Default::default() },
        );
        bus.set_scalar(LIFT.0, 0.37);
        node.step(100_000_000, &mut bus).unwrap();
        let mut tf: BTreeMap<String, (String, Pose)> = BTreeMap::new();
        for topic in [TF, TF_STATIC] {
            let m = TFMessage::from_cdr(&bus.latest(topic).unwrap().cdr).unwrap();
            for t in m.transforms {
                let r = &t.transform.rotation;
                let uq = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(r.w, r.x, r.y, r.z));
                let m = uq.to_rotation_matrix();
                let rot = [0, 1, 2].map(|i| [0, 1, 2].map(|k| m[(i, k)]));
                let tr = &t.transform.translation;
                tf.insert(t.child_frame_id, (t.header.frame_id, Pose { rot, trans: [tr.x, tr.y, tr.z] }));
            }
        }
        let mut frame = "left_hand_tcp".to_string();
        let mut chained = Pose::IDENTITY;
        while frame != "base_link" {
            let (parent, p) = tf.get(&frame).unwrap_or_else(|| panic!("no transform to {frame}"));
            chained = p.mul(&chained);
            frame = parent.clone();
        }
        let mut qs: BTreeMap<String, f64> = names.into_iter().zip(pos).collect();
        qs.insert("lift_joint".into(), 0.37);
        let fk = robot.fk(&qs).unwrap()["left_hand_tcp"];
        assert!(chained.max_abs_diff(&fk) < 1e-9, "{chained:?} vs {fk:?}");
    }
}
