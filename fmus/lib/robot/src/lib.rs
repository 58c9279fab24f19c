//! agrisim's robot description as a kinematic tree.
//!
//! One URDF (models/robot/agrisim_robot.urdf) drives the arm FMUs' joints, the world FMU's
//! kinematic links, the TF tree and the planner's kinematics; this crate is the single place
//! that reads it, so they cannot disagree. It keeps what those users need: joints with limits
//! in a parent-before-child order, forward kinematics of every link in the root frame
//! (`base_link`), joint chains between two links (e.g. `lift_link` -> `left_hand`), and the
//! collision primitives of every link. Meshes are rejected for collision: the project's
//! collision checking (sphere approximations, parry) works on primitives.

pub mod model;
mod pose;
pub mod reach;

pub use pose::Pose;

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

/// Joint types the robot uses. Floating/planar/spherical joints are refused at load time:
/// nothing in agrisim can actuate them and FK would need more than one coordinate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointKind {
    Revolute,
    Continuous,
    Prismatic,
    Fixed,
}

impl JointKind {
    /// Whether the joint has a coordinate (appears in joint states and FK inputs).
    pub fn is_movable(self) -> bool {
        self != JointKind::Fixed
    }
}

/// Joint limits in SI units (rad or m, rad/s or m/s, N m or N). Continuous joints have
/// infinite position bounds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    pub lower: f64,
    pub upper: f64,
    pub velocity: f64,
    pub effort: f64,
}

impl Limits {
    pub fn contains(&self, q: f64) -> bool {
        q >= self.lower && q <= self.upper
    }
}

#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    pub name: String,
    pub kind: JointKind,
    pub parent: String,
    pub child: String,
    /// Child joint frame in the parent link frame at q = 0.
    pub origin: Pose,
    /// Unit axis in the joint frame (meaningless for fixed joints).
    pub axis: [f64; 3],
    /// `None` for fixed joints.
    pub limits: Option<Limits>,
}

impl Joint {
    /// Child link frame in the parent link frame at coordinate `q`.
    pub fn transform(&self, q: f64) -> Pose {
        match self.kind {
            JointKind::Fixed => self.origin,
            JointKind::Revolute | JointKind::Continuous => self.origin.mul(&Pose::from_axis_angle(self.axis, q)),
            JointKind::Prismatic => {
                let a = self.axis;
                self.origin.mul(&Pose::from_translation([a[0] * q, a[1] * q, a[2] * q]))
            }
        }
    }
}

/// A collision primitive. Cylinders and capsules are along their local z axis (URDF).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// Full edge lengths.
    Box {
        size: [f64; 3],
    },
    Cylinder {
        radius: f64,
        length: f64,
    },
    /// URDF 1.2 capsule: `length` of the cylindrical part.
    Capsule {
        radius: f64,
        length: f64,
    },
    Sphere {
        radius: f64,
    },
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Collider {
    pub shape: Shape,
    /// Primitive frame in the link frame.
    pub origin: Pose,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Link {
    pub name: String,
    /// 0 for massless frames (e.g. optical frames).
    pub mass: f64,
    pub colliders: Vec<Collider>,
}

#[derive(Debug, Clone)]
pub struct Robot {
    pub name: String,
    /// The link that is no joint's child (`base_link` here).
    pub root: String,
    links: Vec<Link>,
    /// Parent before child (breadth-first from the root), so FK is one pass.
    joints: Vec<Joint>,
    link_index: HashMap<String, usize>,
    /// Joint index by child link name: a tree has exactly one per non-root link.
    joint_by_child: HashMap<String, usize>,
}

impl Robot {
    /// Loads and validates a URDF file. Errors name the file and the offending element.
    pub fn from_urdf_file(path: impl AsRef<Path>) -> Result<Robot, String> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
        Robot::from_urdf_str(&text).map_err(|e| format!("{}: {e}", path.display()))
    }

    /// Loads and validates URDF text (errors name the element, not a file).
    pub fn from_urdf_str(text: &str) -> Result<Robot, String> {
        let urdf = urdf_rs::read_from_string(text).map_err(|e| format!("URDF parse error: {e}"))?;
        Robot::from_urdf(&urdf)
    }

    /// Builds the tree from urdf-rs's model: checks link references, one parent per link,
    /// a single root and no cycles, and converts geometry to primitives.
    pub fn from_urdf(urdf: &urdf_rs::Robot) -> Result<Robot, String> {
        let mut links = Vec::with_capacity(urdf.links.len());
        let mut link_index = HashMap::new();
        for l in &urdf.links {
            if link_index.insert(l.name.clone(), links.len()).is_some() {
                return Err(format!("link \"{}\": defined twice", l.name));
            }
            let mut colliders = Vec::with_capacity(l.collision.len());
            for (i, c) in l.collision.iter().enumerate() {
                let shape = match &c.geometry {
                    urdf_rs::Geometry::Box { size } => Shape::Box { size: size.0 },
                    urdf_rs::Geometry::Cylinder { radius, length } => Shape::Cylinder { radius: *radius, length: *length },
                    urdf_rs::Geometry::Capsule { radius, length } => Shape::Capsule { radius: *radius, length: *length },
                    urdf_rs::Geometry::Sphere { radius } => Shape::Sphere { radius: *radius },
                    urdf_rs::Geometry::Mesh { filename, .. } => {
                        return Err(format!(
                            "link \"{}\" collision {i}: mesh \"{filename}\" not supported (collision geometry must be primitives)",
                            l.name
                        ))
                    }
                };
                colliders.push(Collider { shape, origin: pose_of(&c.origin) });
            }
            links.push(Link { name: l.name.clone(), mass: l.inertial.mass.value, colliders });
        }

        let mut joints = Vec::with_capacity(urdf.joints.len());
        let mut joint_by_child = HashMap::new();
        let mut seen = HashMap::new();
        for j in &urdf.joints {
            if seen.insert(j.name.clone(), ()).is_some() {
                return Err(format!("joint \"{}\": defined twice", j.name));
            }
            for (role, l) in [("parent", &j.parent.link), ("child", &j.child.link)] {
                if !link_index.contains_key(l) {
                    return Err(format!("joint \"{}\": {role} link \"{l}\" does not exist", j.name));
                }
            }
            let kind = match &j.joint_type {
                urdf_rs::JointType::Revolute => JointKind::Revolute,
                urdf_rs::JointType::Continuous => JointKind::Continuous,
                urdf_rs::JointType::Prismatic => JointKind::Prismatic,
                urdf_rs::JointType::Fixed => JointKind::Fixed,
                other => return Err(format!("joint \"{}\": type {other:?} not supported", j.name)),
            };
            let a = j.axis.xyz.0;
            let n = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
            if kind.is_movable() && !(n > 1e-12 && n.is_finite()) {
                return Err(format!("joint \"{}\": axis {a:?} is not a direction", j.name));
            }
            let axis = if kind.is_movable() { a.map(|x| x / n) } else { a };
            let limits = match kind {
                JointKind::Fixed => None,
                JointKind::Continuous => Some(Limits {
                    lower: f64::NEG_INFINITY,
                    upper: f64::INFINITY,
                    velocity: j.limit.velocity,
                    effort: j.limit.effort,
                }),
                _ => {
                    let l = &j.limit;
                    if l.lower.is_nan() || l.upper.is_nan() || l.lower > l.upper {
                        return Err(format!("joint \"{}\": limit lower {} above upper {}", j.name, l.lower, l.upper));
                    }
                    Some(Limits { lower: l.lower, upper: l.upper, velocity: l.velocity, effort: l.effort })
                }
            };
            if joint_by_child.insert(j.child.link.clone(), joints.len()).is_some() {
                return Err(format!("joint \"{}\": link \"{}\" already has a parent joint", j.name, j.child.link));
            }
            joints.push(Joint {
                name: j.name.clone(),
                kind,
                parent: j.parent.link.clone(),
                child: j.child.link.clone(),
                origin: pose_of(&j.origin),
                axis,
                limits,
            });
        }

        let roots: Vec<&str> =
            links.iter().map(|l| l.name.as_str()).filter(|n| !joint_by_child.contains_key(*n)).collect();
        let root = match roots.as_slice() {
            [r] => r.to_string(),
            [] => return Err("robot: no root link (the joints form a cycle)".into()),
            many => return Err(format!("robot: {} root links {many:?}; a URDF must be one tree", many.len())),
        };

        // Breadth-first order from the root; any joint not reached is on a cycle.
        let mut children: HashMap<&str, Vec<usize>> = HashMap::new();
        for (i, j) in joints.iter().enumerate() {
            children.entry(j.parent.as_str()).or_default().push(i);
        }
        let mut order = Vec::with_capacity(joints.len());
        let mut queue = std::collections::VecDeque::from([root.as_str()]);
        while let Some(l) = queue.pop_front() {
            for &i in children.get(l).map(Vec::as_slice).unwrap_or(&[]) {
                order.push(i);
                queue.push_back(joints[i].child.as_str());
            }
        }
        if order.len() != joints.len() {
            let bad = (0..joints.len()).find(|i| !order.contains(i)).unwrap();
            return Err(format!("joint \"{}\": not reachable from root \"{root}\" (cycle)", joints[bad].name));
        }
        let joints: Vec<Joint> = order.into_iter().map(|i| joints[i].clone()).collect();
        let joint_by_child = joints.iter().enumerate().map(|(i, j)| (j.child.clone(), i)).collect();
        Ok(Robot { name: urdf.name.clone(), root, links, joints, link_index, joint_by_child })
    }

    pub fn links(&self) -> &[Link] {
        &self.links
    }

    pub fn link(&self, name: &str) -> Option<&Link> {
        self.link_index.get(name).map(|&i| &self.links[i])
    }

    /// All joints, parent before child.
    pub fn joints(&self) -> &[Joint] {
        &self.joints
    }

    pub fn joint(&self, name: &str) -> Option<&Joint> {
        self.joints.iter().find(|j| j.name == name)
    }

    /// Joints with a coordinate, in the order `fk_slice` expects.
    pub fn movable_joints(&self) -> impl Iterator<Item = &Joint> {
        self.joints.iter().filter(|j| j.kind.is_movable())
    }

    /// The collision primitives of a link (empty for frames), in the link frame.
    pub fn colliders(&self, link: &str) -> Option<&[Collider]> {
        self.link(link).map(|l| l.colliders.as_slice())
    }

    /// Pose of every link in the root frame. Joints absent from `q` are at 0 (so a caller
    /// can pass only the arm it cares about); names that are not movable joints are an error,
    /// as a typo would otherwise silently leave a joint at 0.
    pub fn fk(&self, q: &BTreeMap<String, f64>) -> Result<BTreeMap<String, Pose>, String> {
        for name in q.keys() {
            match self.joint(name) {
                Some(j) if j.kind.is_movable() => {}
                Some(_) => return Err(format!("fk: joint \"{name}\" is fixed")),
                None => return Err(format!("fk: no joint \"{name}\"")),
            }
        }
        Ok(self.fk_with(|j| q.get(&j.name).copied().unwrap_or(0.0)))
    }

    /// Like [`Robot::fk`] with one value per movable joint in [`Robot::movable_joints`] order.
    pub fn fk_slice(&self, q: &[f64]) -> Result<BTreeMap<String, Pose>, String> {
        let n = self.movable_joints().count();
        if q.len() != n {
            return Err(format!("fk_slice: {} values for {n} movable joints", q.len()));
        }
        let mut it = q.iter();
        Ok(self.fk_with(|j| if j.kind.is_movable() { *it.next().unwrap() } else { 0.0 }))
    }

    fn fk_with(&self, mut q: impl FnMut(&Joint) -> f64) -> BTreeMap<String, Pose> {
        let mut out = BTreeMap::new();
        out.insert(self.root.clone(), Pose::IDENTITY);
        for j in &self.joints {
            let parent = out[&j.parent];
            out.insert(j.child.clone(), parent.mul(&j.transform(q(j))));
        }
        out
    }

    /// Joints (fixed included) from `base` down to `tip`, in order. `base` must be an
    /// ancestor of `tip` (or equal, giving an empty chain).
    pub fn chain(&self, base: &str, tip: &str) -> Result<Vec<Joint>, String> {
        for l in [base, tip] {
            if !self.link_index.contains_key(l) {
                return Err(format!("chain: no link \"{l}\""));
            }
        }
        let mut out = Vec::new();
        let mut cur = tip;
        while cur != base {
            let Some(&i) = self.joint_by_child.get(cur) else {
                return Err(format!("chain: \"{base}\" is not an ancestor of \"{tip}\""));
            };
            out.push(self.joints[i].clone());
            cur = &self.joints[i].parent;
        }
        out.reverse();
        Ok(out)
    }

    /// `tip` in `base` along [`Robot::chain`], with one value per movable joint of the chain
    /// (in chain order): what an arm-only IK needs without the rest of the tree.
    pub fn chain_fk(chain: &[Joint], q: &[f64]) -> Result<Pose, String> {
        let n = chain.iter().filter(|j| j.kind.is_movable()).count();
        if q.len() != n {
            return Err(format!("chain_fk: {} values for {n} movable joints", q.len()));
        }
        let mut it = q.iter();
        Ok(chain.iter().fold(Pose::IDENTITY, |acc, j| {
            let qj = if j.kind.is_movable() { *it.next().unwrap() } else { 0.0 };
            acc.mul(&j.transform(qj))
        }))
    }
}

fn pose_of(p: &urdf_rs::Pose) -> Pose {
    Pose::from_xyz_rpy(p.xyz.0, p.rpy.0)
}
