//! Robot contacts: which scene objects (and which links of the other arm) each robot part,
//! and each fruit a gripper holds, touches or penetrates now, where and how deep, sorted
//! into the categories a benchmark scores; and the bookkeeping that turns successive
//! contact sets into onsets.
//!
//! Exact parry contact queries on the broad-phase candidates, rather than rapier's narrow
//! phase: kinematic robot parts against fixed scene objects generate no solver contacts, and
//! a query gives map-frame points and normals directly.
//!
//! Categories:
//! - **plant**: stems, leaves, trusses and fruit on the crop (on a plant or dropped).
//!   Brushing leaves is expected while harvesting: counted, not a failure.
//! - **structure**: everything else in the house (posts, gutters, heating pipes, walls, roof,
//!   obstacles, and the floor for every link; the base box's own bottom is its ride height
//!   and does not count). A benchmark failure.
//! - **arm_arm**: a left-arm link (hand and fingers included) against a right-arm link.
//!   A benchmark failure.
//! - **carried_structure**: a fruit held by a gripper against the structure (floor included):
//!   the robot swung its load into the house. Not against the plant: a picked fruit starts
//!   among its truss and neighbours, so that would count every pick.
//!
//! Otherwise the robot's load is no contact: touching a carried, falling or placed fruit
//! does not count, nor does what a falling or placed fruit touches.

use crate::harvest::Harvest;
use crate::robot_model::Side;
use crate::robot_parts::Group;
use crate::scene_world::{is_ground, SceneWorld};
use agrisim_scene::scene::Kind;
use rapier3d::parry::bounding_volume::{Aabb, BoundingVolume};
use rapier3d::parry::query;
use rapier3d::prelude::{Collider, Real, Vector};

/// What a robot part or carried fruit touches.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, serde::Serialize, serde::Deserialize)]
pub enum Other {
    /// Index into [`SceneWorld::objects`].
    Object(usize),
    /// A right-arm part (the touching part is a left-arm one).
    Part(usize),
}

/// What touches: a robot part or the robot's load.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, serde::Serialize, serde::Deserialize)]
pub enum Toucher {
    /// Index into [`SceneWorld::parts`] (0 = the base box).
    Part(usize),
    /// Index into [`SceneWorld::fruit`] of a fruit a gripper holds.
    Carried(usize),
}

/// Discriminants index [`ContactTracker`]'s onset counters (new categories go last).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, serde::Serialize, serde::Deserialize)]
pub enum Category {
    Plant,
    Structure,
    ArmArm,
    CarriedStructure,
}

const CATEGORIES: usize = 4;

/// One robot contact in the map frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RobotContact {
    pub toucher: Toucher,
    pub other: Other,
    pub category: Category,
    /// Deepest point on the other's surface.
    pub point: Vector,
    /// The other's outward surface normal there: the direction that separates the toucher.
    pub normal: Vector,
    /// Penetration depth (0 when just touching).
    pub depth: Real,
}

/// A robot part pressing a scene object, in f64: the object, the contact point, the object's
/// outward normal there and the depth. What the plant models (stems, leaves) take from a
/// contact; a carried fruit's contacts are none (they are the structure's).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Press {
    pub object: usize,
    pub point: [f64; 3],
    pub normal: [f64; 3],
    pub depth: f64,
}

impl RobotContact {
    /// This contact as a press of a robot part on a scene object, if it is one.
    pub fn press(&self) -> Option<Press> {
        let (Toucher::Part(_), Other::Object(object)) = (self.toucher, self.other) else { return None };
        let v = |v: Vector| [v.x as f64, v.y as f64, v.z as f64];
        Some(Press { object, point: v(self.point), normal: v(self.normal), depth: self.depth as f64 })
    }
}

pub fn category_of(kind: Kind) -> Category {
    match kind {
        Kind::Stem | Kind::Leaf | Kind::Truss | Kind::Fruit { .. } => Category::Plant,
        _ => Category::Structure,
    }
}

/// Every contact of every robot part and carried fruit, sorted by (toucher, other).
///
/// One broad-phase query with the AABB of the whole robot and its load gives the candidate
/// objects (in an aisle: only the floor); each toucher is then tested against those whose
/// AABB it overlaps.
pub fn robot_contacts(world: &SceneWorld, harvest: &Harvest) -> Vec<RobotContact> {
    let aabbs: Vec<Aabb> = world.parts.iter().map(|p| world.colliders[p.collider].compute_aabb()).collect();
    let carried: Vec<(usize, &Collider, Aabb)> = harvest
        .carried()
        .map(|f| {
            let c = &world.colliders[world.objects[world.fruit[f].object].collider];
            (f, c, c.compute_aabb())
        })
        .collect();
    let boxes = aabbs.iter().chain(carried.iter().map(|c| &c.2));
    let Some(all) = boxes.copied().reduce(|a, b| a.merged(&b)) else { return Vec::new() };
    let qp = world.query_pipeline();
    let mut candidates: Vec<(usize, &Collider, Aabb)> = Vec::new();
    for (_, other) in qp.intersect_aabb_conservative(all) {
        let Some(object) = world.object_of(other) else { continue };
        if let Some(f) = world.fruit_of_object(object) {
            if !harvest.counts_as_plant(f) {
                continue;
            }
        }
        candidates.push((object, other, other.compute_aabb()));
    }
    let mut out = Vec::new();
    for (p, part) in world.parts.iter().enumerate() {
        let collider = &world.colliders[part.collider];
        for &(object, other, ref aabb) in &candidates {
            let kind = world.objects[object].kind;
            if (is_ground(kind) && !part.floor_counts) || !aabbs[p].intersects(aabb) {
                continue;
            }
            out.extend(contact(Toucher::Part(p), collider, Other::Object(object), other, category_of(kind)));
        }
    }
    for &(f, fruit, ref fruit_aabb) in &carried {
        for &(object, other, ref aabb) in &candidates {
            if category_of(world.objects[object].kind) == Category::Structure && fruit_aabb.intersects(aabb) {
                out.extend(contact(
                    Toucher::Carried(f),
                    fruit,
                    Other::Object(object),
                    other,
                    Category::CarriedStructure,
                ));
            }
        }
    }
    arm_arm_contacts(world, &aabbs, &mut out);
    out.sort_by_key(|c| (c.toucher, c.other));
    out
}

/// The contact of `a` (the toucher) with `b`, if they touch or overlap.
fn contact(toucher: Toucher, a: &Collider, other: Other, b: &Collider, category: Category) -> Option<RobotContact> {
    // Both shapes are parry primitives, which `contact` always supports.
    let c = query::contact(a.position(), a.shape(), b.position(), b.shape(), 0.0).ok()??;
    Some(RobotContact { toucher, other, category, point: c.point2, normal: c.normal2, depth: (-c.dist).max(0.0) })
}

/// Left-arm parts against right-arm parts (AABB test first: most pairs are far apart).
fn arm_arm_contacts(world: &SceneWorld, aabbs: &[Aabb], out: &mut Vec<RobotContact>) {
    let arm = |side| {
        world
            .parts
            .iter()
            .enumerate()
            .filter(move |(_, p)| p.group == Group::Arm(side))
            .map(|(i, p)| (i, &world.colliders[p.collider], aabbs[i]))
            .collect::<Vec<_>>()
    };
    let (left, right) = (arm(Side::Left), arm(Side::Right));
    for (i, a, aabb_a) in &left {
        for (j, b, aabb_b) in &right {
            if !aabb_a.intersects(aabb_b) {
                continue;
            }
            out.extend(contact(Toucher::Part(*i), a, Other::Part(*j), b, Category::ArmArm));
        }
    }
}

/// Remembers the last contact set to count onsets per category and notice changes.
///
/// An onset is a new thing in contact: for plant and structure a scene object that no robot
/// part touched the step before, for carried-structure one that no carried fruit touched; for
/// arm-arm a (left link part, right link part) pair that was not in contact. So a leaf pressed
/// by the base box and then also by an arm is one onset; touching it again after letting go
/// is another.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ContactTracker {
    /// (category, toucher, other) in contact, sorted: contacts with objects are keyed by the
    /// object alone (toucher None), arm-arm ones by both parts.
    touching: Vec<(Category, Option<Toucher>, Other)>,
    /// (toucher, other) pairs of the last step: a change publishes collision_state.
    pairs: Vec<(Toucher, Other)>,
    onsets: [u64; CATEGORIES],
}

impl ContactTracker {
    /// Takes the new contact set (sorted by toucher, other); returns whether it differs from the last.
    pub fn update(&mut self, contacts: &[RobotContact]) -> bool {
        let mut now: Vec<(Category, Option<Toucher>, Other)> = contacts
            .iter()
            .map(|c| match c.other {
                Other::Object(_) => (c.category, None, c.other),
                Other::Part(_) => (c.category, Some(c.toucher), c.other),
            })
            .collect();
        now.sort();
        now.dedup();
        for key in &now {
            if self.touching.binary_search(key).is_err() {
                self.onsets[key.0 as usize] += 1;
            }
        }
        self.touching = now;
        let pairs: Vec<(Toucher, Other)> = contacts.iter().map(|c| (c.toucher, c.other)).collect();
        let changed = pairs != self.pairs;
        self.pairs = pairs;
        changed
    }

    /// Cumulative onsets in a category.
    pub fn onsets_in(&self, category: Category) -> u64 {
        self.onsets[category as usize]
    }

    /// Cumulative onsets over all categories.
    pub fn onsets(&self) -> u64 {
        self.onsets.iter().sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(part: usize, object: usize, category: Category) -> RobotContact {
        RobotContact {
            toucher: Toucher::Part(part),
            other: Other::Object(object),
            category,
            point: Vector::ZERO,
            normal: Vector::X,
            depth: 0.0,
        }
    }

    #[test]
    fn onsets_count_objects_entering_contact() {
        let s = Category::Structure;
        let mut t = ContactTracker::default();
        assert!(!t.update(&[]));
        assert!(t.update(&[c(0, 3, s)]));
        assert!(!t.update(&[c(0, 3, s)]), "a lasting contact is no new onset");
        assert!(t.update(&[c(0, 3, s), c(0, 7, s)]));
        assert!(t.update(&[c(0, 3, s), c(0, 7, s), c(4, 7, s)]), "another part on the same object: a change");
        assert!(t.update(&[c(0, 7, s)]));
        assert!(t.update(&[]));
        assert!(t.update(&[c(0, 3, s)]), "touching again is a new onset");
        assert_eq!(t.onsets(), 3);
        assert_eq!(t.onsets_in(s), 3);
    }

    #[test]
    fn categories_are_counted_apart() {
        let mut t = ContactTracker::default();
        let arm = RobotContact {
            toucher: Toucher::Part(5),
            other: Other::Part(20),
            category: Category::ArmArm,
            point: Vector::ZERO,
            normal: Vector::X,
            depth: 0.0,
        };
        t.update(&[c(0, 1, Category::Plant), arm]);
        t.update(&[c(0, 1, Category::Plant), c(2, 9, Category::Structure)]);
        t.update(&[arm, RobotContact { other: Other::Part(21), ..arm }]);
        assert_eq!(
            [t.onsets_in(Category::Plant), t.onsets_in(Category::Structure), t.onsets_in(Category::ArmArm)],
            [1, 1, 3]
        );
    }

    #[test]
    fn carried_structure_onsets_are_counted_apart() {
        let (s, cs) = (Category::Structure, Category::CarriedStructure);
        let fruit = |f: usize, object: usize| RobotContact { toucher: Toucher::Carried(f), ..c(0, object, cs) };
        let mut t = ContactTracker::default();
        assert!(t.update(&[fruit(2, 7)]));
        assert!(!t.update(&[fruit(2, 7)]), "a lasting contact is no new onset");
        // The hand follows its fruit onto the post: a robot-structure onset of its own.
        assert!(t.update(&[c(4, 7, s), fruit(2, 7)]));
        assert!(t.update(&[c(4, 7, s), fruit(2, 7), fruit(5, 7)]), "another carried fruit on the same post: a change");
        // Across an FMU state save and restore.
        let mut bytes = Vec::new();
        agrisim_fmi::serial::write(&t, &mut bytes).unwrap();
        let mut t: ContactTracker = agrisim_fmi::serial::read(&bytes).unwrap();
        assert!(t.update(&[fruit(2, 9)]), "another object");
        assert!(t.update(&[]));
        assert!(t.update(&[fruit(5, 9)]), "touching again is a new onset");
        let counts = [Category::Plant, s, Category::ArmArm, cs].map(|k| t.onsets_in(k));
        assert_eq!(counts, [0, 1, 0, 3]);
        assert_eq!(t.onsets(), 4);
    }
}
