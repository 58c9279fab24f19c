//! Rigid transforms as plain f64 arrays: the tree only needs compose, rotate and the URDF
//! roll-pitch-yaw convention, which does not justify a linear-algebra dependency here.

use agrisim_math::vec3::{add, mat_mul, mat_vec, transpose};

/// A rigid transform: `p_parent = rot * p_child + trans`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Pose {
    /// Row-major rotation matrix.
    pub rot: [[f64; 3]; 3],
    pub trans: [f64; 3],
}

impl Pose {
    pub const IDENTITY: Pose = Pose { rot: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], trans: [0.0; 3] };

    /// URDF `<origin xyz rpy>`: R = Rz(yaw) Ry(pitch) Rx(roll) (fixed axes x, y, z).
    pub fn from_xyz_rpy(xyz: [f64; 3], rpy: [f64; 3]) -> Pose {
        let (sr, cr) = rpy[0].sin_cos();
        let (sp, cp) = rpy[1].sin_cos();
        let (sy, cy) = rpy[2].sin_cos();
        Pose {
            rot: [
                [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                [-sp, cp * sr, cp * cr],
            ],
            trans: xyz,
        }
    }

    /// Rotation by `angle` about the unit vector `axis` (Rodrigues).
    pub fn from_axis_angle(axis: [f64; 3], angle: f64) -> Pose {
        let [x, y, z] = axis;
        let (s, c) = angle.sin_cos();
        let t = 1.0 - c;
        Pose {
            rot: [
                [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
                [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
                [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
            ],
            trans: [0.0; 3],
        }
    }

    pub fn from_translation(t: [f64; 3]) -> Pose {
        Pose { trans: t, ..Pose::IDENTITY }
    }

    /// `self * other`: `other` expressed in `self`'s parent frame.
    pub fn mul(&self, other: &Pose) -> Pose {
        Pose { rot: mat_mul(&self.rot, &other.rot), trans: self.transform_point(other.trans) }
    }

    pub fn rotate(&self, v: [f64; 3]) -> [f64; 3] {
        mat_vec(&self.rot, v)
    }

    pub fn transform_point(&self, p: [f64; 3]) -> [f64; 3] {
        add(self.rotate(p), self.trans)
    }

    pub fn inverse(&self) -> Pose {
        let rt = transpose(&self.rot);
        let t = mat_vec(&rt, self.trans);
        Pose { rot: rt, trans: [-t[0], -t[1], -t[2]] }
    }

    /// Column `i` of the rotation: the child's axis `i` in the parent frame.
    pub fn axis(&self, i: usize) -> [f64; 3] {
        [self.rot[0][i], self.rot[1][i], self.rot[2][i]]
    }

    /// The rotation as a unit quaternion (x, y, z, w), by Shepperd's method (the largest of
    /// the four candidates first, for accuracy near 180-degree turns).
    pub fn quaternion(&self) -> [f64; 4] {
        let m = &self.rot;
        let tr = m[0][0] + m[1][1] + m[2][2];
        let q = if tr > 0.0 {
            let s = (tr + 1.0).sqrt() * 2.0;
            [(m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s, 0.25 * s]
        } else if m[0][0] > m[1][1] && m[0][0] > m[2][2] {
            let s = (1.0 + m[0][0] - m[1][1] - m[2][2]).sqrt() * 2.0;
            [0.25 * s, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s, (m[2][1] - m[1][2]) / s]
        } else if m[1][1] > m[2][2] {
            let s = (1.0 + m[1][1] - m[0][0] - m[2][2]).sqrt() * 2.0;
            [(m[0][1] + m[1][0]) / s, 0.25 * s, (m[1][2] + m[2][1]) / s, (m[0][2] - m[2][0]) / s]
        } else {
            let s = (1.0 + m[2][2] - m[0][0] - m[1][1]).sqrt() * 2.0;
            [(m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, 0.25 * s, (m[1][0] - m[0][1]) / s]
        };
        let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
        q.map(|v| v / n)
    }

    /// Largest absolute element difference (rotation and translation), for tests and checks.
    pub fn max_abs_diff(&self, other: &Pose) -> f64 {
        let mut m: f64 = 0.0;
        for i in 0..3 {
            for j in 0..3 {
                m = m.max((self.rot[i][j] - other.rot[i][j]).abs());
            }
            m = m.max((self.trans[i] - other.trans[i]).abs());
        }
        m
    }
}
