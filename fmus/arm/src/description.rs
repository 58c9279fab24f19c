//! What the arm FMU takes from the robot URDF (models/robot/agrisim_robot.urdf, compiled in):
//! one side's 7 joint names and limits, the finger joints' limits, and the rigid bodies the
//! joints move with their inertials (for [`crate::inertia`]). The URDF is the single source,
//! so the FMU, the world FMU and the planner agree on names and limits.

use agrisim_math::vec3::{mat_mul, transpose};
use agrisim_robot::{Joint, JointKind, Limits, Pose, Robot};

/// The robot description, compiled into the FMU (no file lookup at run time).
pub const URDF: &str = include_str!("../../../models/robot/agrisim_robot.urdf");

/// Number of arm joints.
pub const N: usize = 7;

/// A rigid body moved by the arm: its mass, centre of mass and inertia in its link frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    pub link: String,
    pub mass: f64,
    pub com: [f64; 3],
    /// Inertia about the centre of mass, in the link frame (rotated from the inertial frame).
    pub inertia: [[f64; 3]; 3],
}

/// One arm side as the FMU needs it.
#[derive(Clone, Debug)]
pub struct ArmDescription {
    pub side: String,
    /// `{side}_joint1..7`.
    pub joint_names: [String; N],
    pub limits: [Limits; N],
    /// `{side}_finger_joint1`, `{side}_finger_joint2`.
    pub finger_names: [String; 2],
    /// Limits of one finger joint (the gap is twice the finger travel).
    pub finger_limits: Limits,
    /// Joints from `{side}_link0` to `{side}_hand` (the 7 revolute joints plus fixed ones).
    pub chain: Vec<Joint>,
    /// The finger joints (parent `{side}_hand`).
    pub finger_joints: [Joint; 2],
    /// Bodies after chain joint `k` (index into `chain`), hand included.
    pub chain_bodies: Vec<(usize, Body)>,
    /// Finger bodies, one per finger joint.
    pub finger_bodies: [Body; 2],
}

fn limits_of(j: &Joint) -> Result<Limits, String> {
    let l = j.limits.ok_or_else(|| format!("joint {} has no limits in the URDF", j.name))?;
    if !(l.lower.is_finite() && l.upper.is_finite() && l.lower < l.upper && l.velocity > 0.0 && l.effort > 0.0) {
        return Err(format!("joint {}: unusable limits {l:?}", j.name));
    }
    Ok(l)
}

/// `R I R^T`: an inertia tensor expressed in a rotated frame.
pub fn rotate_inertia(r: &[[f64; 3]; 3], i: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    mat_mul(&mat_mul(r, i), &transpose(r))
}

fn body_of(urdf: &urdf_rs::Robot, link: &str) -> Result<Option<Body>, String> {
    let l = urdf.links.iter().find(|l| l.name == link).ok_or_else(|| format!("URDF has no link {link}"))?;
    let inr = &l.inertial;
    if inr.mass.value <= 0.0 {
        return Ok(None);
    }
    let o = Pose::from_xyz_rpy(inr.origin.xyz.0, inr.origin.rpy.0);
    let t = &inr.inertia;
    let local = [[t.ixx, t.ixy, t.ixz], [t.ixy, t.iyy, t.iyz], [t.ixz, t.iyz, t.izz]];
    Ok(Some(Body {
        link: link.to_string(),
        mass: inr.mass.value,
        com: o.trans,
        inertia: rotate_inertia(&o.rot, &local),
    }))
}

impl ArmDescription {
    /// The `side` ("left" or "right") arm of the compiled-in URDF.
    pub fn load(side: &str) -> Result<ArmDescription, String> {
        Self::from_urdf_str(URDF, side)
    }

    pub fn from_urdf_str(text: &str, side: &str) -> Result<ArmDescription, String> {
        if side != "left" && side != "right" {
            return Err(format!("parameter side must be \"left\" or \"right\", got {side:?}"));
        }
        let robot = Robot::from_urdf_str(text)?;
        let urdf = urdf_rs::read_from_string(text).map_err(|e| format!("URDF parse error: {e}"))?;
        let chain = robot.chain(&format!("{side}_link0"), &format!("{side}_hand"))?;
        let revolute: Vec<&Joint> = chain.iter().filter(|j| j.kind.is_movable()).collect();
        if revolute.len() != N || revolute.iter().any(|j| j.kind != JointKind::Revolute) {
            return Err(format!("{side} arm: expected {N} revolute joints from {side}_link0 to {side}_hand"));
        }
        let mut limits =
            [revolute[0].limits.unwrap_or(Limits { lower: 0.0, upper: 0.0, velocity: 0.0, effort: 0.0 }); N];
        let joint_names: [String; N] = std::array::from_fn(|i| revolute[i].name.clone());
        for (i, j) in revolute.iter().enumerate() {
            if j.name != format!("{side}_joint{}", i + 1) {
                return Err(format!("{side} arm: joint {} is named {}, expected {side}_joint{}", i + 1, j.name, i + 1));
            }
            limits[i] = limits_of(j)?;
        }
        let finger_names = [format!("{side}_finger_joint1"), format!("{side}_finger_joint2")];
        let fj = |n: &str| robot.joint(n).cloned().ok_or_else(|| format!("URDF has no joint {n}"));
        let finger_joints = [fj(&finger_names[0])?, fj(&finger_names[1])?];
        let finger_limits = limits_of(&finger_joints[0])?;
        if limits_of(&finger_joints[1])? != finger_limits
            || finger_joints.iter().any(|j| j.kind != JointKind::Prismatic)
        {
            return Err(format!("{side} gripper: finger joints must be prismatic with equal limits"));
        }
        let mut chain_bodies = Vec::new();
        for (k, j) in chain.iter().enumerate() {
            if let Some(b) = body_of(&urdf, &j.child)? {
                chain_bodies.push((k, b));
            }
        }
        let fb = |j: &Joint| body_of(&urdf, &j.child)?.ok_or_else(|| format!("finger link {} has no mass", j.child));
        let finger_bodies = [fb(&finger_joints[0])?, fb(&finger_joints[1])?];
        Ok(ArmDescription {
            side: side.to_string(),
            joint_names,
            limits,
            finger_names,
            finger_limits,
            chain,
            finger_joints,
            chain_bodies,
            finger_bodies,
        })
    }

    /// Largest finger gap (two fingers at their upper limit).
    pub fn max_width(&self) -> f64 {
        2.0 * self.finger_limits.upper
    }

    /// Index of a joint name among the 7 arm joints.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.joint_names.iter().position(|n| n == name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_sides_load_with_panda_limits() {
        for side in ["left", "right"] {
            let d = ArmDescription::load(side).unwrap();
            assert_eq!(d.joint_names[0], format!("{side}_joint1"));
            assert_eq!(d.limits[3].upper, -0.0698);
            assert_eq!(d.limits[0].effort, 87.0);
            assert_eq!(d.limits[6].velocity, 2.61);
            assert_eq!(d.max_width(), 0.08);
            // link1..7 and the hand carry mass; link8 is a massless frame.
            assert_eq!(d.chain_bodies.len(), 8);
        }
        assert!(ArmDescription::load("middle").is_err());
    }
}
