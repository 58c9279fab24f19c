//! Robot-scene contacts: which objects the robot touches or penetrates now, where, and how
//! deep; and the bookkeeping that turns successive contact sets into onsets.
//!
//! Exact parry contact queries on the broad-phase candidates, rather than rapier's narrow
//! phase: a kinematic robot against fixed scene objects generates no solver contacts, and a
//! query gives map-frame points and normals directly.

use crate::scene_world::{is_ground, SceneWorld};
use rapier3d::parry::query;
use rapier3d::prelude::{Real, Vector};

/// One robot-object contact in the map frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RobotContact {
    /// Index into [`SceneWorld::objects`].
    pub object: usize,
    /// Deepest point on the object's surface.
    pub point: Vector,
    /// The object's outward surface normal there: the direction that separates the robot.
    pub normal: Vector,
    /// Penetration depth (0 when just touching).
    pub depth: Real,
}

/// Every object the robot base touches (distance <= 0), ground excluded, sorted by object index.
pub fn robot_contacts(world: &SceneWorld) -> Vec<RobotContact> {
    let robot_pose = world.robot_pose();
    let shape = &*world.robot.shape;
    let qp = world.query_pipeline();
    let mut out = Vec::new();
    for (_, collider) in qp.intersect_aabb_conservative(shape.compute_aabb(&robot_pose)) {
        let Some(object) = world.object_of(collider) else { continue };
        if is_ground(world.objects[object].kind) {
            continue;
        }
        // Both shapes are parry primitives, which `contact` always supports.
        if let Ok(Some(c)) = query::contact(&robot_pose, shape, collider.position(), collider.shape(), 0.0) {
            out.push(RobotContact { object, point: c.point2, normal: c.normal2, depth: (-c.dist).max(0.0) });
        }
    }
    out.sort_by_key(|c| c.object);
    out
}

/// Remembers the last contact set to count onsets and notice changes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ContactTracker {
    touching: Vec<usize>,
    onsets: u64,
}

impl ContactTracker {
    /// Takes the new contact set (sorted by object); returns whether it differs from the last.
    /// Every object that was not touching before is one onset.
    pub fn update(&mut self, contacts: &[RobotContact]) -> bool {
        let now: Vec<usize> = contacts.iter().map(|c| c.object).collect();
        let new = now.iter().filter(|o| self.touching.binary_search(o).is_err()).count();
        self.onsets += new as u64;
        let changed = now != self.touching;
        self.touching = now;
        changed
    }

    /// Cumulative number of contact onsets.
    pub fn onsets(&self) -> u64 {
        self.onsets
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(object: usize) -> RobotContact {
        RobotContact { object, point: Vector::ZERO, normal: Vector::X, depth: 0.0 }
    }

    #[test]
    fn onsets_count_objects_entering_contact() {
        let mut t = ContactTracker::default();
        assert!(!t.update(&[]));
        assert!(t.update(&[c(3)]));
        assert!(!t.update(&[c(3)]), "a lasting contact is no new onset");
        assert!(t.update(&[c(3), c(7)]));
        assert!(t.update(&[c(7)]));
        assert!(t.update(&[]));
        assert!(t.update(&[c(3)]), "touching again is a new onset");
        assert_eq!(t.onsets(), 3);
    }
}
