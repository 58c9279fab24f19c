//! The `agrisim_msgs/CollisionState` message: the current contacts with the object's id, name
//! and kind and the robot link, so a benchmark can tell "hit a post" from "brushed a leaf".
//!
//! Arm-arm contacts use the same fields: `robot_link` is the left-arm link, `object_name` the
//! right-arm link, `object_kind` is [`ARM_KIND`] and `object_id` is [`ARM_OBJECT_ID`] (no
//! scene object has it). A fruit a gripper holds that touches the structure has `robot_link`
//! [`CARRIED_LINK`] and the object's fields as usual. The category of a contact follows from
//! `object_kind` and `robot_link` (see [`crate::contacts`]).

use crate::contacts::{Other, RobotContact, Toucher};
use crate::geometry::{point_msg, vector_msg};
use crate::scene_world::SceneWorld;
use agrisim_msgs::agrisim::{CollisionState, Contact};
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::std_msgs::Header;
use agrisim_scene::scene::Kind;

/// `object_kind` of an arm-arm contact.
pub const ARM_KIND: &str = "robot_arm";
/// `object_id` of an arm-arm contact.
pub const ARM_OBJECT_ID: u32 = u32::MAX;
/// `robot_link` of a contact of a carried fruit (no URDF link has this name).
pub const CARRIED_LINK: &str = "carried_fruit";

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
                let (object_id, object_name, object_kind) = match c.other {
                    Other::Object(i) => {
                        let o = &world.objects[i];
                        (o.id, o.name.clone(), kind_label(o.kind).to_string())
                    }
                    Other::Part(j) => (ARM_OBJECT_ID, world.parts[j].link.clone(), ARM_KIND.to_string()),
                };
                Contact {
                    object_id,
                    object_name,
                    object_kind,
                    robot_link: match c.toucher {
                        Toucher::Part(p) => world.parts[p].link.clone(),
                        Toucher::Carried(_) => CARRIED_LINK.to_string(),
                    },
                    position: point_msg(c.point),
                    normal: vector_msg(c.normal),
                    depth: c.depth as f64,
                }
            })
            .collect(),
    }
}
