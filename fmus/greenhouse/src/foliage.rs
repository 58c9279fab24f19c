//! Compliant foliage: a leaf or a truss the robot presses gives way, turning about where it
//! grows from the stem, and springs back when the robot leaves it.
//!
//! Model:
//! - A compound leaf (its rachis and leaflets, [`agrisim_scene::generate::compound_leaf`]) is
//!   one rigid blade hinged at the petiole's base. A truss is its rachis (`.../truss{t}`)
//!   hinged where it leaves the stem, carrying its pedicels (`.../pedicel{t}_{f}`) and the
//!   fruit that still hang from it (`.../fruit{t}_{f}`). Each pedicel is hinged in turn
//!   where it meets the rachis, carrying its fruit: a finger that presses one fruit's pedicel
//!   swings that fruit, not the whole truss with its neighbours (a single rigid truss, the
//!   first model, swung the fruit being grasped whenever the fingers brushed a neighbour's
//!   pedicel: 90/102 ground-truth harvests against 101/102 rigid). Each such part's state is
//!   a rotation vector `theta` from its grown pose (a pedicel's in its rachis's frame) and a
//!   rate.
//! - In contact, the robot moves it: a robot part pressing on the part at `p` by `depth`
//!   along the surface normal `n` (pointing to the robot part) turns it by the least
//!   rotation that takes `p` out of the way, `d theta = (p - hinge) x (-n) depth / |p - hinge|^2`
//!   (of several presses on one part, the largest turn: its colliders overlap, and their
//!   turns are mostly one). The robot is kinematic, so the part follows it; holding it
//!   turned costs the robot the spring's moment: a force `k |theta| / |p - hinge|` at the press.
//! - Free, it swings back as a damped rotational oscillator of natural frequency `f` and
//!   damping ratio `zeta`: `theta'' = -w^2 theta - 2 zeta w theta'` (`w = 2 pi f`), integrated
//!   semi-implicitly per step.
//! - A part turns at most [`MAX_ANGLE`]; back within [`REST_ANGLE`] and slow, it is put back at
//!   its grown pose and leaves the simulation: only parts the robot has moved, and only
//!   until they are still again, are simulated, so the cost is bounded by what the robot
//!   touches, not by the crop's size.
//! - Colliders move with the part: contacts, clearance and the world's planning scene see the
//!   deflected leaf or truss, and the camera and LiDAR FMUs draw it where it is from the
//!   world's `moved_objects` output ([`crate::moved_objects`]).
//! - A truss's fruit move with it only while they hang free on the plant. A fruit a gripper
//!   holds (its pedicel not yet broken, [`crate::pedicel`]) follows the hand, and its pedicel
//!   spring stands for the give of pedicel and truss together under the hand's pull; a press
//!   on a fruit turns neither it nor its truss (only presses on the truss or its pedicels do).
//!
//! Figures (defaults of the `leaf_*` and `truss_*` parameters), all estimates: no
//! measurement of a tomato leaf's or truss's bending stiffness at the stem was found.
//! - `leaf_stiffness` 0.3 N m/rad: a 30 cm leaf pushed 10 cm at its tip (0.33 rad) resists
//!   with about 0.3 N, a light brush. `leaf_frequency` 2 Hz, `leaf_damping_ratio` 0.5: leaves
//!   sway at a few hertz and settle in a few swings; a released leaf is back within 2 % of
//!   its turn in about `4 / (zeta w)` = 0.64 s.
//! - A pedicel's spring is the pedicel's own bending stiffness (`pedicel_bend_stiffness`,
//!   0.3 N m/rad, of [`crate::pedicel`]); [`PEDICEL_FREQUENCY`] 7 Hz: that stiffness and
//!   gravity against a 100 g fruit about 4 cm below the hinge; the truss's damping ratio.
//! - `truss_stiffness` 1.5 N m/rad: a truss of 5 fruit of about 100 g whose weight acts some
//!   8 cm from the stem (0.4 N m) would sag 0.26 rad on it, the kink that makes growers hang
//!   heavy trusses in truss supports. Pushed 5 cm at 10 cm out (0.46 rad), it resists with
//!   about 7 N. `truss_frequency` 2.5 Hz (that stiffness against about 0.5 kg at 8 cm gives
//!   2.8 Hz), `truss_damping_ratio` 0.3: back within 2 % in about 0.85 s.
//! - Compliant trusses are off by default (`truss_compliant = false`): the benchmarks' figures
//!   were measured with rigid ones.

use crate::contacts::Press;
use crate::robot_links::{from_rapier, to_rapier};
use crate::scene_world::SceneWorld;
use agrisim_math::vec3::{add, cross, dot, norm, scale, sub};
use agrisim_robot::Pose as RPose;
use agrisim_scene::scene::{Kind, Object};
use agrisim_scene::Shape;
use rapier3d::prelude::Pose;
use std::collections::BTreeMap;

/// Largest turn of a leaf from its grown pose [rad].
pub const MAX_ANGLE: f64 = 1.5;
/// Presses nearer the petiole's base than this [m] count at this distance: the base of the
/// petiole is as stiff as the stem it grows from, and a press there turns the leaf no more.
pub const MIN_ARM: f64 = 0.03;
/// Natural frequency of a fruit swinging on its pedicel [Hz]: sqrt((k + m g L) / (m L^2)) /
/// 2 pi with k = 0.3 N m/rad, m = 0.1 kg, L = 0.04 m gives 7.3 Hz (estimate).
pub const PEDICEL_FREQUENCY: f64 = 7.0;
/// A free leaf turned less than this [rad], and slower than `REST_ANGLE` per second, is at rest.
pub const REST_ANGLE: f64 = 1e-4;

/// How one kind of part gives way (the FMU's `leaf_*` or `truss_*` parameters).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Spring {
    /// Whether parts of this kind give way (false: rigid).
    pub enabled: bool,
    /// Rotational stiffness about the hinge [N m/rad].
    pub stiffness: f64,
    /// Natural frequency [Hz] and damping ratio of the free part.
    pub frequency: f64,
    pub damping_ratio: f64,
}

/// The foliage parameters: leaves, trusses and the pedicels on them (compliant with their
/// truss).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FoliageParams {
    pub leaf: Spring,
    pub truss: Spring,
    pub pedicel: Spring,
}

impl Default for FoliageParams {
    fn default() -> Self {
        FoliageParams {
            leaf: Spring { enabled: true, stiffness: 0.3, frequency: 2.0, damping_ratio: 0.5 },
            truss: Spring { enabled: false, stiffness: 1.5, frequency: 2.5, damping_ratio: 0.3 },
            pedicel: Spring { enabled: false, stiffness: 0.3, frequency: PEDICEL_FREQUENCY, damping_ratio: 0.3 },
        }
    }
}

impl FoliageParams {
    fn of(&self, part: Part) -> &Spring {
        match part {
            Part::Leaf => &self.leaf,
            Part::Truss => &self.truss,
            Part::Pedicel => &self.pedicel,
        }
    }
}

/// What kind of part turns about a hinge.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Part {
    Leaf,
    Truss,
    /// A pedicel of a truss, with its fruit.
    Pedicel,
}

/// A leaf or a truss: its static objects (a leaf's rachis then its leaflets; a truss's rachis
/// then its pedicels), the fruit hanging from it (scene object indices; none for a leaf) and
/// its hinge, in the map frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Hinged {
    pub part: Part,
    pub objects: Vec<usize>,
    pub fruit: Vec<usize>,
    pub hinge: [f64; 3],
}

/// The end of a cylinder on its local -z axis (where a rachis meets the stem).
fn base_of(o: &Object) -> Option<[f64; 3]> {
    end_of(o, -1.0)
}

/// The end of a cylinder on its local z axis in direction `sign`.
fn end_of(o: &Object, sign: f64) -> Option<[f64; 3]> {
    match o.shape {
        Shape::Cylinder { half_height, .. } => Some(o.placement.transform_point([0.0, 0.0, sign * half_height])),
        _ => None,
    }
}

/// The pedicels of `truss` (one of [`trusses`]): each pedicel (`{plant}/pedicel{t}_{f}`, a
/// rod whose local +z end is at the rachis) hinged there, with its fruit (`{plant}/fruit{t}_{f}`).
pub fn pedicels(objects: &[Object], truss: &Hinged) -> Vec<Hinged> {
    let fruit_of = |pedicel: &str| {
        let fruit = pedicel.replacen("/pedicel", "/fruit", 1);
        truss.fruit.iter().copied().filter(|&f| objects[f].name == fruit).collect()
    };
    truss.objects[1..]
        .iter()
        .filter_map(|&o| {
            let hinge = end_of(&objects[o], 1.0)?;
            Some(Hinged { part: Part::Pedicel, objects: vec![o], fruit: fruit_of(&objects[o].name), hinge })
        })
        .collect()
}

/// Every compound leaf of `objects`: a rachis (`.../leaf{k}`, a cylinder whose local -z end
/// is the petiole's base) and the leaflets named after it (`.../leaf{k}_{j}`), in object order.
pub fn leaves(objects: &[Object]) -> Vec<Hinged> {
    let mut out: Vec<Hinged> = Vec::new();
    let mut rachis_name = String::new();
    for (i, o) in objects.iter().enumerate() {
        if o.kind != Kind::Leaf {
            continue;
        }
        match base_of(o) {
            Some(hinge) => {
                out.push(Hinged { part: Part::Leaf, objects: vec![i], fruit: vec![], hinge });
                rachis_name = format!("{}_", o.name);
            }
            None if !rachis_name.is_empty() && o.name.starts_with(&rachis_name) => {
                if let Some(l) = out.last_mut() {
                    l.objects.push(i);
                }
            }
            None => {}
        }
    }
    out
}

/// Every truss of `objects`: a rachis (`{plant}/truss{t}`, a cylinder whose local -z end is
/// at the stem) and, in the objects that follow it, its pedicels (`{plant}/pedicel{t}_{f}`)
/// and fruit (`{plant}/fruit{t}_{f}`), as the scene generator grows them.
pub fn trusses(objects: &[Object]) -> Vec<Hinged> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < objects.len() {
        let o = &objects[i];
        let split =
            o.name.rsplit_once("/truss").filter(|(_, t)| !t.is_empty() && t.bytes().all(|b| b.is_ascii_digit()));
        let (Kind::Truss, Some((plant, t)), Some(hinge)) = (o.kind, split, base_of(o)) else {
            i += 1;
            continue;
        };
        let (pedicel, fruit) = (format!("{plant}/pedicel{t}_"), format!("{plant}/fruit{t}_"));
        let mut truss = Hinged { part: Part::Truss, objects: vec![i], fruit: vec![], hinge };
        i += 1;
        while let Some(o) = objects.get(i) {
            match o.kind {
                Kind::Truss if o.name.starts_with(&pedicel) => truss.objects.push(i),
                Kind::Fruit { .. } if o.name.starts_with(&fruit) => truss.fruit.push(i),
                _ => break,
            }
            i += 1;
        }
        out.push(truss);
    }
    out
}

/// A part the robot has moved and that is not at rest yet.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LeafState {
    /// Rotation vector from the grown pose [rad] and its rate [rad/s].
    pub theta: [f64; 3],
    pub rate: [f64; 3],
}

/// The moving leaves and trusses and what pushing them has cost.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Foliage {
    /// By part index (into [`FoliageTable::parts`]).
    pub moving: BTreeMap<usize, LeafState>,
    /// Leaves the robot moved from rest (a leaf pushed again before it came to rest counts once).
    pub pushes: u64,
    /// The largest force the robot spent holding a leaf turned [N].
    pub peak_force: f64,
    /// The same for trusses.
    pub truss_pushes: u64,
    pub peak_truss_force: f64,
}

/// The static per-scene data: leaves, trusses and their pedicels, the part of each static
/// object, each such object's grown pose, and each part's fruit with their grown poses.
#[derive(Clone, Debug, Default)]
pub struct FoliageTable {
    /// The leaves, then the trusses, then the pedicels. A truss lists its pedicels and fruit
    /// too (all that turns with it).
    pub parts: Vec<Hinged>,
    /// By part: the truss a pedicel hangs from.
    parent: Vec<Option<usize>>,
    /// By part: a truss's pedicels.
    children: Vec<Vec<usize>>,
    /// Part index by object index (sorted by object): a pedicel's own part, not its truss.
    of_object: Vec<(usize, usize)>,
    /// Grown collider pose of each part's objects, by object index (sorted).
    rest: Vec<(usize, RPose)>,
    /// By part: the fruit (fruit-list index) that hang from it directly (a truss: those
    /// without a pedicel), and their grown body poses.
    hanging: Vec<Vec<(usize, Pose)>>,
}

impl FoliageTable {
    pub fn new(objects: &[Object], world: &SceneWorld) -> FoliageTable {
        let mut parts = leaves(objects);
        let trusses = trusses(objects);
        let first = parts.len();
        parts.extend(trusses.iter().cloned());
        let mut parent = vec![None; parts.len()];
        let mut children = vec![vec![]; parts.len()];
        for (k, truss) in trusses.iter().enumerate() {
            for p in pedicels(objects, truss) {
                children[first + k].push(parts.len());
                parent.push(Some(first + k));
                children.push(vec![]);
                parts.push(p);
            }
        }
        // Later parts win: a pedicel object is its pedicel's, not its truss's.
        let mut of_object = BTreeMap::new();
        let mut rest = BTreeMap::new();
        for (l, part) in parts.iter().enumerate() {
            for &o in &part.objects {
                of_object.insert(o, l);
                rest.insert(o, from_rapier(world.colliders[world.objects[o].collider].position()));
            }
        }
        let hanging = parts
            .iter()
            .enumerate()
            .map(|(l, part)| {
                let on_child = |o: &usize| children[l].iter().any(|&c| parts[c].fruit.contains(o));
                let fruit = part.fruit.iter().filter(|o| !on_child(o)).filter_map(|&o| world.fruit_of_object(o));
                fruit.map(|f| (f, world.fruit_pose(f))).collect()
            })
            .collect();
        FoliageTable {
            parts,
            parent,
            children,
            of_object: of_object.into_iter().collect(),
            rest: rest.into_iter().collect(),
            hanging,
        }
    }

    /// The part (leaf or truss) an object belongs to.
    pub fn part_of(&self, object: usize) -> Option<usize> {
        self.of_object.binary_search_by_key(&object, |e| e.0).ok().map(|k| self.of_object[k].1)
    }

    fn rest(&self, object: usize) -> &RPose {
        &self.rest[self.rest.binary_search_by_key(&object, |r| r.0).expect("a leaf or truss object")].1
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
    /// How many parts of this kind are off their grown pose.
    pub fn moving_of(&self, table: &FoliageTable, part: Part) -> usize {
        self.moving.keys().filter(|&&l| table.parts[l].part == part).count()
    }

    /// One step of `h` seconds: `presses` of robot parts move the leaves and trusses they
    /// touch, free ones swing back; the moved parts' colliders are put at their new poses,
    /// and a truss's fruit with it while `hangs(fruit)` (fruit-list index) says the fruit
    /// hangs free on its plant. Returns whether any collider moved.
    pub fn step(
        &mut self,
        table: &FoliageTable,
        world: &mut SceneWorld,
        presses: &[Press],
        p: &FoliageParams,
        h: f64,
        hangs: impl Fn(usize) -> bool,
    ) -> bool {
        if !p.leaf.enabled && !p.truss.enabled {
            return false;
        }
        // Presses by part: the largest turn and its lever arm.
        let mut turns: BTreeMap<usize, ([f64; 3], f64)> = BTreeMap::new();
        for c in presses {
            let Some(l) = table.part_of(c.object) else { continue };
            if !p.of(table.parts[l].part).enabled {
                continue;
            }
            // A pedicel turns in its truss's frame, about its hinge where the truss put it.
            let frame = table.parent[l].map_or(RPose::IDENTITY, |t| about(table, &self.moving, t));
            let r = sub(c.point, frame.transform_point(table.parts[l].hinge));
            let arm = dot(r, r).sqrt().max(MIN_ARM);
            let turn = frame.inverse().rotate(scale(cross(r, scale(c.normal, -1.0)), c.depth / (arm * arm)));
            if turns.get(&l).is_none_or(|&(t, _)| norm(turn) > norm(t)) {
                turns.insert(l, (turn, arm));
            }
        }
        let mut moved = Vec::new();
        for (&l, &(turn, arm)) in &turns {
            let part = table.parts[l].part;
            let new = !self.moving.contains_key(&l);
            let s = self.moving.entry(l).or_default();
            let before = s.theta;
            s.theta = clamp_angle(add(s.theta, turn));
            s.rate = scale(sub(s.theta, before), 1.0 / h);
            let force = p.of(part).stiffness * norm(s.theta) / arm;
            let (pushes, peak) = match part {
                Part::Leaf => (&mut self.pushes, &mut self.peak_force),
                Part::Truss | Part::Pedicel => (&mut self.truss_pushes, &mut self.peak_truss_force),
            };
            *pushes += new as u64;
            *peak = peak.max(force);
            moved.push(l);
        }
        let mut rested = Vec::new();
        for (&l, s) in self.moving.iter_mut() {
            if turns.contains_key(&l) {
                continue;
            }
            let sp = p.of(table.parts[l].part);
            let w = 2.0 * std::f64::consts::PI * sp.frequency;
            // Semi-implicit Euler: the rate first, then the angle with the new rate.
            let acc = sub(scale(s.theta, -w * w), scale(s.rate, 2.0 * sp.damping_ratio * w));
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
            place(table, &self.moving, world, l, &hangs);
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

/// Part `l`'s displacement from its grown pose: its turn about its hinge, after its truss's
/// for a pedicel. Identity at rest.
fn about(table: &FoliageTable, moving: &BTreeMap<usize, LeafState>, l: usize) -> RPose {
    let hinge = table.parts[l].hinge;
    let own = match moving.get(&l) {
        Some(s) => {
            RPose::from_translation(hinge).mul(&rotation(s.theta)).mul(&RPose::from_translation(scale(hinge, -1.0)))
        }
        None => RPose::IDENTITY,
    };
    match table.parent[l] {
        Some(t) => about(table, moving, t).mul(&own),
        None => own,
    }
}

/// Whether part `l` or the truss it hangs from is off its grown pose.
fn off_rest(table: &FoliageTable, moving: &BTreeMap<usize, LeafState>, l: usize) -> bool {
    moving.contains_key(&l) || table.parent[l].is_some_and(|t| moving.contains_key(&t))
}

/// Puts part `l`'s colliders where `moving` turns them (a truss's pedicels each by its own
/// turn too), and the fruit that hang free from them: a fruit at rest exactly at its grown
/// pose, so that `moved_objects` no longer lists it.
fn place(
    table: &FoliageTable,
    moving: &BTreeMap<usize, LeafState>,
    world: &mut SceneWorld,
    l: usize,
    hangs: &impl Fn(usize) -> bool,
) {
    // The part and its pedicels, each displacement computed once.
    let shown: Vec<(usize, RPose)> =
        std::iter::once(l).chain(table.children[l].iter().copied()).map(|k| (k, about(table, moving, k))).collect();
    let at = |k: usize| shown.iter().find(|s| s.0 == k).map_or_else(|| about(table, moving, k), |s| s.1);
    for &o in &table.parts[l].objects {
        let pose = to_rapier(&at(table.part_of(o).unwrap_or(l)).mul(table.rest(o)));
        let handle = world.objects[o].collider;
        world.colliders[handle].set_position(pose);
    }
    for &(k, at) in &shown {
        let off = off_rest(table, moving, k);
        for &(f, grown) in &table.hanging[k] {
            if hangs(f) {
                let pose = if off { to_rapier(&at.mul(&from_rapier(&grown))) } else { grown };
                let body = world.fruit[f].body;
                world.bodies[body].set_position(pose, true);
            }
        }
    }
}
