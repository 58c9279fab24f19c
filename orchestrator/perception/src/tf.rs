//! A small TF buffer: the latest transform of every child frame from /tf and /tf_static, and
//! look-ups between any two frames of the tree (like tf2's lookupTransform at the latest time).

use agrisim_msgs::geometry_msgs::TransformStamped;
use agrisim_msgs::tf2_msgs::TFMessage;
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};
use std::collections::BTreeMap;

#[derive(Default, Clone, Debug)]
pub struct TfBuffer {
    /// child -> (parent, child's pose in the parent).
    edges: BTreeMap<String, (String, Isometry3<f64>)>,
}

fn iso(t: &TransformStamped) -> Option<Isometry3<f64>> {
    let tr = &t.transform.translation;
    let q = &t.transform.rotation;
    let q = UnitQuaternion::try_new(Quaternion::new(q.w, q.x, q.y, q.z), 1e-9)?;
    let ok = [tr.x, tr.y, tr.z].iter().all(|v| v.is_finite());
    ok.then(|| Isometry3::from_parts(Translation3::new(tr.x, tr.y, tr.z), q))
}

impl TfBuffer {
    /// Adds every transform of a message; returns how many were unusable (a zero or
    /// non-finite rotation, a frame its own parent).
    pub fn add(&mut self, msg: &TFMessage) -> usize {
        let mut bad = 0;
        for t in &msg.transforms {
            let parent = t.header.frame_id.trim_start_matches('/');
            let child = t.child_frame_id.trim_start_matches('/');
            match iso(t) {
                Some(p) if parent != child && !parent.is_empty() && !child.is_empty() => {
                    self.edges.insert(child.to_string(), (parent.to_string(), p));
                }
                _ => bad += 1,
            }
        }
        bad
    }

    /// The frame's pose in its tree's root and the root's name (at most 64 hops).
    fn to_root(&self, frame: &str) -> (String, Isometry3<f64>) {
        let mut pose = Isometry3::identity();
        let mut f = frame.to_string();
        for _ in 0..64 {
            match self.edges.get(&f) {
                Some((parent, p)) => {
                    pose = p * pose;
                    f = parent.clone();
                }
                None => break,
            }
        }
        (f, pose)
    }

    /// Pose of `source` in `target` (maps points from source to target), if both are in one tree.
    pub fn lookup(&self, target: &str, source: &str) -> Option<Isometry3<f64>> {
        let (rs, ps) = self.to_root(source);
        let (rt, pt) = self.to_root(target);
        (rs == rt
            && (self.edges.contains_key(source) || source == rs)
            && (self.edges.contains_key(target) || target == rt))
            .then(|| pt.inverse() * ps)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use agrisim_msgs::geometry_msgs::{Quaternion as Q, Transform, Vector3};
    use agrisim_msgs::std_msgs::Header;
    use nalgebra::Point3;

    fn tf(parent: &str, child: &str, x: f64, yaw: f64) -> TransformStamped {
        TransformStamped {
            header: Header { frame_id: parent.into(), ..Default::default() },
            child_frame_id: child.into(),
            transform: Transform { translation: Vector3 { x, y: 0.0, z: 0.5 }, rotation: Q::from_yaw(yaw) },
        }
    }

    #[test]
    fn chains_and_inverts() {
        let mut b = TfBuffer::default();
        let bad = b.add(&TFMessage {
            transforms: vec![
                tf("map", "odom", 1.0, 0.0),
                tf("odom", "base_link", 2.0, std::f64::consts::FRAC_PI_2),
                tf("base_link", "cam", 0.3, 0.0),
            ],
        });
        assert_eq!(bad, 0);
        let p = b.lookup("map", "cam").unwrap() * Point3::origin();
        // cam at (0.3, 0, 0.5) in base_link, base turned 90 deg at (3, 0, 1): (3, 0.3, 1.5).
        assert!((p - Point3::new(3.0, 0.3, 1.5)).norm() < 1e-12, "{p}");
        let q = b.lookup("cam", "map").unwrap() * p;
        assert!(q.coords.norm() < 1e-12);
        assert!(b.lookup("map", "nowhere").is_none());
        assert_eq!(b.add(&TFMessage { transforms: vec![tf("a", "a", 0.0, 0.0)] }), 1);
    }
}
