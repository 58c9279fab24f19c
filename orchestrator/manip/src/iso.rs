//! Conversions between `agrisim_robot::Pose` (URDF frames) and nalgebra's `Isometry3`.

use agrisim_robot::Pose;
use nalgebra::{Isometry3, Translation3, UnitQuaternion};

pub fn to_iso(p: &Pose) -> Isometry3<f64> {
    let r = nalgebra::Matrix3::from_row_slice(&[
        p.rot[0][0],
        p.rot[0][1],
        p.rot[0][2],
        p.rot[1][0],
        p.rot[1][1],
        p.rot[1][2],
        p.rot[2][0],
        p.rot[2][1],
        p.rot[2][2],
    ]);
    let rot = UnitQuaternion::from_rotation_matrix(&nalgebra::Rotation3::from_matrix_unchecked(r));
    Isometry3::from_parts(Translation3::new(p.trans[0], p.trans[1], p.trans[2]), rot)
}

pub fn to_pose(i: &Isometry3<f64>) -> Pose {
    let m = i.rotation.to_rotation_matrix().into_inner();
    let t = i.translation.vector;
    Pose { rot: [0, 1, 2].map(|r| [m[(r, 0)], m[(r, 1)], m[(r, 2)]]), trans: [t.x, t.y, t.z] }
}
