//! Minimum clearance: the distance from the robot base box to the nearest scene object that
//! reaches into the base's height band (what the navigation benchmark scores). Objects wholly
//! above or below the band (gutters, high leaves, the floor) cannot be driven into and do not
//! count.
//!
//! A best-first search of rapier's broad-phase tree: a node's AABB distance to the robot's AABB
//! bounds every distance below it, so only the few nearest objects get an exact parry distance.

use crate::scene_world::{is_ground, SceneWorld};
use rapier3d::parry::bounding_volume::Aabb;
use rapier3d::parry::query;
use rapier3d::prelude::Real;

/// Distance [m] from the robot to the nearest object overlapping `band` (z range) in height,
/// or `cap` when none is nearer than `cap`.
pub fn min_clearance(world: &SceneWorld, band: [f64; 2], cap: f64) -> f64 {
    let robot_pose = world.robot_pose();
    let shape = &*world.robot.shape;
    let robot_aabb = shape.compute_aabb(&robot_pose);
    let (z_lo, z_hi) = (band[0] as Real, band[1] as Real);
    let in_band = |aabb: &Aabb| aabb.mins.z <= z_hi && aabb.maxs.z >= z_lo;
    let qp = world.query_pipeline();
    let best = qp.bvh.find_best(
        cap as Real,
        |node, _| {
            let aabb = node.aabb();
            if in_band(&aabb) {
                aabb_distance(&robot_aabb, &aabb)
            } else {
                Real::MAX
            }
        },
        |leaf, _| {
            let (collider, _) = qp.colliders.get_unknown_gen(leaf)?;
            let object = world.object_of(collider)?;
            if is_ground(world.objects[object].kind) || !in_band(&collider.compute_aabb()) {
                return None;
            }
            query::distance(&robot_pose, shape, collider.position(), collider.shape()).ok().map(|d| d.distance)
        },
    );
    best.map_or(cap, |(_, d)| (d as f64).min(cap))
}

/// Euclidean distance between two AABBs (0 when they overlap).
fn aabb_distance(a: &Aabb, b: &Aabb) -> Real {
    let gap = (a.mins - b.maxs).max(b.mins - a.maxs).max(rapier3d::prelude::Vector::ZERO);
    gap.length()
}
