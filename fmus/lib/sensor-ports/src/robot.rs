//! The robot's own body as the ray-casting sensors see it: every URDF link's collision
//! primitives (chassis, lift, arms, grippers, sensor post, harvest box), posed by the shared
//! forward kinematics of `agrisim_robot::model` from the same lift, arm-joint and finger-gap
//! inputs the world FMU takes; or, with `robot_links` off, the base box parameters alone (the
//! world's navigation envelope, 0.05-0.65 m high, taller than the 0.22-0.42 m chassis, so a
//! camera on the lift at lift 0 sits inside it: it stands for the robot, it is not a surface).
//! The wheel units are left out (under the chassis, out of both sensors' views; their steering
//! is not an input), and so is the sensor's own housing (its URDF link): the rays start in it.
//!
//! Ids follow the scene's (base first, then the links in URDF order), so labels and hits on the
//! robot never collide with scene objects; every part has kind `Robot`.

use agrisim_fmi::Var;
use agrisim_raycast::cast_scene::base_box;
use agrisim_robot::model::{chassis_link, RobotModel, OPEN_WIDTH, READY_POSE};
use agrisim_scene::{Kind, Object, Placement, Shape};

pub use agrisim_robot::model::Coords;
use agrisim_robot::{Pose as RPose, Shape as RShape};
use std::sync::{Arc, OnceLock};

/// Parameter: whether the rays see the URDF links besides the base box.
pub const ROBOT_LINKS: Var = Var::param("robot_links", agrisim_fmi::Start::Boolean(true))
    .desc("Rays hit the robot's URDF links (chassis, lift, arms, grippers, sensor post, harvest box) posed from lift_position and the arm inputs; false = the base box parameters only");

/// Input: the lift extension (URDF lift_joint).
pub const LIFT_POSITION: Var = Var::input("lift_position", 0.0)
    .unit("m")
    .desc("Lift extension (URDF lift_joint, clamped to its limits): raises the lift carriage and both arms (and the camera, which rides on the carriage: its mount_z is taken at lift 0)");

/// Inputs: `<side>_q1..7`, the arm joint angles (default: Franka's ready pose), left then right.
pub const ARM_JOINTS: [[Var; 7]; 2] = [
    [
        joint("left_q1", 0).desc("left_joint1 angle (default: Franka ready pose; clamped to the URDF limits)"),
        joint("left_q2", 1).desc("left_joint2 angle"),
        joint("left_q3", 2).desc("left_joint3 angle"),
        joint("left_q4", 3).desc("left_joint4 angle"),
        joint("left_q5", 4).desc("left_joint5 angle"),
        joint("left_q6", 5).desc("left_joint6 angle"),
        joint("left_q7", 6).desc("left_joint7 angle"),
    ],
    [
        joint("right_q1", 0).desc("right_joint1 angle (default: Franka ready pose; clamped to the URDF limits)"),
        joint("right_q2", 1).desc("right_joint2 angle"),
        joint("right_q3", 2).desc("right_joint3 angle"),
        joint("right_q4", 3).desc("right_joint4 angle"),
        joint("right_q5", 4).desc("right_joint5 angle"),
        joint("right_q6", 5).desc("right_joint6 angle"),
        joint("right_q7", 6).desc("right_joint7 angle"),
    ],
];

/// Inputs: the finger-pad gaps of the left and right grippers (default: fully open).
pub const FINGER_WIDTHS: [Var; 2] = [
    Var::input("left_finger_width", OPEN_WIDTH)
        .unit("m")
        .desc("Gap between the left gripper's finger pads (each finger joint = width / 2; clamped to 0..0.08)"),
    Var::input("right_finger_width", OPEN_WIDTH).unit("m").desc("Gap between the right gripper's finger pads"),
];

const fn joint(name: &'static str, i: usize) -> Var {
    Var::input(name, READY_POSE[i]).unit("rad")
}

/// The URDF model, parsed once per process (every sensor instance shares it).
pub fn model() -> Result<Arc<RobotModel>, String> {
    static MODEL: OnceLock<Result<Arc<RobotModel>, String>> = OnceLock::new();
    MODEL.get_or_init(|| RobotModel::load().map(Arc::new)).clone()
}

/// Builds the robot's parts for a configuration.
#[derive(Clone, Debug)]
pub struct RobotBody {
    model: Arc<RobotModel>,
    first_id: u32,
    dims: [f64; 4],
    /// Indices (in the model's link order) of the links the rays see.
    links: Vec<usize>,
}

impl RobotBody {
    /// The body with ids from `first_id` (the scene's object count), base box `dims`
    /// ([length, width, height, clearance]), leaving out `own_link` (the sensor's housing).
    pub fn new(first_id: u32, dims: [f64; 4], own_link: &str) -> Result<RobotBody, String> {
        let model = model()?;
        let links = (model.robot.links().iter().enumerate())
            .filter(|(_, l)| {
                !l.colliders.is_empty() && (l.name == "base_link" || !chassis_link(&l.name)) && l.name != own_link
            })
            .map(|(i, _)| i)
            .collect();
        Ok(RobotBody { model, first_id, dims, links })
    }

    /// The parts with base_link at (x, y, yaw) in the map frame: the URDF links at `coords`,
    /// or for None the base box (exactly [`base_box`]'s).
    pub fn objects(&self, coords: Option<&Coords>, x: f64, y: f64, yaw: f64) -> Vec<Object> {
        let Some(c) = coords else { return vec![base_box(self.first_id, self.dims, x, y, yaw)] };
        let mut out = Vec::new();
        let mut fk = Vec::new();
        self.model.fk(c, &mut fk);
        let base = RPose::from_xyz_rpy([x, y, 0.0], [0.0, 0.0, yaw]);
        for &i in &self.links {
            let link = &self.model.robot.links()[i];
            let at = base.mul(&fk[i]);
            for c in &link.colliders {
                let pose = at.mul(&c.origin);
                let mut push = |shape: Shape, p: &RPose| {
                    let id = self.first_id + out.len() as u32;
                    let placement = Placement { translation: p.trans, rotation: p.quaternion() };
                    out.push(Object { id, name: link.name.clone(), kind: Kind::Robot, shape, placement });
                };
                match c.shape {
                    RShape::Box { size } => push(Shape::Box { half: size.map(|v| 0.5 * v) }, &pose),
                    RShape::Cylinder { radius, length } => {
                        push(Shape::Cylinder { radius, half_height: 0.5 * length }, &pose)
                    }
                    RShape::Sphere { radius } => push(Shape::Sphere { radius }, &pose),
                    // A capsule is its cylinder and the two end spheres (an exact union).
                    RShape::Capsule { radius, length } => {
                        push(Shape::Cylinder { radius, half_height: 0.5 * length }, &pose);
                        for end in [-0.5 * length, 0.5 * length] {
                            push(Shape::Sphere { radius }, &pose.mul(&RPose::from_translation([0.0, 0.0, end])));
                        }
                    }
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parts_follow_the_joints_and_leave_out_the_own_link() {
        let body = RobotBody::new(100, [1.2, 0.9, 0.6, 0.05], "camera_link").unwrap();
        let ready = Coords::default();
        let parts = body.objects(Some(&ready), 1.0, 2.0, 0.5);
        assert!(parts.iter().enumerate().all(|(i, o)| o.id == 100 + i as u32 && o.kind == Kind::Robot));
        assert_eq!(parts[0].name, "base_link");
        assert!(parts.iter().any(|o| o.name == "left_link4") && parts.iter().any(|o| o.name == "right_hand"));
        assert!(!parts.iter().any(|o| o.name == "camera_link" || o.name.ends_with("_wheel_link")));
        assert!(parts.iter().any(|o| o.name == "lidar_link"));
        assert_eq!(body.objects(None, 1.0, 2.0, 0.5), [base_box(100, [1.2, 0.9, 0.6, 0.05], 1.0, 2.0, 0.5)]);
        // The hand goes up with the lift, the rest of the base does not move.
        let hand = |parts: &[Object]| parts.iter().find(|o| o.name == "left_hand").unwrap().placement.translation;
        let raised = body.objects(Some(&Coords { lift: 0.3, ..ready }), 1.0, 2.0, 0.5);
        let (a, b) = (hand(&parts), hand(&raised));
        assert!((b[2] - a[2] - 0.3).abs() < 1e-12 && (b[0] - a[0]).abs() < 1e-12, "{a:?} {b:?}");
        // Each part is where the model's FK puts its link (base at the origin, yaw 0).
        let model = model().unwrap();
        let mut fk = Vec::new();
        model.fk(&ready, &mut fk);
        let at_origin = body.objects(Some(&ready), 0.0, 0.0, 0.0);
        let i = model.link_index("left_link4").unwrap();
        let o = at_origin.iter().find(|o| o.name == "left_link4").unwrap();
        let want = fk[i].mul(&model.robot.colliders("left_link4").unwrap()[0].origin);
        assert!((0..3).all(|k| (o.placement.translation[k] - want.trans[k]).abs() < 1e-12));
    }

    #[test]
    fn the_quaternion_gives_back_the_rotation() {
        for rpy in [[0.0, 0.0, 0.0], [3.1, 0.2, -1.0], [0.0, std::f64::consts::PI, 0.0], [1.0, -1.4, 2.9]] {
            let p = RPose::from_xyz_rpy([0.0; 3], rpy);
            let [x, y, z, w] = p.quaternion();
            let back = RPose {
                rot: [
                    [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - z * w), 2.0 * (x * z + y * w)],
                    [2.0 * (x * y + z * w), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - x * w)],
                    [2.0 * (x * z - y * w), 2.0 * (y * z + x * w), 1.0 - 2.0 * (x * x + y * y)],
                ],
                trans: [0.0; 3],
            };
            assert!(p.max_abs_diff(&back) < 1e-12, "{rpy:?}");
        }
    }
}
