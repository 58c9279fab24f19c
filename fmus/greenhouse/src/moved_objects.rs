//! Which scene objects are away from where the greenhouse grew them, and where they are: the
//! `moved_objects` output, which the sensor FMUs (camera, LiDAR) take so that they render a
//! pushed leaf where it is pushed to and a picked fruit in the gripper or the box, not where
//! the scene generator put it.
//!
//! Two kinds of objects ever move: the leaves and trusses the foliage model turns (a leaf's
//! rachis and leaflets, a truss's rachis and pedicels, while off their rest pose) and fruit
//! (a body that left its grown pose: on a turned truss, pulled on its pedicel, carried,
//! falling, boxed, dropped). Everything else is static, so
//! the list stays as short as what the robot touched.

use crate::foliage::{Foliage, FoliageTable};
use crate::geometry::{object_pose, pose_msg};
use crate::scene_world::SceneWorld;
use agrisim_msgs::agrisim::MovedObjects;
use agrisim_msgs::std_msgs::Header;
use rapier3d::prelude::Pose;

/// Each fruit body's pose as built (fruit-list order): a body whose pose differs has moved.
pub fn grown_fruit_poses(world: &SceneWorld) -> Vec<Pose> {
    (0..world.fruit.len()).map(|i| world.fruit_pose(i)).collect()
}

/// Every moved object (ids ascending) with its placement in the map frame; `header` left
/// default (the caller stamps it).
pub fn moved_objects(
    world: &SceneWorld,
    grown_fruit: &[Pose],
    table: &FoliageTable,
    foliage: &Foliage,
) -> MovedObjects {
    let mut moved: Vec<(u32, Pose)> = Vec::new();
    for &l in foliage.moving.keys() {
        for &o in &table.parts[l].objects {
            let object = &world.objects[o];
            moved.push((object.id, object_pose(&world.colliders[object.collider])));
        }
    }
    for (i, grown) in grown_fruit.iter().enumerate() {
        let pose = world.fruit_pose(i);
        if pose != *grown {
            moved.push((world.objects[world.fruit[i].object].id, pose));
        }
    }
    moved.sort_unstable_by_key(|m| m.0);
    // A pedicel turning with its truss and on its own is listed by both: once is enough.
    moved.dedup_by_key(|m| m.0);
    MovedObjects {
        header: Header::default(),
        ids: moved.iter().map(|m| m.0).collect(),
        poses: moved.iter().map(|m| pose_msg(&m.1)).collect(),
    }
}
