//! Publishes the robot's link frames from the URDF and the joint states, as ROS 2's
//! robot_state_publisher does: fixed joints once on `/tf_static`, movable joints on `/tf` at
//! every exchange (arms and fingers from `/{left,right}_arm/joint_states`, the lift from the
//! `/lift/position` signal; joints nobody reports, such as wheels, stay at 0). With the
//! odometry and localization transforms this gives the full map -> ... -> hand TCP tree, so
//! Foxglove shows the robot and any node can look a frame up.
//!
//! Like ROS 2's robot_state_publisher it also publishes the URDF on `/robot_description`
//! (std_msgs/String, once: a latched topic) and, as joint_state_publisher would, every movable
//! joint's position on `/joint_states` at every exchange: with these RViz's and Foxglove's
//! robot model displays draw the robot, live and from the MCAP. The URDF has collision and
//! visual primitives only (no meshes, no `package://` paths), so a viewer needs no files.

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
/// The URDF (std_msgs/String), published once (transient local on the bridges).
pub const ROBOT_DESCRIPTION: &str = "/robot_description";
/// Every movable joint's position (sensor_msgs/JointState), at every exchange.
pub const ALL_JOINT_STATES: &str = "/joint_states";
/// The project's robot model, compiled in.
pub const AGRISIM_URDF: &str = include_str!("../../../models/robot/agrisim_robot.urdf");

pub struct RobotStatePublisher {
    joints: Vec<Joint>,
    positions: BTreeMap<String, f64>,
    seen: [u64; 2],
    static_sent: bool,
    /// The URDF text for /robot_description (None: not published).
    description: Option<String>,
}

impl RobotStatePublisher {
    pub fn new(robot: &Robot) -> RobotStatePublisher {
        let joints = robot.joints().to_vec();
        let positions = robot.movable_joints().map(|j| (j.name.clone(), 0.0)).collect();
        RobotStatePublisher { joints, positions, seen: [0; 2], static_sent: false, description: None }
    }

    /// Also publishes `urdf` (the text `robot` was read from) on /robot_description.
    pub fn with_description(mut self, urdf: impl Into<String>) -> RobotStatePublisher {
        self.description = Some(urdf.into());
        self
    }

    /// The robot of models/robot/agrisim_robot.urdf (compiled in), with its description.
    pub fn agrisim() -> RobotStatePublisher {
        let robot = Robot::from_urdf_str(AGRISIM_URDF).expect("the project's URDF loads (tested in agrisim-robot)");
        RobotStatePublisher::new(&robot).with_description(AGRISIM_URDF)
    }

    /// Every movable joint (in the robot model's joint order) with its current position.
    fn joint_states(&self, t_ns: i64) -> JointState {
        let movable = self.joints.iter().filter(|j| j.kind.is_movable());
        let (name, position) =
            movable.map(|j| (j.name.clone(), self.positions.get(&j.name).copied().unwrap_or(0.0))).unzip();
        JointState {
            header: Header { stamp: Time::from_nanos(t_ns), frame_id: String::new() },
            name,
            position,
            ..Default::default()
        }
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
            if let Some(urdf) = &self.description {
                bus.publish(ROBOT_DESCRIPTION, t_ns, &agrisim_msgs::std_msgs::String { data: urdf.clone() });
            }
            let msg = self.transforms(t_ns, false);
            bus.publish(TF_STATIC, t_ns, &msg);
            self.static_sent = true;
        }
        let msg = self.transforms(t_ns, true);
        bus.publish(TF, t_ns, &msg);
        if self.description.is_some() {
            bus.publish(ALL_JOINT_STATES, t_ns, &self.joint_states(t_ns));
        }
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
        let robot = Robot::from_urdf_str(AGRISIM_URDF).unwrap();
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

    /// /robot_description carries the URDF once; /joint_states names every movable joint of
    /// the URDF (wheels, steering, lift, both arms and fingers) with the positions reported;
    /// every link of the URDF is reached from base_link by /tf and /tf_static.
    #[test]
    fn description_joint_states_and_a_tree_over_every_link() {
        let robot = Robot::from_urdf_str(AGRISIM_URDF).unwrap();
        let mut node = RobotStatePublisher::agrisim();
        let mut bus = Bus::default();
        bus.publish(
            JOINT_STATES[1],
            0,
            &JointState { name: vec!["right_joint3".into()], position: vec![0.7], ..Default::default() },
        );
        bus.set_scalar(LIFT.0, 0.25);
        node.step(0, &mut bus).unwrap();
        node.step(100_000_000, &mut bus).unwrap();
        let mut seen = 0;
        let urdf = bus.take_new::<agrisim_msgs::std_msgs::String>(ROBOT_DESCRIPTION, &mut seen).unwrap().unwrap();
        assert_eq!(urdf.data, AGRISIM_URDF);
        assert!(bus.take_new::<agrisim_msgs::std_msgs::String>(ROBOT_DESCRIPTION, &mut seen).unwrap().is_none());
        let js = JointState::from_cdr(&bus.latest(ALL_JOINT_STATES).unwrap().cdr).unwrap();
        let movable: Vec<&str> = robot.movable_joints().map(|j| j.name.as_str()).collect();
        assert_eq!(js.name, movable);
        for needed in
            ["front_left_steer_joint", "rear_right_drive_joint", "lift_joint", "left_joint7", "right_finger_joint2"]
        {
            assert!(js.name.iter().any(|n| n == needed), "{needed} missing from /joint_states");
        }
        let at = |n: &str| js.position[js.name.iter().position(|m| m == n).unwrap()];
        assert_eq!((at("right_joint3"), at("lift_joint"), at("left_joint1")), (0.7, 0.25, 0.0));
        assert_eq!(js.header.stamp, Time::from_nanos(100_000_000));
        let mut parent: BTreeMap<String, String> = BTreeMap::new();
        for topic in [TF, TF_STATIC] {
            for t in TFMessage::from_cdr(&bus.latest(topic).unwrap().cdr).unwrap().transforms {
                parent.insert(t.child_frame_id, t.header.frame_id);
            }
        }
        for j in robot.joints() {
            let mut frame = j.child.clone();
            let mut hops = 0;
            while frame != "base_link" {
                frame = parent.get(&frame).unwrap_or_else(|| panic!("no transform to {frame}")).clone();
                hops += 1;
                assert!(hops < 100, "a cycle in the tree at {frame}");
            }
        }
    }
}
