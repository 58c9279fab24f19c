//! Compliant leaves: a leaf the robot presses gives way, turning about its petiole's base on
//! the stem, and springs back when the robot leaves it.
//!
//! Model:
//! - A compound leaf (its rachis and leaflets, [`agrisim_scene::generate::compound_leaf`]) is
//!   one rigid blade hinged at the petiole's base: its state is a rotation vector `theta`
//!   from its grown pose and a rate.
//! - In contact, the robot moves it: a robot part pressing on the blade at `p` by `depth`
//!   along the leaf's surface normal `n` (pointing to the part) turns it by the least
//!   rotation that takes `p` out of the way, `d theta = (p - hinge) x (-n) depth / |p - hinge|^2`
//!   (of several presses on one leaf, the largest turn: the parts of one blade overlap, and
//!   their turns are mostly one). The robot is kinematic, so the leaf follows it; holding the leaf
//!   turned costs the robot the spring's moment: a force `k |theta| / |p - hinge|` at the press.
//! - Free, it swings back as a damped rotational oscillator of natural frequency `f` and
//!   damping ratio `zeta`: `theta'' = -w^2 theta - 2 zeta w theta'` (`w = 2 pi f`), integrated
//!   semi-implicitly per step.
//! - A leaf turns at most [`MAX_ANGLE`]; back within [`REST_ANGLE`] and slow, it is put back at
//!   its grown pose and leaves the simulation: only leaves the robot has moved, and only
//!   until they are still again, are simulated, so the cost is bounded by what the robot
//!   touches, not by the crop's size.
//! - Colliders move with the leaf: contacts, clearance and the world's planning scene see the
//!   deflected leaf, and the camera and LiDAR FMUs draw it where it is from the world's
//!   `moved_objects` output ([`crate::moved_objects`]).
//!
//! Figures (defaults of the `leaf_*` parameters), all estimates: no measurement of a tomato
//! leaf's bending stiffness at the petiole was found. `leaf_stiffness` 0.3 N m/rad: a 30 cm leaf
//! pushed 10 cm at its tip (0.33 rad) resists with about 0.3 N, a light brush.
//! `leaf_frequency` 2 Hz, `leaf_damping_ratio` 0.5: leaves sway at a few hertz and settle in
//! a few swings; a released leaf is back within 2 % of its turn in about
//! `4 / (zeta w)` = 0.64 s.

use crate::contacts::Press;
use crate::robot_links::{from_rapier, to_rapier};
use crate::scene_world::SceneWorld;
use agrisim_math::vec3::{add, cross, dot, norm, scale, sub};
use agrisim_robot::Pose as RPose;
use agrisim_scene::scene::{Kind, Object};
use agrisim_scene::Shape;
use std::collections::BTreeMap;

/// Largest turn of a leaf from its grown pose [rad].
pub const MAX_ANGLE: f64 = 1.5;
/// Presses nearer the petiole's base than this [m] count at this distance: the base of the
/// petiole is as stiff as the stem it grows from, and a press there turns the leaf no more.
pub const MIN_ARM: f64 = 0.03;
/// A free leaf turned less than this [rad], and slower than `REST_ANGLE` per second, is at rest.
pub const REST_ANGLE: f64 = 1e-4;

/// The foliage parameters (the FMU's `leaf_*` parameters).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FoliageParams {
    /// Whether leaves give way (false: rigid, as before).
    pub enabled: bool,
    /// Rotational stiffness about the petiole's base [N m/rad].
    pub stiffness: f64,
    /// Natural frequency [Hz] and damping ratio of the free leaf.
    pub frequency: f64,
    pub damping_ratio: f64,
}

impl Default for FoliageParams {
    fn default() -> Self {
        FoliageParams { enabled: true, stiffness: 0.3, frequency: 2.0, damping_ratio: 0.5 }
    }
}

/// A leaf: its objects (the rachis, then its leaflets) and its hinge, in the map frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Leaf {
    pub objects: Vec<usize>,
    pub hinge: [f64; 3],
}

/// Every compound leaf of `objects`: a rachis (`.../leaf{k}`, a cylinder whose local -z end
/// is the petiole's base) and the leaflets named after it (`.../leaf{k}_{j}`), in object order.
pub fn leaves(objects: &[Object]) -> Vec<Leaf> {
    let mut out: Vec<Leaf> = Vec::new();
    let mut rachis_name = String::new();
    for (i, o) in objects.iter().enumerate() {
        if o.kind != Kind::Leaf {
            continue;
        }
        match o.shape {
            Shape::Cylinder { half_height, .. } => {
                let hinge = o.placement.transform_point([0.0, 0.0, -half_height]);
                out.push(Leaf { objects: vec![i], hinge });
                rachis_name = format!("{}_", o.name);
            }
            _ if !rachis_name.is_empty() && o.name.starts_with(&rachis_name) => {
                if let Some(l) = out.last_mut() {
                    l.objects.push(i);
                }
            }
            _ => {}
        }
    }
    out
}

/// A leaf the robot has moved and that is not at rest yet.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LeafState {
    /// Rotation vector from the grown pose [rad] and its rate [rad/s].
    pub theta: [f64; 3],
    pub rate: [f64; 3],
}

/// The moving leaves and what pushing them has cost.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Foliage {
    /// By leaf index (into [`leaves`]).
    pub moving: BTreeMap<usize, LeafState>,
    /// Leaves the robot moved from rest (a leaf pushed again before it came to rest counts once).
    pub pushes: u64,
    /// The largest force the robot spent holding a leaf turned [N].
    pub peak_force: f64,
}

/// The static per-scene data: leaves, the leaf of each object, each leaf object's grown pose.
#[derive(Clone, Debug, Default)]
pub struct LeafTable {
    pub leaves: Vec<Leaf>,
    /// Leaf index by object index (sorted by object).
    of_object: Vec<(usize, usize)>,
    /// Grown collider pose of each leaf object, by object index (sorted).
    rest: Vec<(usize, RPose)>,
}

impl LeafTable {
    pub fn new(objects: &[Object], world: &SceneWorld) -> LeafTable {
        let leaves = leaves(objects);
        let mut of_object = Vec::new();
        let mut rest = Vec::new();
        for (l, leaf) in leaves.iter().enumerate() {
            for &o in &leaf.objects {
                of_object.push((o, l));
                rest.push((o, from_rapier(world.colliders[world.objects[o].collider].position())));
            }
        }
        of_object.sort_unstable();
        rest.sort_unstable_by_key(|r| r.0);
        LeafTable { leaves, of_object, rest }
    }

    /// The leaf an object belongs to.
    pub fn leaf_of(&self, object: usize) -> Option<usize> {
        self.of_object.binary_search_by_key(&object, |e| e.0).ok().map(|k| self.of_object[k].1)
    }

    fn rest(&self, object: usize) -> &RPose {
        &self.rest[self.rest.binary_search_by_key(&object, |r| r.0).expect("a leaf object")].1
    }
}

/// The rotation by rotation vector `theta`.
fn rotation(theta: [f64; 3]) -> RPose {
    let a = norm(theta);
    if a < 1e-12 {
        return RPose::IDENTITY;
    }
    RPose::from_axis_angle(scale(theta, 1.0 / a), a)
}

impl Foliage {
    /// One step of `h` seconds: `presses` of robot parts move the leaves they touch, free
    /// leaves swing back; the moved leaves' colliders are put at their new poses. Returns
    /// whether any collider moved.
    pub fn step(
        &mut self,
        table: &LeafTable,
        world: &mut SceneWorld,
        presses: &[Press],
        p: &FoliageParams,
        h: f64,
    ) -> bool {
        if !p.enabled {
            return false;
        }
        // Presses by leaf: the largest turn and its lever arm.
        let mut turns: BTreeMap<usize, ([f64; 3], f64)> = BTreeMap::new();
        for c in presses {
            let Some(l) = table.leaf_of(c.object) else { continue };
            let r = sub(c.point, table.leaves[l].hinge);
            let arm = dot(r, r).sqrt().max(MIN_ARM);
            let turn = scale(cross(r, scale(c.normal, -1.0)), c.depth / (arm * arm));
            if turns.get(&l).is_none_or(|&(t, _)| norm(turn) > norm(t)) {
                turns.insert(l, (turn, arm));
            }
        }
        let w = 2.0 * std::f64::consts::PI * p.frequency;
        let mut moved = Vec::new();
        for (&l, &(turn, arm)) in &turns {
            if !self.moving.contains_key(&l) {
                self.pushes += 1;
            }
            let s = self.moving.entry(l).or_default();
            let before = s.theta;
            s.theta = clamp_angle(add(s.theta, turn));
            s.rate = scale(sub(s.theta, before), 1.0 / h);
            self.peak_force = self.peak_force.max(p.stiffness * norm(s.theta) / arm);
            moved.push(l);
        }
        let mut rested = Vec::new();
        for (&l, s) in self.moving.iter_mut() {
            if turns.contains_key(&l) {
                continue;
            }
            // Semi-implicit Euler: the rate first, then the angle with the new rate.
            let acc = sub(scale(s.theta, -w * w), scale(s.rate, 2.0 * p.damping_ratio * w));
            s.rate = add(s.rate, scale(acc, h));
            s.theta = clamp_angle(add(s.theta, scale(s.rate, h)));
            if norm(s.theta) < REST_ANGLE && norm(s.rate) < REST_ANGLE {
                rested.push(l);
            }
            moved.push(l);
        }
        for l in &rested {
            self.moving.remove(l);
        }
        for &l in &moved {
            let theta = self.moving.get(&l).map_or([0.0; 3], |s| s.theta);
            place(table, world, l, theta);
        }
        !moved.is_empty()
    }
}

fn clamp_angle(theta: [f64; 3]) -> [f64; 3] {
    let a = norm(theta);
    if a > MAX_ANGLE {
        scale(theta, MAX_ANGLE / a)
    } else {
        theta
    }
}

/// Puts leaf `l`'s colliders at their grown poses turned by `theta` about its hinge.
fn place(table: &LeafTable, world: &mut SceneWorld, l: usize, theta: [f64; 3]) {
    let leaf = &table.leaves[l];
    let about = RPose::from_translation(leaf.hinge)
        .mul(&rotation(theta))
        .mul(&RPose::from_translation(scale(leaf.hinge, -1.0)));
    for &o in &leaf.objects {
        let pose = to_rapier(&about.mul(table.rest(o)));
        let handle = world.objects[o].collider;
        world.colliders[handle].set_position(pose);
    }
}
