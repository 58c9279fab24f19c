//! One arm as a kinematic chain in the planning frame `base_link`.
//!
//! The chain is read from the robot URDF (via agrisim-robot), so the planner and the simulated
//! robot cannot disagree. Its variables are `x = [lift, q1..q7]`: the lift is usually a fixed
//! input, but the IK may free it (an 8th joint) where that helps reach a fruit.

use crate::acm::{Acm, ACM_SAMPLES};
use crate::body::{body_parts, BodyPart};
use crate::iso::{to_iso, to_pose};
use crate::layout::{join, BODY_NAMES, DOF, HAND, NBODIES};
use crate::spheres::SphereModel;
use agrisim_robot::{Joint, JointKind, Limits, Pose, Robot};
use nalgebra::{Isometry3, Matrix6xX, Point3, Translation3, Unit, UnitQuaternion, Vector3};
use std::sync::OnceLock;

/// The robot description every planner object is built from (compiled in).
pub const URDF: &str = include_str!("../../../models/robot/agrisim_robot.urdf");

/// Which arm.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Side {
    Left,
    Right,
}

impl Side {
    /// URDF name prefix (`left_`, `right_`).
    pub fn prefix(self) -> &'static str {
        match self {
            Side::Left => "left_",
            Side::Right => "right_",
        }
    }
    pub fn other(self) -> Side {
        match self {
            Side::Left => Side::Right,
            Side::Right => Side::Left,
        }
    }
}

#[derive(Debug, Clone, Copy)]
enum Motion {
    Fixed,
    Revolute(Unit<Vector3<f64>>),
    Prismatic(Vector3<f64>),
}

/// One joint of the chain: `child = parent * origin * motion(x[var])`.
#[derive(Debug, Clone)]
struct Seg {
    origin: Isometry3<f64>,
    motion: Motion,
    /// Index into `x = [lift, q1..q7]`.
    var: Option<usize>,
}

/// Kinematics of one arm (lift + 7 joints + hand + fingers), built from the URDF.
#[derive(Debug, Clone)]
pub struct ArmModel {
    pub side: Side,
    segs: Vec<Seg>,
    /// Segment whose child frame is each body's frame (fingers: the hand's, see `finger`).
    body_seg: [usize; NBODIES],
    /// Finger joints relative to the hand: origin and sliding axis.
    finger: [(Isometry3<f64>, Vector3<f64>); 2],
    /// Arm joint limits (position, velocity, effort) from the URDF.
    pub limits: [Limits; DOF],
    /// Lift limits from the URDF.
    pub lift_limits: Limits,
    /// Finger joint limits (per finger, m).
    pub finger_limits: Limits,
    /// URDF joint names `{side}_joint1..7`.
    pub joint_names: [String; DOF],
    /// The collision primitives of each body, in the body frame (from the URDF).
    pub colliders: Vec<Vec<agrisim_robot::Collider>>,
    /// Sphere approximation of each body.
    pub spheres: SphereModel,
    /// The robot's fixed structure, obstacles of this arm.
    pub body: Vec<BodyPart>,
    /// Which body pairs are checked.
    pub acm: Acm,
}

/// Every frame of one configuration, in the planning frame.
#[derive(Debug, Clone)]
pub struct Frames {
    /// Pose of each body of [`BODY_NAMES`].
    pub bodies: [Isometry3<f64>; NBODIES],
    /// The tool centre point `{side}_hand_tcp`.
    pub tcp: Isometry3<f64>,
    /// World axis and origin of each variable `[lift, q1..q7]`.
    axes: [(Vector3<f64>, Point3<f64>); 8],
}

fn seg_of(j: &Joint, var: Option<usize>) -> Seg {
    let a = Vector3::from(j.axis);
    let motion = match j.kind {
        JointKind::Fixed => Motion::Fixed,
        JointKind::Revolute | JointKind::Continuous => Motion::Revolute(Unit::new_normalize(a)),
        JointKind::Prismatic => Motion::Prismatic(a),
    };
    Seg { origin: to_iso(&j.origin), motion, var }
}

impl Seg {
    fn apply(&self, parent: &Isometry3<f64>, x: f64) -> Isometry3<f64> {
        let base = parent * self.origin;
        match self.motion {
            Motion::Fixed => base,
            Motion::Revolute(ax) => base * UnitQuaternion::from_axis_angle(&ax, x),
            Motion::Prismatic(ax) => base * Translation3::from(ax * x),
        }
    }
}

impl ArmModel {
    /// The arm of `side` from the compiled-in URDF (built once per process and cloned:
    /// the allowed-collision matrix samples 20 000 configurations). Panics only if that URDF
    /// is broken, which the crate's tests rule out.
    pub fn new(side: Side) -> ArmModel {
        static CACHE: [OnceLock<ArmModel>; 2] = [OnceLock::new(), OnceLock::new()];
        CACHE[side as usize]
            .get_or_init(|| {
                let robot = Robot::from_urdf_str(URDF).expect("compiled-in URDF parses");
                ArmModel::from_robot(&robot, side).expect("compiled-in URDF has both arms")
            })
            .clone()
    }

    /// The arm of `side` from any robot with the agrisim naming (`{side}_joint1..7`,
    /// `{side}_hand_tcp`, `{side}_finger_joint1/2`, `lift_joint`).
    pub fn from_robot(robot: &Robot, side: Side) -> Result<ArmModel, String> {
        let p = side.prefix();
        let chain = robot.chain(&robot.root, &format!("{p}hand_tcp"))?;
        let mut segs = Vec::new();
        let mut nvar = 0;
        let mut limits = Vec::new();
        let mut lift_limits = None;
        let mut joint_names = Vec::new();
        let mut child_of_seg = Vec::new();
        for j in &chain {
            let var = if j.kind.is_movable() {
                if j.name == "lift_joint" {
                    lift_limits = j.limits;
                    Some(0)
                } else {
                    nvar += 1;
                    limits.push(j.limits.ok_or("arm joint without limits")?);
                    joint_names.push(j.name.clone());
                    Some(nvar)
                }
            } else {
                None
            };
            segs.push(seg_of(j, var));
            child_of_seg.push(j.child.clone());
        }
        if nvar != DOF || lift_limits.is_none() {
            return Err(format!("{p}arm: expected lift + {DOF} joints, found {nvar} arm joints"));
        }
        let mut body_seg = [0; NBODIES];
        for (b, name) in BODY_NAMES.iter().enumerate() {
            let want = if b > HAND { format!("{p}hand") } else { format!("{p}{name}") };
            body_seg[b] =
                child_of_seg.iter().position(|c| *c == want).ok_or_else(|| format!("chain has no link {want}"))?;
        }
        let mut finger = [(Isometry3::identity(), Vector3::zeros()); 2];
        let mut finger_limits = None;
        for (k, f) in finger.iter_mut().enumerate() {
            let j = robot.joint(&format!("{p}finger_joint{}", k + 1)).ok_or("no finger joint")?;
            *f = (to_iso(&j.origin), Vector3::from(j.axis));
            finger_limits = j.limits;
        }
        let colliders: Vec<_> =
            BODY_NAMES.iter().map(|n| robot.colliders(&format!("{p}{n}")).unwrap_or(&[]).to_vec()).collect();
        let spheres = SphereModel::new(&colliders);
        let mut arm = ArmModel {
            side,
            segs,
            body_seg,
            finger,
            limits: limits.try_into().unwrap(),
            lift_limits: lift_limits.unwrap(),
            finger_limits: finger_limits.ok_or("finger joint without limits")?,
            joint_names: joint_names.try_into().unwrap(),
            colliders,
            spheres,
            body: body_parts(robot)?,
            acm: Acm::default(),
        };
        arm.acm = Acm::sample(&arm.body, ACM_SAMPLES, arm.spheres.offsets, |rng, buf| {
            let q = arm.random_q(rng);
            let lift = arm.lift_limits.lower + (arm.lift_limits.upper - arm.lift_limits.lower) * rng.uniform();
            let finger = arm.finger_limits.upper * rng.uniform();
            let _ = world_spheres(&arm, lift, &q, finger, buf);
            lift
        });
        Ok(arm)
    }

    pub fn lower(&self) -> [f64; DOF] {
        self.limits.map(|l| l.lower)
    }
    pub fn upper(&self) -> [f64; DOF] {
        self.limits.map(|l| l.upper)
    }

    /// Whether every joint is within its limits.
    pub fn within_limits(&self, q: &[f64; DOF]) -> bool {
        q.iter().zip(&self.limits).all(|(v, l)| l.contains(*v))
    }

    /// Uniform random configuration within the joint limits.
    pub fn random_q(&self, rng: &mut agrisim_math::Rng) -> [f64; DOF] {
        self.limits.map(|l| l.lower + (l.upper - l.lower) * rng.uniform())
    }

    /// TCP pose in the planning frame (`base_link`).
    pub fn fk(&self, lift: f64, q: &[f64; DOF]) -> Pose {
        to_pose(&self.fk_iso(lift, q))
    }

    /// TCP pose in the planning frame as an isometry.
    pub fn fk_iso(&self, lift: f64, q: &[f64; DOF]) -> Isometry3<f64> {
        self.fk_x(&join(lift, q))
    }

    pub(crate) fn fk_x(&self, x: &[f64; 8]) -> Isometry3<f64> {
        let mut f = Isometry3::identity();
        for s in &self.segs {
            f = s.apply(&f, s.var.map_or(0.0, |v| x[v]));
        }
        f
    }

    /// Every body frame, the TCP and the joint axes; `finger` is each finger's opening (m).
    pub fn frames(&self, lift: f64, q: &[f64; DOF], finger: f64) -> Frames {
        self.frames_x(&join(lift, q), finger)
    }

    pub(crate) fn frames_x(&self, x: &[f64; 8], finger: f64) -> Frames {
        let mut seg_frames = [Isometry3::identity(); 16];
        let mut axes = [(Vector3::zeros(), Point3::origin()); 8];
        let mut f = Isometry3::identity();
        for (i, s) in self.segs.iter().enumerate() {
            f = s.apply(&f, s.var.map_or(0.0, |v| x[v]));
            seg_frames[i] = f;
            if let Some(v) = s.var {
                let a = match s.motion {
                    Motion::Revolute(a) => a.into_inner(),
                    Motion::Prismatic(a) => a,
                    Motion::Fixed => Vector3::zeros(),
                };
                axes[v] = (f.rotation * a, Point3::from(f.translation.vector));
            }
        }
        let mut bodies = [Isometry3::identity(); NBODIES];
        for b in 0..NBODIES {
            bodies[b] = seg_frames[self.body_seg[b]];
        }
        for k in 0..2 {
            let (o, a) = self.finger[k];
            bodies[HAND + 1 + k] = bodies[HAND] * o * Translation3::from(a * finger);
        }
        Frames { bodies, tcp: f, axes }
    }

    /// Geometric Jacobian (6 x 7: linear velocity over angular velocity of the TCP, planning
    /// frame) of the arm joints.
    pub fn jacobian(&self, lift: f64, q: &[f64; DOF]) -> Matrix6xX<f64> {
        let j = self.jacobian_x(&join(lift, q));
        j.columns(1, DOF).into_owned()
    }

    /// 6 x 8 Jacobian with the lift as column 0.
    pub(crate) fn jacobian_x(&self, x: &[f64; 8]) -> Matrix6xX<f64> {
        let fr = self.frames_x(x, 0.0);
        fr.jacobian()
    }
}

impl Frames {
    /// 6 x 8 geometric Jacobian at the TCP, lift first.
    pub fn jacobian(&self) -> Matrix6xX<f64> {
        let mut j = Matrix6xX::zeros(8);
        let p = self.tcp.translation.vector;
        for (v, (a, o)) in self.axes.iter().enumerate() {
            if v == 0 {
                j.fixed_view_mut::<3, 1>(0, v).copy_from(a);
            } else {
                j.fixed_view_mut::<3, 1>(0, v).copy_from(&a.cross(&(p - o.coords)));
                j.fixed_view_mut::<3, 1>(3, v).copy_from(a);
            }
        }
        j
    }
}

/// World positions of an arm's spheres: (centre, radius, body).
pub(crate) fn world_spheres(
    arm: &ArmModel,
    lift: f64,
    q: &[f64; DOF],
    finger: f64,
    out: &mut Vec<(Point3<f64>, f64)>,
) -> ([(Point3<f64>, f64); NBODIES], Isometry3<f64>) {
    let fr = arm.frames_x(&join(lift, q), finger);
    out.clear();
    for b in 0..NBODIES {
        for s in arm.spheres.of(b) {
            out.push((fr.bodies[b] * s.center, s.radius));
        }
    }
    let bounds = std::array::from_fn(|b| (fr.bodies[b] * arm.spheres.bounds[b].center, arm.spheres.bounds[b].radius));
    (bounds, fr.tcp)
}
