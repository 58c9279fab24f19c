//! Robot contacts: which scene objects (and which links of the other arm) each robot part
//! touches or penetrates now, where and how deep, sorted into the categories a benchmark
//! scores; and the bookkeeping that turns successive contact sets into onsets.
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
//!
//! Fruit being carried, falling or placed in the box are the robot's load: not contacts.

use crate::harvest::Harvest;
use crate::robot_model::Side;
use crate::robot_parts::Group;
use crate::scene_world::{is_ground, SceneWorld};
use agrisim_greenhouse::scene::Kind;
use rapier3d::parry::bounding_volume::{Aabb, BoundingVolume};
use rapier3d::parry::query;
use rapier3d::prelude::{Collider, Real, Vector};

/// What a robot part touches.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, serde::Serialize, serde::Deserialize)]
pub enum Other {
    /// Index into [`SceneWorld::objects`].
    Object(usize),
    /// A right-arm part (the touching part is a left-arm one).
    Part(usize),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, serde::Serialize, serde::Deserialize)]
pub enum Category {
    Plant,
    Structure,
    ArmArm,
}

/// One robot contact in the map frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RobotContact {
    /// Index into [`SceneWorld::parts`] (0 = the base box).
    pub part: usize,
    pub other: Other,
    pub category: Category,
    /// Deepest point on the other's surface.
    pub point: Vector,
    /// The other's outward surface normal there: the direction that separates the robot part.
    pub normal: Vector,
    /// Penetration depth (0 when just touching).
    pub depth: Real,
}

pub fn category_of(kind: Kind) -> Category {
    match kind {
        Kind::Stem | Kind::Leaf | Kind::Truss | Kind::Fruit { .. } => Category::Plant,
        _ => Category::Structure,
    }
}

/// Every contact of every robot part, sorted by (part, other).
///
/// One broad-phase query with the whole robot's AABB gives the candidate objects (in an
/// aisle: only the floor); each part is then tested against those whose AABB it overlaps.
pub fn robot_contacts(world: &SceneWorld, harvest: &Harvest) -> Vec<RobotContact> {
    let aabbs: Vec<Aabb> = world.parts.iter().map(|p| world.colliders[p.collider].compute_aabb()).collect();
    let Some(all) = aabbs.iter().copied().reduce(|a, b| a.merged(&b)) else { return Vec::new() };
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
        let (pose, shape) = (collider.position(), collider.shape());
        for &(object, other, ref aabb) in &candidates {
            let kind = world.objects[object].kind;
            if (is_ground(kind) && !part.floor_counts) || !aabbs[p].intersects(aabb) {
                continue;
            }
            // Both shapes are parry primitives, which `contact` always supports.
            if let Ok(Some(c)) = query::contact(pose, shape, other.position(), other.shape(), 0.0) {
                out.push(RobotContact {
                    part: p,
                    other: Other::Object(object),
                    category: category_of(kind),
                    point: c.point2,
                    normal: c.normal2,
                    depth: (-c.dist).max(0.0),
                });
            }
        }
    }
    arm_arm_contacts(world, &aabbs, &mut out);
    out.sort_by_key(|c| (c.part, c.other));
    out
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
            if let Ok(Some(c)) = query::contact(a.position(), a.shape(), b.position(), b.shape(), 0.0) {
                out.push(RobotContact {
                    part: *i,
                    other: Other::Part(*j),
                    category: Category::ArmArm,
                    point: c.point2,
                    normal: c.normal2,
                    depth: (-c.dist).max(0.0),
                });
            }
        }
    }
}

/// Remembers the last contact set to count onsets per category and notice changes.
///
/// An onset is a new thing in contact: for plant and structure a scene object that no robot
/// part touched the step before; for arm-arm a (left link part, right link part) pair that
/// was not in contact. So a leaf pressed by the base box and then also by an arm is one
/// onset; touching it again after letting go is another.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ContactTracker {
    /// (category, robot part or 0, other) in contact, sorted: plant and structure contacts
    /// are keyed by the object alone, arm-arm ones by both parts.
    touching: Vec<(Category, usize, Other)>,
    /// (part, other) pairs of the last step: a change publishes collision_state.
    pairs: Vec<(usize, Other)>,
    onsets: [u64; 3],
}

impl ContactTracker {
    /// Takes the new contact set (sorted by part, other); returns whether it differs from the last.
    pub fn update(&mut self, contacts: &[RobotContact]) -> bool {
        let mut now: Vec<(Category, usize, Other)> = contacts
            .iter()
            .map(|c| match c.other {
                Other::Object(_) => (c.category, 0, c.other),
                Other::Part(_) => (c.category, c.part, c.other),
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
        let pairs: Vec<(usize, Other)> = contacts.iter().map(|c| (c.part, c.other)).collect();
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
        RobotContact { part, other: Other::Object(object), category, point: Vector::ZERO, normal: Vector::X, depth: 0.0 }
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
        let arm = RobotContact { part: 5, other: Other::Part(20), category: Category::ArmArm, point: Vector::ZERO, normal: Vector::X, depth: 0.0 };
        t.update(&[c(0, 1, Category::Plant), arm]);
        t.update(&[c(0, 1, Category::Plant), c(2, 9, Category::Structure)]);
        t.update(&[arm, RobotContact { other: Other::Part(21), ..arm }]);
        assert_eq!([t.onsets_in(Category::Plant), t.onsets_in(Category::Structure), t.onsets_in(Category::ArmArm)], [1, 1, 3]);
    }
}
