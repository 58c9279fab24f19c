//! The `agrisim_msgs/PlanningScene` message: the scene objects near the robot as primitives in
//! the map frame, from which the manipulation planner builds its collision world.
//!
//! Objects come from the rapier colliders (so fruit are where they are now), within `radius`
//! of base_link in the horizontal plane (nearest point of the object's bounding box). The
//! robot's own links are not listed: the planner has them from the URDF. `id` is the scene
//! object id in decimal (for fruit the id of `target_id`, `left_held_id`, ...); `kind` is the
//! collision-report kind label, with fruit refined by harvest state: `fruit` (on its plant or
//! dropped), `fruit_held`, `fruit_falling`, `fruit_placed`.

use crate::collision_report::kind_label;
use crate::geometry::{object_pose, pose_msg};
use crate::harvest::{FruitState, Harvest};
use crate::scene_world::SceneWorld;
use agrisim_msgs::agrisim::{CollisionObject, PlanningScene};
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::shape_msgs::SolidPrimitive;
use agrisim_msgs::std_msgs::Header;
use rapier3d::parry::bounding_volume::Aabb;
use rapier3d::prelude::*;

/// Objects whose bounding box comes within `radius` [m] (horizontally) of `centre` (x, y).
pub fn planning_scene(
    world: &SceneWorld,
    harvest: &Harvest,
    centre: [f64; 2],
    radius: f64,
    stamp_ns: i64,
) -> PlanningScene {
    let (cx, cy, r) = (centre[0] as Real, centre[1] as Real, radius as Real);
    let query = Aabb::new(Vector::new(cx - r, cy - r, -1e6), Vector::new(cx + r, cy + r, 1e6));
    let qp = world.query_pipeline();
    let mut found: Vec<usize> = Vec::new();
    for (_, collider) in qp.intersect_aabb_conservative(query) {
        let Some(object) = world.object_of(collider) else { continue };
        let aabb = collider.compute_aabb();
        let dx = (aabb.mins.x - cx).max(cx - aabb.maxs.x).max(0.0);
        let dy = (aabb.mins.y - cy).max(cy - aabb.maxs.y).max(0.0);
        if dx * dx + dy * dy <= r * r {
            found.push(object);
        }
    }
    found.sort_unstable();
    found.dedup();
    PlanningScene {
        header: Header::new(Time::from_nanos(stamp_ns), "map"),
        objects: found.into_iter().filter_map(|o| collision_object(world, harvest, o)).collect(),
    }
}

fn collision_object(world: &SceneWorld, harvest: &Harvest, object: usize) -> Option<CollisionObject> {
    let o = &world.objects[object];
    let collider = &world.colliders[o.collider];
    let shape = collider.shape();
    // parry cylinders run along y; the scene's (and SolidPrimitive's) along z: the object's
    // own pose undoes the quarter turn `geometry::shape_of` put in the collider's position.
    let pose = object_pose(collider);
    let primitive = if let Some(c) = shape.as_cuboid() {
        let h = c.half_extents;
        SolidPrimitive::new_box(2.0 * h.x as f64, 2.0 * h.y as f64, 2.0 * h.z as f64)
    } else if let Some(b) = shape.as_ball() {
        SolidPrimitive::sphere(b.radius as f64)
    } else if let Some(c) = shape.as_cylinder() {
        SolidPrimitive::cylinder(2.0 * c.half_height as f64, c.radius as f64)
    } else {
        return None;
    };
    let kind = match world.fruit_of_object(object).map(|f| harvest.state(f)) {
        Some(FruitState::Held { .. }) => "fruit_held",
        Some(FruitState::Falling { .. }) => "fruit_falling",
        Some(FruitState::Placed { .. }) => "fruit_placed",
        _ => kind_label(o.kind),
    };
    Some(CollisionObject { id: o.id.to_string(), kind: kind.to_string(), primitive, pose: pose_msg(&pose) })
}
