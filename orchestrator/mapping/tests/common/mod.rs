//! Helpers shared by the mapping crate's integration tests.

use agrisim_msgs::geometry_msgs::{Quaternion as Q, Transform, TransformStamped, Vector3};
use agrisim_msgs::std_msgs::Header;
use agrisim_msgs::tf2_msgs::TFMessage;
use nalgebra::Isometry3;

/// A /tf message with the one transform `parent` -> `child` at `pose`.
pub fn tf(parent: &str, child: &str, pose: &Isometry3<f64>) -> TFMessage {
    let (t, q) = (pose.translation.vector, pose.rotation.quaternion());
    TFMessage {
        transforms: vec![TransformStamped {
            header: Header { frame_id: parent.into(), ..Default::default() },
            child_frame_id: child.into(),
            transform: Transform {
                translation: Vector3 { x: t.x, y: t.y, z: t.z },
                rotation: Q { x: q.i, y: q.j, z: q.k, w: q.w },
            },
        }],
    }
}
