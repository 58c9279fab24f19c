//! What the IK must reach: a TCP pose in the planning frame, optionally with the roll about
//! the tool z axis left free (a sphere-like fruit can be grasped with any roll about the
//! approach axis, which enlarges the reachable set and the goal set).

use agrisim_robot::Pose;
use nalgebra::{Isometry3, UnitQuaternion, Vector3, Vector6};

#[derive(Debug, Clone, Copy)]
pub struct Target {
    /// Desired TCP pose in the planning frame (`base_link`).
    pub pose: Isometry3<f64>,
    /// Any rotation about the target's z axis (the approach axis) is acceptable.
    pub free_roll: bool,
    /// Position tolerance (m).
    pub pos_tol: f64,
    /// Orientation tolerance (rad): angle of the residual rotation (free roll: between z axes).
    pub rot_tol: f64,
}

impl Target {
    /// Full 6-D target with the default tolerances (1 mm, 0.01 rad).
    pub fn pose(pose: Isometry3<f64>) -> Target {
        Target { pose, free_roll: false, pos_tol: 1e-3, rot_tol: 1e-2 }
    }
    /// 5-D target: position and approach axis (tool z), any roll about it.
    pub fn free_roll(pose: Isometry3<f64>) -> Target {
        Target { free_roll: true, ..Target::pose(pose) }
    }
    /// From agrisim-robot's pose type.
    pub fn from_pose(p: &Pose, free_roll: bool) -> Target {
        let t = Target::pose(crate::iso::to_iso(p));
        Target { free_roll, ..t }
    }

    /// Error twist from `cur` to the target: [position; rotation vector], planning frame.
    /// With free roll the rotation is the smallest one that aligns the z axes, i.e. the
    /// goal orientation is the acceptable one closest to `cur`.
    pub fn error(&self, cur: &Isometry3<f64>) -> Vector6<f64> {
        let ep = self.pose.translation.vector - cur.translation.vector;
        let er = if self.free_roll {
            let zc = cur.rotation * Vector3::z();
            let zt = self.pose.rotation * Vector3::z();
            match UnitQuaternion::rotation_between(&zc, &zt) {
                Some(r) => r.scaled_axis(),
                // Antiparallel: any axis normal to z works; take the current x.
                None => (cur.rotation * Vector3::x()) * std::f64::consts::PI,
            }
        } else {
            (self.pose.rotation * cur.rotation.inverse()).scaled_axis()
        };
        Vector6::new(ep.x, ep.y, ep.z, er.x, er.y, er.z)
    }

    /// Whether an error twist from [`Target::error`] is within the tolerances.
    pub fn reached(&self, e: &Vector6<f64>) -> bool {
        e.fixed_rows::<3>(0).norm() <= self.pos_tol && e.fixed_rows::<3>(3).norm() <= self.rot_tol
    }
}
