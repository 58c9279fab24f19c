//! Ground-truth fruit poses, read from the fruit bodies (so a picked or fallen fruit reports
//! where it really is), and the selected target fruit.

use crate::geometry::pose_msg;
use crate::scene_world::SceneWorld;
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::geometry_msgs::{PoseArray, PoseStamped};
use agrisim_msgs::std_msgs::Header;
use rapier3d::prelude::Pose;

/// Every fruit centre in fruit-list order, frame `map`.
pub fn fruit_poses(world: &SceneWorld, stamp_ns: i64) -> PoseArray {
    PoseArray {
        header: Header::new(Time::from_nanos(stamp_ns), "map"),
        poses: (0..world.fruit.len()).map(|i| pose_msg(&world.fruit_pose(i))).collect(),
    }
}

/// The fruit `target_fruit` selects, if it names one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Target {
    /// Scene object id.
    pub id: u32,
    pub pose: Pose,
}

impl Target {
    pub fn select(world: &SceneWorld, index: i32) -> Option<Target> {
        let i = usize::try_from(index).ok().filter(|&i| i < world.fruit.len())?;
        Some(Target { id: world.objects[world.fruit[i].object].id, pose: world.fruit_pose(i) })
    }

    pub fn message(&self, stamp_ns: i64) -> PoseStamped {
        PoseStamped { header: Header::new(Time::from_nanos(stamp_ns), "map"), pose: pose_msg(&self.pose) }
    }
}
