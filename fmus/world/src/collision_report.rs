//! The `agrisim_msgs/CollisionState` message: the current contacts with the object's id, name
//! and kind, so a benchmark can tell "hit a post" from "brushed a leaf".

use crate::contacts::RobotContact;
use crate::geometry::{point_msg, vector_msg};
use crate::scene_world::SceneWorld;
use agrisim_greenhouse::scene::Kind;
use agrisim_msgs::agrisim::{CollisionState, Contact};
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::std_msgs::Header;

/// The robot link every contact is reported on until the arm links join the world.
pub const BASE_LINK: &str = "base_link";

/// Stable lower-case label of a kind (the `object_kind` field).
pub fn kind_label(kind: Kind) -> &'static str {
    match kind {
        Kind::Floor => "floor",
        Kind::Wall => "wall",
        Kind::Roof => "roof",
        Kind::Post => "post",
        Kind::Gutter => "gutter",
        Kind::HeatingPipe => "heating_pipe",
        Kind::Stem => "stem",
        Kind::Leaf => "leaf",
        Kind::Truss => "truss",
        Kind::Fruit { .. } => "fruit",
        Kind::Obstacle => "obstacle",
        Kind::Robot => "robot",
    }
}

/// The collision state at `stamp_ns`, frame `map` (`count` = number of contacts).
pub fn collision_state(world: &SceneWorld, contacts: &[RobotContact], stamp_ns: i64) -> CollisionState {
    CollisionState {
        header: Header::new(Time::from_nanos(stamp_ns), "map"),
        in_collision: !contacts.is_empty(),
        count: contacts.len() as u32,
        contacts: contacts
            .iter()
            .map(|c| {
                let o = &world.objects[c.object];
                Contact {
                    object_id: o.id,
                    object_name: o.name.clone(),
                    object_kind: kind_label(o.kind).to_string(),
                    robot_link: BASE_LINK.to_string(),
                    position: point_msg(c.point),
                    normal: vector_msg(c.normal),
                    depth: c.depth as f64,
                }
            })
            .collect(),
    }
}
