//! The robot as the world and the sensors see it: the project URDF (models/robot/agrisim_robot.urdf, compiled
//! in so the FMU carries exactly the geometry every other consumer reads), forward kinematics
//! driven by the world's scalar inputs (lift, 2 x 7 arm joints, 2 finger gaps), and the two
//! pieces of geometry harvest physics derives from it: the finger pads and the harvest box
//! interior.
//!
//! FK runs over a table built once (joint -> input coordinate, parent/child link indices), so a
//! step costs one pass of ~50 joint transforms and allocates nothing.

use crate::{JointKind, Pose as RPose, Robot, Shape};
use std::collections::HashMap;

/// The URDF the world is built from.
pub const URDF: &str = include_str!("../../../../models/robot/agrisim_robot.urdf");

/// Franka's "ready" configuration (franka_ros / MoveIt panda `ready` pose), inside the URDF
/// limits: the arms' defaults so an unconnected world holds them folded in front of the lift.
pub const READY_POSE: [f64; 7] = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785];

/// Gripper gap when the finger inputs are unconnected: fully open (2 x 0.04 m).
pub const OPEN_WIDTH: f64 = 0.08;

/// The two arms, in a fixed order (left first) wherever both appear.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, serde::Serialize, serde::Deserialize)]
pub enum Side {
    Left = 0,
    Right = 1,
}

impl Side {
    pub const BOTH: [Side; 2] = [Side::Left, Side::Right];

    pub fn prefix(self) -> &'static str {
        match self {
            Side::Left => "left",
            Side::Right => "right",
        }
    }

    pub fn other(self) -> Side {
        match self {
            Side::Left => Side::Right,
            Side::Right => Side::Left,
        }
    }
}

/// Every robot coordinate the world takes as input.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Coords {
    pub lift: f64,
    /// Joint angles [rad] of `<side>_joint1..7`, indexed by [`Side`].
    pub arms: [[f64; 7]; 2],
    /// Finger gaps [m] (distance between the pads), indexed by [`Side`].
    pub widths: [f64; 2],
}

impl Default for Coords {
    fn default() -> Self {
        Coords { lift: 0.0, arms: [READY_POSE; 2], widths: [OPEN_WIDTH; 2] }
    }
}

/// Links the base box stands for, left out of the world's colliders and the sensors' robot:
/// base_link (the box is the chassis: navigation's height band, contacts on `base_link`) and
/// the wheel units (inside or below it; their steering is not an input of either).
pub fn chassis_link(name: &str) -> bool {
    name == "base_link" || name.ends_with("_steer_link") || name.ends_with("_wheel_link")
}

/// Which input drives a joint.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Source {
    /// Steering, wheels: not inputs of the world (the wheels carry no colliders here).
    Zero,
    Lift,
    Arm(Side, usize),
    /// One finger of a gripper: half the gap, less the pad's inner offset.
    Finger(Side),
}

#[derive(Clone, Debug)]
struct FkJoint {
    parent: usize,
    child: usize,
    joint: crate::Joint,
    source: Source,
}

/// Where a gripper's pads are in its hand frame (`<side>_hand`), from the finger geometry.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FingerPads {
    /// Pad extent along the approach axis (hand z) [m].
    pub z: [f64; 2],
    /// Pad extent sideways (hand x, the pad's depth) [m].
    pub x: [f64; 2],
    /// Inner face of finger 1 at hand y = q + inner_offset (finger 2 mirrored): gap = 2 (q + inner_offset).
    pub inner_offset: f64,
    /// Finger joint travel [m].
    pub q_max: f64,
}

impl FingerPads {
    /// Finger joint coordinate for a gap, clamped to the joint's travel.
    pub fn q_for_width(&self, width: f64) -> f64 {
        (0.5 * width - self.inner_offset).clamp(0.0, self.q_max)
    }

    /// The gap with the fingers open all the way [m].
    pub fn max_gap(&self) -> f64 {
        2.0 * (self.q_max + self.inner_offset)
    }

    /// Largest gap the fingers open to.
    pub fn max_width(&self) -> f64 {
        2.0 * (self.q_max + self.inner_offset)
    }
}

/// The harvest box interior in `harvest_box_link`'s frame (an axis-aligned box).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoxInterior {
    pub lo: [f64; 3],
    pub hi: [f64; 3],
}

impl BoxInterior {
    pub fn contains(&self, p: [f64; 3]) -> bool {
        (0..3).all(|i| p[i] >= self.lo[i] && p[i] <= self.hi[i])
    }
}

/// The URDF robot plus the world's FK table.
#[derive(Clone, Debug)]
pub struct RobotModel {
    pub robot: Robot,
    /// Link names in `robot.links()` order (indices of [`RobotModel::fk`]'s output).
    pub link_names: Vec<String>,
    fk_joints: Vec<FkJoint>,
    pub pads: [FingerPads; 2],
    pub box_interior: BoxInterior,
    /// Joint limits of `<side>_joint1..7` and the lift (lower, upper).
    pub arm_limits: [[(f64, f64); 7]; 2],
    pub lift_limits: (f64, f64),
}

impl RobotModel {
    pub fn load() -> Result<RobotModel, String> {
        Self::from_robot(Robot::from_urdf_str(URDF).map_err(|e| format!("robot URDF: {e}"))?)
    }

    pub fn from_robot(robot: Robot) -> Result<RobotModel, String> {
        let link_names: Vec<String> = robot.links().iter().map(|l| l.name.clone()).collect();
        let index: HashMap<&str, usize> = link_names.iter().enumerate().map(|(i, n)| (n.as_str(), i)).collect();
        let limits = |name: &str| -> Result<(f64, f64), String> {
            let j = robot.joint(name).ok_or(format!("robot URDF: no joint {name}"))?;
            let l = j.limits.ok_or(format!("robot URDF: joint {name} has no limits"))?;
            Ok((l.lower, l.upper))
        };
        let mut arm_limits = [[(0.0, 0.0); 7]; 2];
        for side in Side::BOTH {
            for (i, lim) in arm_limits[side as usize].iter_mut().enumerate() {
                *lim = limits(&format!("{}_joint{}", side.prefix(), i + 1))?;
            }
        }
        let lift_limits = limits("lift_joint")?;
        let mut pads = [None, None];
        for side in Side::BOTH {
            pads[side as usize] = Some(finger_pads(&robot, side)?);
        }
        let pads = pads.map(|p| p.expect("both sides set above"));
        let mut fk_joints = Vec::with_capacity(robot.joints().len());
        for j in robot.joints() {
            let source = source_of(&j.name, j.kind);
            fk_joints.push(FkJoint {
                parent: index[j.parent.as_str()],
                child: index[j.child.as_str()],
                joint: j.clone(),
                source,
            });
        }
        let box_interior = box_interior(&robot)?;
        for side in Side::BOTH {
            for (q, &(lo, hi)) in READY_POSE.iter().zip(&arm_limits[side as usize]) {
                if *q < lo || *q > hi {
                    return Err(format!("ready pose {READY_POSE:?} outside the {} arm's limits", side.prefix()));
                }
            }
        }
        Ok(RobotModel { robot, link_names, fk_joints, pads, box_interior, arm_limits, lift_limits })
    }

    pub fn link_index(&self, name: &str) -> Option<usize> {
        self.link_names.iter().position(|n| n == name)
    }

    /// Pose of every link in base_link for `c` (indexed like `link_names`). Joint values are
    /// clamped to their URDF limits: the arm FMUs never leave them, and a clamped pose is
    /// what the real robot's hardware stops would give.
    pub fn fk(&self, c: &Coords, out: &mut Vec<RPose>) {
        out.clear();
        out.resize(self.link_names.len(), RPose::IDENTITY);
        for fj in &self.fk_joints {
            let raw = match fj.source {
                Source::Zero => 0.0,
                Source::Lift => c.lift,
                Source::Arm(side, i) => c.arms[side as usize][i],
                Source::Finger(side) => self.pads[side as usize].q_for_width(c.widths[side as usize]),
            };
            let q = match fj.joint.limits {
                Some(l) if l.lower.is_finite() && l.upper.is_finite() => raw.clamp(l.lower, l.upper),
                _ => raw,
            };
            out[fj.child] = out[fj.parent].mul(&fj.joint.transform(q));
        }
    }
}

fn source_of(name: &str, kind: JointKind) -> Source {
    if kind == JointKind::Fixed {
        return Source::Zero;
    }
    if name == "lift_joint" {
        return Source::Lift;
    }
    for side in Side::BOTH {
        let Some(rest) = name.strip_prefix(side.prefix()) else { continue };
        if let Some(i) =
            rest.strip_prefix("_joint").and_then(|n| n.parse::<usize>().ok()).filter(|i| (1..=7).contains(i))
        {
            return Source::Arm(side, i - 1);
        }
        if rest.starts_with("_finger_joint") {
            return Source::Finger(side);
        }
    }
    Source::Zero
}

/// Pads of `<side>_finger1`: its joint's origin in the hand frame plus its collision box. The
/// finger moves along +y of the hand; finger 2 mirrors it.
fn finger_pads(robot: &Robot, side: Side) -> Result<FingerPads, String> {
    let p = side.prefix();
    let joint = robot.joint(&format!("{p}_finger_joint1")).ok_or(format!("robot URDF: no {p}_finger_joint1"))?;
    let hand = format!("{p}_hand");
    if joint.parent != hand || joint.kind != JointKind::Prismatic {
        return Err(format!("robot URDF: {p}_finger_joint1 must be a prismatic joint on {hand}"));
    }
    let axis_ok = (joint.axis[1] - 1.0).abs() < 1e-9
        && joint.origin.max_abs_diff(&RPose::from_translation(joint.origin.trans)) < 1e-9;
    let [c] = robot.colliders(&joint.child).unwrap_or(&[]) else {
        return Err(format!("robot URDF: {} needs exactly one collision box (the pad)", joint.child));
    };
    let Shape::Box { size } = c.shape else {
        return Err(format!("robot URDF: the collision of {} must be a box", joint.child));
    };
    if !axis_ok || c.origin.max_abs_diff(&RPose::from_translation(c.origin.trans)) > 1e-9 {
        return Err(format!("robot URDF: {p} finger axis must be the hand's +y, pad box unrotated"));
    }
    let o = c.origin.trans;
    let j = joint.origin.trans;
    let limits = joint.limits.ok_or(format!("robot URDF: {p}_finger_joint1 has no limits"))?;
    Ok(FingerPads {
        z: [j[2] + o[2] - 0.5 * size[2], j[2] + o[2] + 0.5 * size[2]],
        x: [j[0] + o[0] - 0.5 * size[0], j[0] + o[0] + 0.5 * size[0]],
        inner_offset: j[1] + o[1] - 0.5 * size[1],
        q_max: limits.upper,
    })
}

/// The open box `harvest_box_link` forms: the overall AABB of its (unrotated) collision boxes,
/// shrunk on each side to the inner face of the thin wall there; open at the top.
fn box_interior(robot: &Robot) -> Result<BoxInterior, String> {
    let cs = robot.colliders("harvest_box_link").ok_or("robot URDF: no harvest_box_link")?;
    let mut boxes = Vec::new();
    for c in cs {
        match c.shape {
            Shape::Box { size } if c.origin.max_abs_diff(&RPose::from_translation(c.origin.trans)) < 1e-9 => {
                boxes.push((c.origin.trans, size))
            }
            _ => return Err("robot URDF: harvest_box_link collisions must be unrotated boxes".into()),
        }
    }
    if boxes.len() < 5 {
        return Err("robot URDF: harvest_box_link needs a bottom and four walls".into());
    }
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for (c, s) in &boxes {
        for i in 0..3 {
            lo[i] = lo[i].min(c[i] - 0.5 * s[i]);
            hi[i] = hi[i].max(c[i] + 0.5 * s[i]);
        }
    }
    let mid: [f64; 3] = std::array::from_fn(|i| 0.5 * (lo[i] + hi[i]));
    let (mut ilo, mut ihi) = (lo, hi);
    for (c, s) in &boxes {
        let thin = (0..3).min_by(|&a, &b| s[a].total_cmp(&s[b])).unwrap_or(0);
        if c[thin] < mid[thin] {
            ilo[thin] = ilo[thin].max(c[thin] + 0.5 * s[thin]);
        } else {
            ihi[thin] = ihi[thin].min(c[thin] - 0.5 * s[thin]);
        }
    }
    if (0..3).any(|i| ilo[i] >= ihi[i]) {
        return Err("robot URDF: harvest_box_link encloses no volume".into());
    }
    Ok(BoxInterior { lo: ilo, hi: ihi })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pads_and_box_come_from_the_urdf() {
        let m = RobotModel::load().unwrap();
        let p = m.pads[0];
        assert!((p.z[0] - 0.0584).abs() < 1e-9 && (p.z[1] - 0.1084).abs() < 1e-9, "{p:?}");
        assert!((p.x[0] + 0.01).abs() < 1e-9 && (p.x[1] - 0.01).abs() < 1e-9);
        assert!(p.inner_offset.abs() < 1e-9 && (p.max_width() - 0.08).abs() < 1e-9);
        assert_eq!(m.pads[0], m.pads[1]);
        let b = m.box_interior;
        let want = BoxInterior { lo: [-0.19, -0.29, 0.01], hi: [0.19, 0.29, 0.25] };
        for i in 0..3 {
            assert!((b.lo[i] - want.lo[i]).abs() < 1e-9 && (b.hi[i] - want.hi[i]).abs() < 1e-9, "{b:?}");
        }
    }

    #[test]
    fn fk_matches_the_crates_fk() {
        let m = RobotModel::load().unwrap();
        let c = Coords { lift: 0.3, arms: [[0.1, -0.5, 0.2, -2.0, 0.3, 1.2, 0.4], READY_POSE], widths: [0.05, 0.02] };
        let mut q = std::collections::BTreeMap::new();
        q.insert("lift_joint".to_string(), 0.3);
        for side in Side::BOTH {
            for i in 0..7 {
                q.insert(format!("{}_joint{}", side.prefix(), i + 1), c.arms[side as usize][i]);
            }
            for f in 1..=2 {
                q.insert(format!("{}_finger_joint{f}", side.prefix()), 0.5 * c.widths[side as usize]);
            }
        }
        let want = m.robot.fk(&q).unwrap();
        let mut got = Vec::new();
        m.fk(&c, &mut got);
        for (name, pose) in m.link_names.iter().zip(&got) {
            assert!(pose.max_abs_diff(&want[name]) < 1e-12, "{name}");
        }
    }
}
