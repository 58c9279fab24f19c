//! The camera's optical frame in the map, by the chain TF gives: base_link at (x, y, yaw) on
//! the floor, the mount's parent link in base_link (the robot's forward kinematics), camera_link
//! at the mount (position, fixed-axis roll-pitch-yaw, URDF) in the parent, and the optical axes
//! (z forward, x right, y down) in camera_link (REP 103 / REP 105).

pub type Mat3 = [[f64; 3]; 3];

fn mul(a: &Mat3, b: &Mat3) -> Mat3 {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

fn apply(a: &Mat3, v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| (0..3).map(|k| a[i][k] * v[k]).sum())
}

/// Rz(yaw) Ry(pitch) Rx(roll).
pub fn rpy(roll: f64, pitch: f64, yaw: f64) -> Mat3 {
    let (sr, cr) = roll.sin_cos();
    let (sp, cp) = pitch.sin_cos();
    let (sy, cy) = yaw.sin_cos();
    let rx = [[1.0, 0.0, 0.0], [0.0, cr, -sr], [0.0, sr, cr]];
    let ry = [[cp, 0.0, sp], [0.0, 1.0, 0.0], [-sp, 0.0, cp]];
    let rz = [[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]];
    mul(&rz, &mul(&ry, &rx))
}

/// Columns: the optical x (right), y (down) and z (forward) axes in camera_link.
const OPTICAL: Mat3 = [[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]];

/// Where camera_link is in the frame of the mount's parent link.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Mount {
    pub x: f64,
    pub y: f64,
    pub z: f64,
    pub roll: f64,
    pub pitch: f64,
    pub yaw: f64,
}

/// The optical frame in the map: `rotation` takes optical coordinates to map coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Extrinsics {
    pub translation: [f64; 3],
    pub rotation: Mat3,
}

impl Extrinsics {
    /// `parent`: the parent link's rotation and origin in base_link.
    pub fn new(mount: &Mount, parent: (Mat3, [f64; 3]), x: f64, y: f64, yaw: f64) -> Extrinsics {
        let base = rpy(0.0, 0.0, yaw);
        let (rp, tp) = parent;
        let in_parent = apply(&rp, [mount.x, mount.y, mount.z]);
        let t = apply(&base, [tp[0] + in_parent[0], tp[1] + in_parent[1], tp[2] + in_parent[2]]);
        let rotation = mul(&mul(&mul(&base, &rp), &rpy(mount.roll, mount.pitch, mount.yaw)), &OPTICAL);
        Extrinsics { translation: [x + t[0], y + t[1], t[2]], rotation }
    }

    /// A map point in the optical frame.
    pub fn to_camera(&self, p: [f64; 3]) -> [f64; 3] {
        let d = [p[0] - self.translation[0], p[1] - self.translation[1], p[2] - self.translation[2]];
        std::array::from_fn(|i| (0..3).map(|k| self.rotation[k][i] * d[k]).sum())
    }

    /// Row-major 4x4 T_map_optical.
    pub fn matrix(&self) -> [[f64; 4]; 4] {
        let (r, t) = (&self.rotation, &self.translation);
        [
            [r[0][0], r[0][1], r[0][2], t[0]],
            [r[1][0], r[1][1], r[1][2], t[1]],
            [r[2][0], r[2][1], r[2][2], t[2]],
            [0.0, 0.0, 0.0, 1.0],
        ]
    }

    /// The rotation as a unit quaternion (x, y, z, w), w >= 0.
    pub fn quaternion(&self) -> [f64; 4] {
        let m = &self.rotation;
        let tr = m[0][0] + m[1][1] + m[2][2];
        let q = if tr > 0.0 {
            let s = 2.0 * (tr + 1.0).sqrt();
            [(m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s, 0.25 * s]
        } else if m[0][0] > m[1][1] && m[0][0] > m[2][2] {
            let s = 2.0 * (1.0 + m[0][0] - m[1][1] - m[2][2]).sqrt();
            [0.25 * s, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s, (m[2][1] - m[1][2]) / s]
        } else if m[1][1] > m[2][2] {
            let s = 2.0 * (1.0 + m[1][1] - m[0][0] - m[2][2]).sqrt();
            [(m[0][1] + m[1][0]) / s, 0.25 * s, (m[1][2] + m[2][1]) / s, (m[0][2] - m[2][0]) / s]
        } else {
            let s = 2.0 * (1.0 + m[2][2] - m[0][0] - m[1][1]).sqrt();
            [(m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, 0.25 * s, (m[1][0] - m[0][1]) / s]
        };
        if q[3] < 0.0 {
            q.map(|v| -v)
        } else {
            q
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn optical_axes_and_round_trip() {
        let m = Mount { x: 0.5, y: 0.0, z: 1.0, roll: 0.0, pitch: 0.0, yaw: 0.0 };
        // The parent raised 0.2 m (a lift) and turned 90 deg; the base turned back.
        let e = Extrinsics::new(&m, (rpy(0.0, 0.0, 1.0), [0.0, 0.0, 0.2]), 1.0, 2.0, std::f64::consts::FRAC_PI_2 - 1.0);
        // Facing map +y from (1, 2.5, 1.2): a point 3 m ahead is at optical (0, 0, 3).
        let near = |a: [f64; 3], b: [f64; 3]| (0..3).all(|i| (a[i] - b[i]).abs() < 1e-12);
        assert!(near(e.translation, [1.0, 2.5, 1.2]), "{:?}", e.translation);
        assert!(near(e.to_camera([1.0, 5.5, 1.2]), [0.0, 0.0, 3.0]));
        // Facing +y, map +x is to the right (optical +x) and map -z is down (optical +y).
        assert!(near(e.to_camera([2.0, 5.5, 1.2]), [1.0, 0.0, 3.0]));
        assert!(near(e.to_camera([1.0, 5.5, 0.2]), [0.0, 1.0, 3.0]));
        // The quaternion rotates like the matrix.
        let [x, y, z, w] = e.quaternion();
        let q: Mat3 = [
            [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - z * w), 2.0 * (x * z + y * w)],
            [2.0 * (x * y + z * w), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - x * w)],
            [2.0 * (x * z - y * w), 2.0 * (y * z + x * w), 1.0 - 2.0 * (x * x + y * y)],
        ];
        for i in 0..3 {
            assert!(near(q[i], e.rotation[i]), "{q:?} {:?}", e.rotation);
        }
    }
}
